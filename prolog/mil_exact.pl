/*  mil_exact: the exact search (Metagol's): the first program, smallest first, that proves every
    positive example and no negative one.

    Iterative deepening on the number of clauses N (min_clauses .. max_clauses), each round with
    the signature of N (mil_prove:signature/3).  With a finite max_literals the deepening runs on
    the body literals L first and then on N <= L, and a round keeps only programs of exactly N
    clauses and L literals, so that each size is searched once.
    Examples are proved in order; one the program so far already proves is not proved again (and
    opens no alternative), as in Metagol; the functional check (setting functional(true)) follows
    each example.
*/
:- module(mil_exact, [ learn_exact/4,        % +Ctx, +Settings, +Pos-Neg, -Prog
                       size/3,               % +Settings, +Ctx0, -Ctx   (nondet: the rounds)
                       exact_size/2,         % +Ctx, +Prog
                       prove_examples/4      % +Ctx, +Atoms, +Prog0, -Prog
                     ]).
:- use_module(library(lists)).
:- use_module(library(apply)).
:- use_module(library(option)).
:- use_module(mil_prove).

%!  learn_exact(+Ctx, +Settings, +Pos-Neg, -Prog) is semidet.
%   Pos and Neg are l/3 atoms; Prog the program's items, newest first.
learn_exact(X0, Settings, Pos-Neg, Prog) :-
    size(Settings, X0, X),
    prove_examples(X, Pos, [], Prog0),
    \+ ( member(E, Neg), deduce(X, Prog0, E, _) ),
    ground(Prog0),
    functional_ok(X, Prog0, Pos),
    exact_size(X, Prog0),
    !,
    Prog = Prog0.

%!  size(+Settings, +Ctx0, -Ctx) is nondet.  The rounds of iterative deepening, smallest first.
size(Settings, X0, X) :-
    option(max_literals(ML), Settings, inf), option(max_clauses(MC), Settings, 10),
    option(min_clauses(Min), Settings, 1),
    (   ML == inf
    ->  between(Min, MC, N), L = inf
    ;   between(1, ML, L), between(Min, MC, N), N =< L
    ),
    signature(X0, N, Sig),
    set_maxn_of_ctx(N, X0, X1), set_maxl_of_ctx(L, X1, X2), with_sig(Sig, X2, X).

%!  exact_size(+Ctx, +Prog) is semidet.
%   With a literal bound, Prog has exactly the round's clauses and literals; else any size.
exact_size(X, Prog) :-
    ctx_maxl(X, L),
    (   L == inf -> true
    ;   ctx_maxn(X, N), length(Prog, N), prog_lits(Prog, L)
    ).

%!  prove_examples(+Ctx, +Atoms, +Prog0, -Prog) is nondet.
prove_examples(_, [], P, P).
prove_examples(X, [L|Ls], P0, P) :-
    (   deduce(X, P0, L, _)
    ->  functional_ok(X, P0, [L]),
        prove_examples(X, Ls, P0, P)
    ;   length(P0, N0), ctx_depth(X, D), ctx_sig(X, Sig),
        prove([L], X, Sig, [], D, P0, P1, N0, _, 1.0, _, _, []),
        functional_ok(X, P1, [L]),
        prove_examples(X, Ls, P1, P)
    ).
