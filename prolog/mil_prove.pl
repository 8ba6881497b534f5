/*  mil_prove: the meta-interpreter the learner's searches share.

    The context is one record, ctx/15 (library(record)): ctx_threshold(Ctx, T) reads a field,
    set_maxn_of_ctx(N, Ctx0, Ctx) changes one.  task_ctx/3 builds it from a task and settings.

    Atoms inside the interpreter are l(P, A, Args) (a predicate symbol P, possibly a variable, its
    arity A and its arguments), so that a metarule can leave P open.  A metarule body also holds
    ordering literals o(Goal) (Metagol's @Goal): Goal runs in the background module, is never part
    of a printed clause and binds no predicate symbol.

    A program is a list of items, newest first: sub(Name, P, A, Subs, K) (metarule Name with
    second- and first-order substitutions Subs for head symbol P/A, K body literals) while
    learning, cl(Head, Body) (an l/3 atom and a list of them) for a fixed clause.

    How an atom l(P, A, Args) is proved, in this order (Metagol's order):
      - P bound and a body predicate: its kind decides: a fact with a confidence (kind fact(Store):
        the background stores Store(Args..., Conf)), a derived rule (kind rule: BK:bk_rule(Head,
        Body), its body proved by this interpreter), or plain Prolog (kind call, confidence 1);
      - P bound and an interpreted background predicate (ibk/2 of a task): its body proved here;
      - P bound, not a body predicate nor a head symbol (a target or an invented symbol) nor
        interpreted: a predicate a metarule or an ibk body names, called in the background module;
      - P open: every body predicate of arity A, in the order given, then every interpreted one;
      - P a head symbol or open: a clause of the program, then a new clause (a metarule instance).
    The signature (Metagol's): the targets, then the invented symbols T_1, T_2, ...  A clause of
    symbol S may call (with an open symbol) only the symbols after S, an invented symbol only once
    it is used, and the first unused one opens a new predicate; a metarule whose body names its
    own head symbol is recursive, needs at least two clauses allowed, and no atom may be proved
    inside its own proof (the path check, by unification, as Metagol's).

    A proof's confidence combines the confidences of the facts it used (combine: product or min);
    a partial proof below the threshold is dropped.
*/
:- module(mil_prove, [ task_ctx/3,          % +Task, +Settings, -Ctx
                       prove/13,            % the interpreter (see below)
                       deduce/4,            % +Ctx, +Prog, +Atom, -Conf     (no new clause, first proof)
                       covers/5,            % +Ctx, +Prog, +Atom, -Conf, -Trace  (every proof)
                       signature/3,         % +Ctx, +MaxClauses, -Sig
                       functional_ok/3,     % +Ctx, +Prog, +Atoms
                       program_items/2,     % +Clauses, -Prog          (H :- B terms to cl items)
                       item_clause/3,       % +Ctx, +Item, -Clause    (with ordering literals dropped)
                       prog_lits/2,         % +Prog, -Literals
                       atom_lit/2,          % ?Atom, ?Lit
                       compile_metarule/2,  % +metarule(Name, Subs, Head, Body, Cond), -MR
                       repeated_literal/2,  % +Ctx, +Item
                       ctx_bk/2, ctx_mm/2, ctx_targets/2, ctx_bps/2, ctx_threshold/2, ctx_combine/2,
                       ctx_inventions/2, ctx_maxn/2, ctx_maxl/2, ctx_miss/2, ctx_trace/2, ctx_sig/2,
                       ctx_depth/2, ctx_functional/2,
                       set_maxn_of_ctx/3, set_maxl_of_ctx/3, with_sig/3, set_threshold_of_ctx/3,
                       set_miss_of_ctx/3, set_trace_of_ctx/3
                     ]).
:- use_module(library(lists)).
:- use_module(library(apply)).
:- use_module(library(option)).
:- use_module(library(record)).
:- use_module(mil_safe, [checked_call/2]).

%   bk: background module; mm: the module holding the task's tables (below); targets: [P/A];
%   bps: [bp(P, A, Kind)] visible body predicates in the order given; heads: [P/A] declared head
%   predicates (Metagol's head_pred/1); depth: bound on nested clause applications; maxn, maxl:
%   bounds on clauses and body literals of the program being built; sig: the signature
%   ([sym(P, A, Used)], or none: no order, for fixed programs); functional: Metagol's functional
%   check; trace: record proofs.
:- record ctx(bk=user, mm=user, targets=[], bps=[], heads=[], depth=inf,
              threshold=0.0, combine=product, inventions=0, maxn=1, maxl=inf, miss=0, sig=none,
              after=[], functional=false, trace=false).

%   The tables, in module BK$mil (filled by task_ctx/3, so that the interpreter looks things up by
%   first-argument indexing):
%     '$mr'(Name, Subs, Head, Body, Rec, Cond, K)   the metarules, in search order
%     '$kind'(P, A, Kind)       a bound symbol's kind: fact(Store), rule, call, head (a target), ibk
%     '$bp'(P, A, Kind)         the visible body predicates, in search order
%     '$call'(P, Args)          P(Args) as Prolog in the background (kind call)
%     '$fact'(P, Args, Conf)    a fact with its confidence (kind fact)
%     '$ibk'(P, A, Args, Body, Cond)   interpreted background knowledge
:- dynamic mm_declared/1.

%!  task_ctx(+Task, +Settings, -Ctx) is det.
%   Task = task(BK, Targets, BodyPreds, Metarules, Pos, Neg) or task/7 with a list of extra
%   declarations last: ibk(Head, Body, Cond), head_pred(P/A), compiled(P/A).  Metarules: compiled
%   (mr/7) or names of mil:metarule/4 or metarule/4 terms.  Throws mil_error(unknown_body_pred(P/A))
%   for a body predicate the background does not define (a task file warns and drops it first).
task_ctx(Task, Settings, Ctx) :-
    task_parts(Task, BK, Targets, BodyPreds, MRs0, Decls),
    maplist(metarule_compiled, MRs0, MRs),
    body_table(BK, BodyPreds, Decls, BPs, Hidden),
    findall(ibk(H, B, C), member(ibk(H, B, C), Decls), Ibks),
    findall(P/A, member(head_pred(P/A), Decls), Heads),
    findall(P/A, member(compiled(P/A), Decls), Compiled),
    fill_tables(BK, MM, Targets, BPs, Hidden, Ibks, MRs, Compiled),
    option(functional(Fun), Settings, false),
    option(max_depth(D), Settings, inf), option(threshold(Thr), Settings, 0.0),
    option(combine(How), Settings, product), option(max_inventions(Inv), Settings, 0),
    option(miss(Eps), Settings, 0),
    make_ctx([bk(BK), mm(MM), targets(Targets), bps(BPs), heads(Heads),
              depth(D), threshold(Thr), combine(How), inventions(Inv), miss(Eps), functional(Fun)], Ctx).

fill_tables(BK, MM, Targets, BPs, Hidden, Ibks, MRs, Compiled) :-
    atom_concat(BK, '$mil', MM),
    (   mm_declared(MM) -> true
    ;   dynamic([MM:'$mr'/7, MM:'$kind'/3, MM:'$bp'/3, MM:'$call'/2, MM:'$fact'/3, MM:'$ibk'/5]),
        assertz(mm_declared(MM))
    ),
    forall(member(PI, ['$mr'/7, '$kind'/3, '$bp'/3, '$call'/2, '$fact'/3, '$ibk'/5]),
           ( PI = F/N, functor(H, F, N), retractall(MM:H) )),
    forall(member(MR, MRs), ( MR = mr(N, S, Hd, B, R, C, K), assertz(MM:'$mr'(N, S, Hd, B, R, C, K)) )),
    forall(member(bp(P, A, K), BPs), assertz(MM:'$bp'(P, A, K))),
    findall(P-A-K, ( member(bp(P, A, K), BPs)
                   ; member(P/A, Targets), K = head
                   ; member(ibk(l(P, A, _), _, _), Ibks), K = ibk
                   ; member(bp(P, A, K), Hidden)
                   ; member(P/A, Compiled), K = call ), Kinds),
    forall(member(P-A-K, Kinds), ( MM:'$kind'(P, A, _) -> true ; assertz(MM:'$kind'(P, A, K)) )),
    forall(( MM:'$kind'(P, A, call), \+ MM:'$call'(P, _) ),
           ( length(Args, A), G =.. [P|Args], assertz((MM:'$call'(P, Args) :- BK:G)) )),
    forall(( MM:'$kind'(P, A, fact(Store)), \+ MM:'$fact'(P, _, _) ),
           ( length(Args, A), append(Args, [Cf], Args1), G =.. [Store|Args1],
             assertz((MM:'$fact'(P, Args, Cf) :- BK:G)) )),
    forall(member(ibk(l(P, A, Args), B, C), Ibks), assertz(MM:'$ibk'(P, A, Args, B, C))).

task_parts(task(BK, Ts, BPs, MRs, _, _), BK, Ts, BPs, MRs, []).
task_parts(task(BK, Ts, BPs, MRs, _, _, Decls), BK, Ts, BPs, MRs, Decls).

metarule_compiled(MR, MR) :- MR = mr(_, _, _, _, _, _, _), !.
metarule_compiled(Name, MR) :- atom(Name), !,
    (   mil:metarule(Name, S, H, B) -> compile_metarule(metarule(Name, S, H, B, true), MR)
    ;   throw(mil_error(unknown_metarule(Name)))
    ).
metarule_compiled(metarule(N, S, H, B), MR) :- !, compile_metarule(metarule(N, S, H, B, true), MR).
metarule_compiled(metarule(N, S, H, B, C), MR) :- compile_metarule(metarule(N, S, H, B, C), MR).

%!  compile_metarule(+metarule(Name, Subs, Head, Body, Cond), -MR) is det.
%   Head and Body in Metagol's list form ([P|Args], [[Q|Args], @Goal, ...]); MR = mr(Name, Subs,
%   HeadLit, BodyLits, Recursive, Cond, K).  Recursive: a body literal's symbol is the head's (==).
compile_metarule(metarule(Name, Subs, [P|HArgs], Body0, Cond), mr(Name, Subs, l(P, HA, HArgs), Body, Rec, Cond, K)) :-
    length(HArgs, HA),
    maplist(body_lit, Body0, Body),
    (   member(l(Q, _, _), Body), Q == P -> Rec = true ; Rec = false ),
    aggregate_all(count, member(l(_, _, _), Body), K).

body_lit(@(G), o(G)) :- !.
body_lit([Q|Args], l(Q, A, Args)) :- length(Args, A).

%!  atom_lit(?Atom, ?Lit) is det.  p(a, b) <-> l(p, 2, [a, b]).
atom_lit(Atom, l(P, A, Args)) :-
    (   nonvar(Atom) -> Atom =.. [P|Args], length(Args, A)
    ;   Atom =.. [P|Args]
    ).

%   The kind of each body predicate: fact(Store) when the background declares it a fact with a
%   confidence ('$mil_fact'(P, A, Store): stored as Store(Args..., Conf)), rule when it has a
%   derived rule (bk_rule/2), call when it defines P/A or P/A is a built-in a task may call.
%   The predicates that derived rules use follow, hidden: proved when a rule calls them, never put
%   in a clause by the search.
body_table(BK, BodyPreds, _Decls, BPs, Hidden) :-
    maplist(body_kind(BK), BodyPreds, BPs),
    findall(Q/B, ( member(bp(P, A, rule), BPs), functor(H, P, A),
                   catch(BK:bk_rule(H, Body), _, fail), member(G, Body), functor(G, Q, B),
                   \+ memberchk(Q/B, BodyPreds) ), Hidden0),
    sort(Hidden0, Hidden1),
    maplist(body_kind(BK), Hidden1, Hidden).

body_kind(BK, P/A, bp(P, A, Kind)) :-
    functor(H, P, A),
    (   catch(BK:'$mil_fact'(P, A, Store), error(existence_error(_, _), _), fail) -> Kind = fact(Store)
    ;   catch(BK:bk_rule(H, _), error(existence_error(_, _), _), fail) -> Kind = rule
    ;   current_predicate(BK:P/A) -> Kind = call
    ;   predicate_property(BK:H, defined) -> Kind = call     % a built-in or library predicate
    ;   throw(mil_error(unknown_body_pred(P/A)))
    ).

%!  signature(+Ctx, +MaxClauses, -Sig) is det.
%   The targets, then min(MaxClauses - 1, inventions) invented symbols named after the first
%   target: T_1, T_2, ...
signature(Ctx, N, Sig) :-
    ctx_targets(Ctx, Ts), ctx_inventions(Ctx, Inv),
    findall(sym(P, A, target), member(P/A, Ts), TSyms),
    Ts = [T/_|_], M is min(N - 1, Inv),
    findall(sym(S, _, _), ( between(1, M, I), atomic_list_concat([T, '_', I], S) ), ISyms),
    append(TSyms, ISyms, Sig).

%% ---- the interpreter
%
%   prove(+Lits, +Ctx, +Sig, +Path, +Depth, +Prog0, -Prog, +N0, -N, +Conf0, -Conf, -Trace0, +Trace)
%   Sig: the symbols an open body symbol may take here; Path: the atoms whose proofs this one is
%   inside; N: the number of clauses of the program; Trace0-Trace: a difference list of what the
%   proof used (kept when the context's trace is true).

prove([], _, _, _, _, P, P, N, N, C, C, T, T).
prove([L|Ls], X, Sig, Path, D, P0, P, N0, N, C0, C, T0, T) :-
    lit(L, X, Sig, Path, D, P0, P1, N0, N1, C0, C1, T0, T1),
    prove(Ls, X, Sig, Path, D, P1, P, N1, N, C1, C, T1, T).

lit(o(G), X, _, _, _, P, P, N, N, C, C, T, T) :- !,
    ctx_bk(X, M), call(M:G).
lit(L, X, Sig, Path, D, P0, P, N0, N, C0, C, T0, T) :-
    L = l(Q, A, _),
    (   atom(Q)
    ->  ctx_mm(X, MM),
        (   MM:'$kind'(Q, A, Kind) -> true
        ;   head_symbol(X, Q, A) -> Kind = head
        ),
        known_lit(Kind, L, X, Sig, Path, D, P0, P, N0, N, C0, C, T0, T)
    ;   var(Q)
    ->  open_lit(L, X, Sig, Path, D, P0, P, N0, N, C0, C, T0, T)
    ;   throw(mil_error(bad_symbol(Q)))
    ).

%   A bound symbol's kind comes from the tables: a body predicate, a target, interpreted, a
%   predicate derived rules use, or a fixed symbol of a metarule or ibk body, called as Prolog
%   (Metagol's "compiled" predicates); else an invented symbol of the signature.  Any other symbol
%   (one an example's data put there) proves nothing.
head_symbol(X, Q, A) :-
    ctx_sig(X, Sig),
    Sig \== none,
    memberchk(sym(Q, A0, _), Sig), ( var(A0) -> true ; A0 == A ).

known_lit(head, L, X, Sig, Path, D, P0, P, N0, N, C0, C, T0, T) :- !,
    program_lit(L, X, Sig, Path, D, P0, P, N0, N, C0, C, T0, T).
known_lit(ibk, L, X, Sig, Path, D, P0, P, N0, N, C0, C, T0, T) :- !,
    ibk_lit(L, X, Sig, Path, D, P0, P, N0, N, C0, C, T0, T).
known_lit(K, L, X, Sig, Path, D, P0, P, N0, N, C0, C, T0, T) :-
    bk_lit(K, L, X, Sig, Path, D, P0, P, N0, N, C0, C, T0, T).

open_lit(L, X, Sig, Path, D, P0, P, N0, N, C0, C, T0, T) :-
    L = l(Q, A, _), ctx_mm(X, MM),
    (   MM:'$bp'(Q, A, K),
        bk_lit(K, L, X, Sig, Path, D, P0, P, N0, N, C0, C, T0, T)
    ;   ibk_lit(L, X, Sig, Path, D, P0, P, N0, N, C0, C, T0, T)
    ;   program_lit(L, X, Sig, Path, D, P0, P, N0, N, C0, C, T0, T)
    ).

% a fact with a confidence
bk_lit(fact(_), l(Q, _, Args), X, _, _, _, P, P, N, N, C0, C, T0, T) :-
    ctx_mm(X, MM),
    MM:'$fact'(Q, Args, Cf),
    combine(X, C0, Cf, C),
    (   ctx_trace(X, true) -> F =.. [Q|Args], T0 = [fact(F, Cf)|T] ; T0 = T ).
% near misses (setting miss(Eps) > 0): a fact the background lacks holds with confidence Eps, the
% chance that perception missed a true fact; bindings it would make are made by BK:near_miss(BK, G)
% when the background defines it, else left open
bk_lit(fact(_), l(Q, _, Args), X, _, _, _, P, P, N, N, C0, C, T0, T) :-
    ctx_miss(X, Eps), Eps > 0,
    C is C0 * Eps, ctx_threshold(X, Thr), C >= Thr,
    G =.. [Q|Args], ctx_bk(X, M),
    catch(M:near_miss(M, G), error(existence_error(procedure, _), _), true),
    (   ctx_trace(X, true) -> T0 = [miss(G, Eps)|T] ; T0 = T ).
% a derived rule of the background: its body proved here
bk_lit(rule, l(Q, _, Args), X, Sig, Path, D, P0, P, N0, N, C0, C, T0, T) :-
    G =.. [Q|Args], ctx_bk(X, M),
    M:bk_rule(G, Body0),
    maplist(atom_lit, Body0, Body),
    (   ctx_trace(X, true) -> T0 = [bk(G)|T1] ; T1 = T0 ),
    prove(Body, X, Sig, Path, D, P0, P, N0, N, C0, C, T1, T).
% plain Prolog: confidence 1
bk_lit(call, l(Q, _, Args), X, _, _, _, P, P, N, N, C, C, T0, T) :-
    ctx_mm(X, MM),
    MM:'$call'(Q, Args),
    (   ctx_trace(X, true) -> G =.. [Q|Args], T0 = [call(G)|T] ; T0 = T ).

% interpreted background knowledge: ibk(Head, Body) of the task, its body proved here (it may leave
% symbols open, which the search fills: map/3's F); the path is not extended (Metagol's)
ibk_lit(l(Q, A, Args), X, Sig, Path, D, P0, P, N0, N, C0, C, T0, T) :-
    ctx_mm(X, MM),
    MM:'$ibk'(Q, A, Args, Body, Cond),
    run_cond(Cond, X),
    (   ctx_trace(X, true) -> G =.. [Q|Args], T0 = [bk(G)|T1] ; T1 = T0 ),
    prove(Body, X, Sig, Path, D, P0, P, N0, N, C0, C, T1, T).

% a clause of the program, then a new clause
program_lit(L, X, Sig1, Path, D, P0, P, N0, N, C0, C, T0, T) :-
    (   D == inf -> D1 = inf ; D > 0, D1 is D - 1 ),
    L = l(Q, A, _),
    (   N0 > 0,
        select_lower(Q, A, X, Sig1, Sig2),
        (   ctx_trace(X, true)
        ->  nth1(I, P0, Item), length(P0, NP), IC is NP - I + 1, T0 = [clause(IC)|T1]
        ;   P0 = [sub(_, _, _, _, _)|_]
        ->  Item = sub(_, Q, A, _, _), member(Item, P0), T1 = T0       % only the symbol's own items
        ;   member(Item, P0), T1 = T0
        ),
        item_instance(Item, X, L, Body, Rec),
        recursion_ok(Rec, X, L, Path),
        prove(Body, X, Sig2, [L|Path], D1, P0, P, N0, N, C0, C, T1, T)
    ;   ctx_maxn(X, MaxN), N0 < MaxN,
        bind_lower(Q, A, X, Sig1, Sig2),
        ctx_mm(X, MM),
        MM:'$mr'(Name, Subs, L, Body, Rec, Cond, K),
        run_cond(Cond, X),
        recursion_ok(Rec, X, L, Path),
        literal_budget(X, P0, K),
        new_metasub(Name, Q, A, Subs, P0),
        N1 is N0 + 1,
        (   ctx_trace(X, true) -> T0 = [clause(new)|T1] ; T1 = T0 ),
        prove(Body, X, Sig2, [L|Path], D1, [sub(Name, Q, A, Subs, K)|P0], P, N1, N, C0, C, T1, T)
    ).

%   A recursive metarule needs room for a second clause, and its atom may not be inside its own
%   proof (Metagol's).  With several targets, which may call each other, no atom of any clause may.
recursion_ok(false, X, L, Path) :-
    (   ctx_targets(X, [_, _|_]) -> \+ memberchk(L, Path) ; true ).
recursion_ok(true, X, L, Path) :-
    ctx_maxn(X, MaxN), MaxN \== 1,
    \+ memberchk(L, Path).

literal_budget(X, P0, K) :-
    ctx_maxl(X, ML),
    (   ML == inf -> true ; prog_lits(P0, L0), L0 + K =< ML ).

%   A second clause of one metarule and symbol must differ in its substitutions (checked once the
%   last of them is bound, as Metagol does).
new_metasub(Name, Q, A, Subs, Prog) :-
    (   memberchk(sub(Name, Q, A, _, _), Prog)
    ->  last(Subs, Z),
        when(ground(Z), \+ memberchk(sub(Name, _, A, Subs, _), Prog))
    ;   true
    ).

%   The symbols a clause body may name, after the clause's head symbol Q: a bound Q must be a head
%   symbol (Sig2: those after it; with several targets, a target's clause may name the other
%   targets too); an open Q takes a used symbol of Sig1 (not past the first unused one; a target
%   counts as used).  With no signature (fixed programs) anything goes.
select_lower(Q, A, X, Sig1, Sig2) :-
    ctx_sig(X, Full),
    (   Full == none -> Sig2 = none
    ;   nonvar(Q) -> after(X, Full, Q, A, Sig2)
    ;   lower_used(Sig1, Q, A, Rest, U), lower_rest(U, X, Full, Q, A, Rest, Sig2)
    ).

%   After a target taken for an open symbol, the same symbols as for its own clauses.
lower_rest(U, X, Full, Q, A, Rest, Sig2) :-
    (   U == target -> after(X, Full, Q, A, Sig2) ; Sig2 = Rest ).

after(X, _, Q, A, Sig2) :-
    ctx_after(X, Table),
    memberchk(a(Q, A, Sig2), Table).

%!  with_sig(+Sig, +Ctx0, -Ctx) is det.  Ctx with the signature Sig and its table of what follows each
%   symbol: a(Symbol, Arity, Symbols a clause of it may name), the variables shared with Sig.
with_sig(Sig, X0, X) :-
    ctx_targets(X0, Ts),
    (   Ts = [_, _|_] -> Multi = true ; Multi = false ),
    sig_table(Sig, [], Multi, Table),
    set_sig_of_ctx(Sig, X0, X1), set_after_of_ctx(Table, X1, X).

sig_table([], _, _, []).
sig_table([sym(Q, A, U)|After], Before, Multi, [a(Q, A, Sig2)|Table]) :-
    (   U == target, Multi == true
    ->  include(target_sym, Before, Ts0), reverse(Ts0, Ts), append(Ts, After, Sig2)
    ;   Sig2 = After
    ),
    sig_table(After, [sym(Q, A, U)|Before], Multi, Table).

target_sym(sym(_, _, U)) :- U == target.

lower_used([sym(S, B, U0)|Rest], Q, A, Sig2, U) :-
    nonvar(U0),
    (   Q = S, A = B, Sig2 = Rest, U = U0
    ;   lower_used(Rest, Q, A, Sig2, U)
    ).

%   For a new clause: a bound Q as above; an open Q takes a used symbol or the first unused one,
%   which it marks used.
bind_lower(Q, A, X, Sig1, Sig2) :-
    ctx_sig(X, Full),
    (   Full == none -> fail                         % a fixed program takes no new clause
    ;   nonvar(Q) -> after(X, Full, Q, A, Sig2)
    ;   lower_bind(Sig1, Q, A, Rest, U), lower_rest(U, X, Full, Q, A, Rest, Sig2)
    ).

lower_bind([sym(S, B, U0)|Rest], Q, A, Sig2, U) :-
    (   var(U0)
    ->  U0 = 1, Q = S, A = B, Sig2 = Rest, U = 1
    ;   (   Q = S, A = B, Sig2 = Rest, U = U0
        ;   lower_bind(Rest, Q, A, Sig2, U)
        )
    ).

%   The body of a program item, renamed apart, its head unified with L.
item_instance(sub(Name, Q, A, Subs, _), X, L, Body, Rec) :-
    L = l(Q, A, _),
    ctx_mm(X, MM),
    MM:'$mr'(Name, Subs, L, Body, Rec, Cond, _),
    run_cond(Cond, X).
item_instance(cl(H, B), _, L, Body, false) :-
    L = l(Q, A, _), H = l(Q, A, _),
    copy_term(H-B, L-Body).

%   A metarule's or ibk's condition: Prolog in the background module, except head_pred(P, A), true
%   of the head symbols (Metagol's metagol:type(P, A, head_pred)).
run_cond(true, _) :- !.
run_cond((A, B), X) :- !, run_cond(A, X), run_cond(B, X).
run_cond('$mil_head_pred'(P, A), X) :- !,
    ctx_sig(X, Sig),
    (   Sig == none -> ctx_targets(X, Ts), member(P/A, Ts)
    ;   member(sym(P, A0, _), Sig), ( var(A0) -> true ; A = A0 )
    ;   ctx_heads(X, Hs), member(P/A, Hs)
    ).
run_cond(G, X) :- ctx_bk(X, M), call(M:G).

combine(X, C0, Cf, C) :-
    ctx_combine(X, How),
    (   How == min -> C is min(C0, Cf) ; C is C0 * Cf ),
    ctx_threshold(X, Thr), C >= Thr.

prog_lits(Prog, L) :- foldl(add_lits, Prog, 0, L).
add_lits(sub(_, _, _, _, K), L0, L) :- !, L is L0 + K.
add_lits(cl(_, B), L0, L) :- length(B, K), L is L0 + K.

%!  deduce(+Ctx, +Prog, +Atom, -Conf) is semidet.
%   The first proof of Atom (an l/3) with Prog and no new clause (Metagol's deduce_atom).
deduce(X0, Prog, L, C) :-
    fixed_ctx(X0, Prog, N, X), ctx_depth(X, D),
    once(prove([L], X, [], [], D, Prog, _, N, _, 1.0, C, _, [])).

%   Every proof (nondet) of L with Prog and no new clause.
proves(X0, Prog, L) :-
    fixed_ctx(X0, Prog, N, X), ctx_depth(X, D),
    prove([L], X, [], [], D, Prog, _, N, _, 1.0, _, _, []).

%   The context for proving with Prog as it is: no new clause, and without a signature of the
%   search, the program's own (its targets, then the other symbols its clauses define).
fixed_ctx(X0, Prog, N, X) :-
    length(Prog, N), set_maxn_of_ctx(N, X0, X1),
    (   ctx_sig(X1, none)
    ->  ctx_targets(X1, Ts),
        findall(sym(P, A, target), member(P/A, Ts), TSyms),
        findall(sym(P, A, 1), ( member(I, Prog), item_head(I, P, A), \+ memberchk(P/A, Ts) ), Syms0),
        list_to_set(Syms0, Syms), append(TSyms, Syms, Sig),
        with_sig(Sig, X1, X)
    ;   X = X1
    ).

item_head(sub(_, P, A, _, _), P, A).
item_head(cl(l(P, A, _), _), P, A).

%!  covers(+Ctx, +Prog, +Atom, -Conf, -Trace) is nondet.  Every proof of Atom (an l/3 or an atom)
%   with the fixed program Prog.
covers(X0, Prog, E, C, Trace) :-
    ( E = l(_, _, _) -> L = E ; atom_lit(E, L) ),
    fixed_ctx(X0, Prog, N, X), ctx_depth(X, D),
    prove([L], X, [], [], D, Prog, _, N, _, 1.0, C, Trace, []).

%!  functional_ok(+Ctx, +Prog, +Atoms) is semidet.
%   Metagol's functional check: for no atom does the task's func_test(Atom, Test, Condition) give a
%   Test that a proof with Prog binds so that Condition fails.
functional_ok(X, Prog, Atoms) :-
    (   ctx_functional(X, true)
    ->  ctx_bk(X, M),
        forall(member(l(P, _, Args), Atoms),
               \+ ( M:func_test([P|Args], [TP|TArgs], Cond),
                    length(TArgs, TA), proves(X, Prog, l(TP, TA, TArgs)),
                    \+ mil_safe:checked_call(M, Cond) ))
    ;   true
    ).

%!  repeated_literal(+Ctx, +Item) is semidet.  The clause's body holds one literal twice.
repeated_literal(X, sub(Name, Q, A, Subs, _)) :-
    ctx_mm(X, MM),
    once(MM:'$mr'(Name, Subs, l(Q, A, _), Body, _, _, _)),
    append(_, [L1|Rest], Body), member(L2, Rest), L1 == L2, !.

%!  program_items(+Clauses, -Prog) is det.  Clauses (H :- B terms, B a conjunction) as cl items,
%   in the order given (the first clause first).
program_items(Clauses, Prog) :-
    maplist(clause_item, Clauses, Items),
    reverse(Items, Prog).

clause_item((H :- B), cl(HL, BL)) :- !, atom_lit(H, HL), conj_list(B, Bs), maplist(atom_lit, Bs, BL).
clause_item(H, cl(HL, [])) :- atom_lit(H, HL).

conj_list((A, B), [A|Bs]) :- !, conj_list(B, Bs).
conj_list(true, []) :- !.
conj_list(A, [A]).

%!  item_clause(+Ctx, +Item, -Clause) is det.  A program item as a clause (Head :- Body, or Head
%   for an empty body); ordering literals are not part of it.
item_clause(X, sub(Name, Q, A, Subs, _), Clause) :-
    ctx_mm(X, MM),
    once(MM:'$mr'(Name, Subs, l(Q, A, HArgs), Body, _, _, _)),
    lits_clause(l(Q, A, HArgs), Body, Clause).
item_clause(_, cl(H, Body), Clause) :-
    lits_clause(H, Body, Clause).

lits_clause(l(Q, _, HArgs), Body, Clause) :-
    H =.. [Q|HArgs],
    body_goals(Body, Gs),
    list_conj(Gs, B),
    ( B == true -> Clause = H ; Clause = (H :- B) ).

body_goals([], []).
body_goals([o(_)|Ls], Gs) :- !, body_goals(Ls, Gs).
body_goals([l(P, _, Args)|Ls], [G|Gs]) :- G =.. [P|Args], body_goals(Ls, Gs).

list_conj([], true).
list_conj([A], A) :- !.
list_conj([A|As], (A, B)) :- list_conj(As, B).
