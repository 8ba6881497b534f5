/*  Task files, read as data: Metagol's example files unchanged, and lv3d's own form.

    A Metagol file (its directives, settings, metarules, background and learning goals):
      :- use_module('../metagol').           loading Metagol: read as nothing to do
      metagol:max_clauses(6).                 Metagol's settings: max_clauses, min_clauses,
                                                max_inv_preds, functional, timeout (unfold_program
                                                is read and has no effect: a warning)
      body_pred(mother/2).                    a background predicate clause bodies may use
      head_pred(p/1).                         a head predicate, for metarule conditions
      metarule([P,Q], [P,A,B], [[Q,A,B]]).    a metarule (named 1, 2, ... in order), or
      metarule(chain, [P,Q,R], [P,A,B], [[Q,A,C],[R,C,B]]).   a named one; a body may be empty,
                                                hold @Goal ordering literals and fixed symbols;
      metarule(Name, Subs, Head, Body) :- Cond.   a condition on its instances (metagol:type(R, 1,
                                                head_pred): R is a head predicate);
      metarule(Subs, (Head :- Body)).         and this form too
      ibk([map,[A|As],[B|Bs],F], [[F,A,B],[map,As,Bs,F]]).   interpreted background knowledge
      func_test(Atom1, Atom2, Condition) :- ...   the functional check's test (with metagol:functional)
      a :- Pos = [...], Neg = [...], learn(Pos, Neg).   a learning goal: learn/2, learn/3 or
      :- time(a).   or  :- ..., learn(Pos, Neg).      learn_seq/2, in a clause or a directive
      mother(ann, amy).  p(X) :- ...          anything else: the background, Prolog the file runs
                                                only through mil_safe's check
    Confidences: 0.9::mother(ann, amy). is a fact that holds with confidence 0.9 (the noisy
    search and the coverage threshold read it).

    lv3d's form, for a file with pos/1 facts and no learning goal:
      metarules([ident, chain]).              metarules of mil:metarule/4 by name
      setting(max_clauses(3)).                overrides of mil:default/1
      pos(grandparent(ann, amelia)).          examples; their predicates are the targets
      neg(grandparent(amy, amelia)).

    The goals a file learns: those its directives run, else every learning goal clause (a clause of
    a 0-ary predicate whose body calls learn/2, learn/3 or learn_seq/2).  A goal runs (its own
    Prolog, checked, under the time limit) only up to its learning call, which names the examples;
    the learning call itself is never run, the learner learns them.

    Every problem is an error term mil_error(task(File, Message)); warnings come back as text.
*/
:- module(mil_task, [ load_task/4,        % +File, +Module, -Task, -Settings  (lv3d's form, one task)
                      read_task_file/3,   % +File, +Module, -TaskFile
                      task_goals/2,       % +TaskFile, -[Name-Goal]
                      goal_call/4,        % +TaskFile, +Goal, +Seconds, -Call
                      learn_call/5,       % +TaskFile, +Call, +Settings, +Mode, -Result
                      program_text/2      % +Clauses, -Lines
                    ]).
:- use_module(library(lists)).
:- use_module(library(apply)).
:- use_module(library(option)).
:- use_module(library(time)).
:- use_module(mil).
:- use_module(mil_prove).
:- use_module(mil_safe).

%   taskfile(File, Module, Format, BodyPreds, Metarules, Decls, Settings, Goals, Warnings)
%   Decls: ibk(Head, Body, Cond), head_pred(P/A), compiled(P/A) (the fixed symbols of metarules
%   and ibk bodies).

%!  load_task(+File, +Module, -Task, -Settings) is det.
%   A file of one task (lv3d's form, or a Metagol file with one learning goal whose examples are
%   plain data): Task = task/7 for mil's API.
load_task(File, M, Task, Settings) :-
    read_task_file(File, M, TF),
    task_goals(TF, Goals),
    (   Goals = [_-G|_] -> true ; problem(File, 'no learning goal') ),
    goal_call(TF, G, 10, Call),
    (   Call = learn(Pos, Neg) -> true ; problem(File, 'the learning goal is a sequence (learn_seq/2)') ),
    call_task(TF, Pos, Neg, [], Task),
    TF = taskfile(_, _, _, _, _, _, Settings, _, _).

%!  read_task_file(+File, +Module, -TaskFile) is det.
%   Read and check File; its background goes into Module (emptied first).
read_task_file(File, M, TF) :-
    read_terms(File, M, Terms),
    clear_module(M),
    (   member(t(T, _), Terms), learning_term(T) -> Format = metagol ; Format = lv3d ),
    foldl(classify(File, Format), Terms, s([], [], [], [], [], [], [], []), S0),
    S0 = s(BK0, BPs0, MRs0, Decls0, Sets0, Dirs0, Exs0, Ws0),
    maplist(reverse, [BK0, BPs0, MRs0, Decls0, Sets0, Dirs0, Exs0, Ws0],
                     [BK0r, BPs1, MRs1, Decls1, Sets, Dirs, Exs, Ws1]),
    confident(File, BK0r, BK),
    declare_own(File, M, BK, Dirs),
    findall(P/A, ( member(c(Cl, _, _), BK), clause_pi(Cl, P/A) ), Own0),
    foldl(assert_clause(File, M), BK, Ws1, Ws2),
    number_metarules(MRs1, 1, MRs2),
    maplist(compile_mr(File, M), MRs2, MRs, Wss3), append(Wss3, Ws3),
    maplist(compile_decl(File, M), Decls1, Decls2, Wss4), append(Wss4, Ws4),
    body_preds(File, M, BPs1, BodyPreds, Ws5),
    compiled_symbols(File, M, BodyPreds, MRs, Decls2, Compiled, Ws6),
    append(Decls2, Compiled, Decls),
    task_settings(File, Sets, Settings),
    goals(File, M, Format, Own0, Dirs, Exs, Goals, Ws7),
    append([Ws2, Ws3, Ws4, Ws5, Ws6, Ws7], Ws8), list_to_set(Ws8, Ws),
    (   MRs == [] -> problem(File, 'no metarules (metarule/3, metarule/4 or metarules/1)') ; true ),
    TF = taskfile(File, M, Format, BodyPreds, MRs, Decls, Settings, Goals, Ws).

%% ---- reading

%   Read in a module of its own, which holds the operators: Metagol's @ (ordering literals), :: (a
%   fact's confidence) and those the file's op/3 directives declare.
read_terms(File, _, Terms) :-
    gensym(mil_read_ops_, Ops),
    op(950, fx, Ops:(@)), op(700, xfx, Ops:(::)),
    catch(setup_call_cleanup(open(File, read, S), read_all(S, File, Ops, Terms), close(S)), E,
          read_error(File, E)).

read_all(S, File, Ops, Terms) :-
    read_term(S, T, [syntax_errors(error), module(Ops), term_position(Pos)]),
    (   T == end_of_file -> Terms = []
    ;   stream_position_data(line_count, Pos, Line),
        (   T = (:- op(P, Ty, N)) -> catch(op(P, Ty, Ops:N), _, problem(File, format('line ~w: bad op/3 directive', [Line])))
        ;   true
        ),
        Terms = [t(T, Line)|Ts], read_all(S, File, Ops, Ts)
    ).

read_error(File, E) :-
    (   E = error(syntax_error(Msg), Ctx) -> syntax_where(Ctx, Where),
        problem(File, format('syntax error ~w: ~w', [Where, Msg]))
    ;   E = error(existence_error(source_sink, _), _) -> problem(File, 'no such file')
    ;   E = error(permission_error(_, _, _), _) -> problem(File, 'cannot be read')
    ;   E = error(resource_error(R), _) -> problem(File, format('a term is nested too deeply to read (~w)', [R]))
    ;   E = mil_error(_) -> throw(E)
    ;   problem(File, format('cannot be read: ~q', [E]))
    ).

syntax_where(stream(_, Line, Col, _), W) :- !, format(atom(W), 'at line ~w column ~w', [Line, Col]).
syntax_where(file(_, Line, Col, _), W) :- !, format(atom(W), 'at line ~w column ~w', [Line, Col]).
syntax_where(_, '').

%   A file is Metagol's when a clause or directive calls a learning predicate.
learning_term((:- G)) :- !, learning_body(G).
learning_term((_ :- B)) :- learning_body(B).

learning_body(G) :- var(G), !, fail.
learning_body(G) :- functor(G, P, A), memberchk(P/A, [learn/2, learn/3, learn_seq/2]), !.
learning_body(G) :- compound(G), G =.. [_|Args], member(X, Args), callable(X), learning_body(X), !.

%% ---- what each term is
%   s(BK clauses, body_preds, metarules, decls, settings, directives, examples, warnings), each
%   newest first.

classify(File, Format, t(T, Line), S0, S) :-
    (   var(T) -> problem(File, format('line ~w: a term is a variable', [Line])) ; true ),
    term_kind(T, Format, Kind),
    add(Kind, File, Line, S0, S).

term_kind((:- D), _, directive(D)) :- !.
term_kind((metarule(N, S, H, B) :- C), _, metarule(N, S, H, B, C)) :- !.
term_kind((metarule(S, H, B) :- C), _, metarule(_, S, H, B, C)) :- !.
term_kind(metarule(N, S, H, B), _, metarule(N, S, H, B, true)) :- !.
term_kind(metarule(S, H, B), _, metarule(_, S, H, B, true)) :- !.
term_kind(metarule(S, (H :- B)), _, metarule(_, S, H, B, true)) :- !.
term_kind((ibk(H, B) :- C), _, ibk(H, B, C)) :- !.
term_kind(ibk(H, B), _, ibk(H, B, true)) :- !.
term_kind(body_pred(PI), _, body_pred(PI)) :- !.
term_kind(head_pred(PI), _, head_pred(PI)) :- !.
term_kind((metagol:S), _, metagol(S)) :- !.
term_kind('::'(C, F), _, conf(C, F)) :- !.
term_kind(('::'(_, _) :- _), _, conf_rule) :- !.
term_kind(pos(E), lv3d, pos(E)) :- !.
term_kind(neg(E), lv3d, neg(E)) :- !.
term_kind(setting(O), lv3d, setting(O)) :- !.
term_kind(metarules(L), lv3d, metarules(L)) :- !.
term_kind(T, _, clause(T)).

add(directive(D), _, L, s(B, P, M, D0, Se, Di, E, W), s(B, P, M, D0, Se, [d(D, L)|Di], E, W)).
add(metarule(N, Su, H, Bd, C), _, L, s(B, P, M, D0, Se, Di, E, W), s(B, P, [m(N, Su, H, Bd, C, L)|M], D0, Se, Di, E, W)).
add(ibk(H, Bd, C), _, L, s(B, P, M, D0, Se, Di, E, W), s(B, P, M, [ibk(H, Bd, C, L)|D0], Se, Di, E, W)).
add(body_pred(PI), _, L, s(B, P, M, D0, Se, Di, E, W), s(B, [bp(PI, L)|P], M, D0, Se, Di, E, W)).
add(head_pred(PI), File, L, s(B, P, M, D0, Se, Di, E, W), s(B, P, M, [head_pred(PI)|D0], Se, Di, E, W)) :-
    pi(File, L, head_pred, PI).
add(metagol(S), File, L, s(B, P, M, D0, Se, Di, E, W0), s(B, P, M, D0, Se1, Di, E, W)) :-
    metagol_setting(File, L, S, Se, Se1, W0, W).
add(conf(C, F), File, L, s(B, P, M, D0, Se, Di, E, W), s([c(F, L, conf(C))|B], P, M, D0, Se, Di, E, W)) :-
    (   number(C), C > 0, C =< 1 -> true
    ;   problem(File, format('line ~w: ~q::~q: a confidence is a number in (0, 1]', [L, C, F]))
    ),
    (   callable(F), F \= (_ :- _), F \= _:_ -> true
    ;   problem(File, format('line ~w: ~q: a confidence goes on a fact', [L, F]))
    ).
add(conf_rule, File, L, _, _) :- problem(File, format('line ~w: a confidence goes on a fact, not on a rule', [L])).
add(pos(X), File, L, s(B, P, M, D0, Se, Di, E, W), s(B, P, M, D0, Se, Di, [pos(X)|E], W)) :- example(File, L, X).
add(neg(X), File, L, s(B, P, M, D0, Se, Di, E, W), s(B, P, M, D0, Se, Di, [neg(X)|E], W)) :- example(File, L, X).
add(setting(O), File, L, s(B, P, M, D0, Se, Di, E, W), s(B, P, M, D0, [O|Se], Di, E, W)) :-
    (   compound(O), functor(O, F, 1), functor(G, F, 1), mil:default(G) -> true
    ;   problem(File, format('line ~w: unknown setting ~q', [L, O]))
    ).
add(metarules(Ns), File, L, s(B, P, M, D0, Se, Di, E, W), s(B, P, M1, D0, Se, Di, E, W)) :-
    (   is_list(Ns), maplist(atom, Ns) -> true
    ;   problem(File, format('line ~w: metarules(~q): expected a list of names', [L, Ns]))
    ),
    foldl(named_metarule(File, L), Ns, M, M1).
add(clause(T), File, L, s(B, P, M, D0, Se, Di, E, W), s([c(T, L, plain)|B], P, M, D0, Se, Di, E, W)) :-
    (   T = (H :- _) -> true ; H = T ),
    (   var(H) -> problem(File, format('line ~w: a clause head is a variable', [L]))
    ;   H = Mod:_ -> problem(File, format('line ~w: the clause is module-qualified (~q): a task defines its own predicates only', [L, Mod]))
    ;   \+ callable(H) -> problem(File, format('line ~w: the clause head ~q is not an atom', [L, H]))
    ;   functor(H, Nm, Ar), sub_atom(Nm, 0, _, _, '$')
    ->  problem(File, format('line ~w: clause ~q/~q: names starting with $ are reserved', [L, Nm, Ar]))
    ;   true
    ).

named_metarule(File, L, N, M0, [m(N, S, H, B, true, L)|M0]) :-
    (   mil:metarule(N, S, H, B) -> true ; problem(File, format('line ~w: unknown metarule ~q', [L, N])) ).

example(File, L, X) :-
    (   callable(X) -> true ; problem(File, format('line ~w: example ~q is not an atom', [L, X])) ).

pi(File, L, What, PI) :-
    (   PI = P/A, atom(P), integer(A), A >= 0 -> true
    ;   problem(File, format('line ~w: ~w(~q): expected Name/Arity', [L, What, PI]))
    ).

metagol_setting(File, L, S, Se0, Se, W0, W) :-
    (   S == functional -> Se = [functional(true)|Se0], W = W0
    ;   S = max_clauses(N), integer(N), N >= 1 -> Se = [max_clauses(N)|Se0], W = W0
    ;   S = min_clauses(N), integer(N), N >= 1 -> Se = [min_clauses(N)|Se0], W = W0
    ;   S = max_inv_preds(N), integer(N), N >= 0 -> Se = [max_inventions(N)|Se0], W = W0
    ;   S = timeout(T), number(T), T > 0 -> Se = [time_limit(T)|Se0], W = W0
    ;   S == unfold_program
    ->  Se = Se0, format(atom(Wn), 'line ~w: metagol:unfold_program has no effect here (the program prints as found)', [L]),
        W = [Wn|W0]
    ;   problem(File, format('line ~w: unknown Metagol setting metagol:~q', [L, S]))
    ).

%% ---- the background

clear_module(M) :-
    forall(( current_predicate(M:P/A), functor(H, P, A), \+ predicate_property(M:H, imported_from(_)) ),
           abolish(M:P/A)).

clause_pi(T, P/A) :-
    (   T = (H :- _) -> true ; H = T ),
    functor(H, P, A).

%   A predicate with a fact that has a confidence is a fact with a confidence throughout: its facts
%   without one hold with confidence 1; a rule for it has no confidence to give and is refused.
confident(File, BK0, BK) :-
    findall(P/A, ( member(c(F, _, conf(_)), BK0), functor(F, P, A) ), Ps0), sort(Ps0, Ps),
    maplist(confident_clause(File, Ps), BK0, BK).

confident_clause(File, Ps, c(T, L, plain), C) :- !,
    (   T = (H :- B), B \== true -> true ; H = T, B = true ),
    functor(H, P, A),
    (   memberchk(P/A, Ps)
    ->  (   B == true -> C = c(H, L, conf(1.0))
        ;   problem(File, format('line ~w: ~q/~q has facts with confidences; a rule for it has none to give', [L, P, A]))
        )
    ;   C = c(T, L, plain)
    ).
confident_clause(_, _, C, C).

%   The task's own predicates (its clauses' and those declared dynamic), before any clause is
%   checked: a clause may call one defined later.
declare_own(File, M, BK, Dirs) :-
    dynamic(M:'$mil_own'/2), dynamic(M:'$mil_fact'/3),
    forall(( member(c(T, _, _), BK), clause_pi(T, P/A) ),
           ( M:'$mil_own'(P, A) -> true ; assertz(M:'$mil_own'(P, A)) )),
    forall(member(d(dynamic(Spec), L), Dirs), declare_dynamic(File, L, M, Spec)).

assert_clause(File, M, c(T, L, plain), W0, W) :-
    (   T = (H :- _) -> true ; H = T ),
    functor(H, P, A),
    (   learning_term((H :- T)) -> Role = goal ; Role = bk ),
    format(atom(What), 'clause ~q/~q', [P, A]),
    check_clause(T, where(File, L, What, M, Role), T1, Ws),
    assertz(M:T1),
    append(W0, Ws, W).
assert_clause(_, M, c(F, _, conf(C)), W, W) :-
    functor(F, P, A),
    (   M:'$mil_fact'(P, A, Store) -> true
    ;   atom_concat('$mil_cf_', P, Store),
        assertz(M:'$mil_fact'(P, A, Store)),
        functor(H, P, A), H =.. [P|Args], append(Args, [_], Args1), B =.. [Store|Args1],
        assertz(M:(H :- B))
    ),
    F =.. [_|Args2], append(Args2, [C], Args3), G =.. [Store|Args3],
    assertz(M:G).

%% ---- metarules and declarations

%   Unnamed metarules are named 1, 2, ... in the order they come (Metagol's).
number_metarules([], _, []).
number_metarules([m(N0, S, H, B, C, L)|Ms], I, [m(N, S, H, B, C, L)|Ns]) :-
    (   var(N0) -> N = I, I1 is I + 1 ; N = N0, I1 = I ),
    number_metarules(Ms, I1, Ns).

compile_mr(File, M, m(N, S, H, B, C, L), MR, Ws) :-
    (   is_list(S), is_list(H), H = [_|_], is_list(B) -> true
    ;   problem(File, format('line ~w: metarule ~q: expected metarule(Name, Subs, [P|Args], [[Q|Args], ...])', [L, N]))
    ),
    format(atom(What), 'metarule ~q', [N]),
    W = where(File, L, What, M, bk),
    maplist(body_element(File, L, W), B, B1, Wss), append(Wss, Ws0),
    condition(C, W, C1, Ws1),
    append(Ws0, Ws1, Ws),
    compile_metarule(metarule(N, S, H, B1, C1), MR).

body_element(_, _, W, @(G), @(G1), Ws) :- !, check_goal(G, W, G1, Ws).
body_element(_, _, _, [Q|Args], [Q|Args], []) :- !.
body_element(File, L, _, X, _, _) :-
    problem(File, format('line ~w: ~q is neither an atom [P|Args] nor an ordering literal @Goal', [L, X])).

%   A condition, a conjunction: metagol:type(P, A, head_pred) is '$mil_head_pred'(P, A) (P is a
%   head predicate, mil_prove reads it), the rest is checked Prolog.
condition(true, _, true, []) :- !.
condition((A, B), W, (A1, B1), Ws) :- !,
    condition(A, W, A1, Ws1), condition(B, W, B1, Ws2), append(Ws1, Ws2, Ws).
condition(metagol:type(P, A, head_pred), _, '$mil_head_pred'(P, A), []) :- !.
condition(C, W, C1, Ws) :-
    check_goal(C, W, C1, Ws).

compile_decl(File, M, ibk(H, B, C, L), ibk(l(P, A, Args), Body, Cond), Ws) :- !,
    (   is_list(H), H = [P|Args], atom(P), is_list(B) -> length(Args, A)
    ;   problem(File, format('line ~w: ibk(~q, ...): expected ibk([P|Args], [[Q|Args], ...])', [L, H]))
    ),
    W = where(File, L, 'ibk', M, bk),
    maplist(body_element(File, L, W), B, B1, Wss), append(Wss, Ws0),
    condition(C, W, Cond, Ws1), append(Ws0, Ws1, Ws),
    compile_metarule(metarule(ibk, [], H, B1, true), mr(_, _, _, Body, _, _, _)).
compile_decl(_, _, D, D, []).

%   body_pred(P/A): own, or a safe built-in (succ/2); one the file does not define is dropped with
%   a warning (Metagol's); P/A's kind is its own (a fact with confidences only when declared so).
body_preds(File, M, BPs0, BodyPreds, Ws) :-
    foldl(body_pred(File, M), BPs0, []-[], BPs1-Ws0),
    reverse(BPs1, BPs2), list_to_set(BPs2, BodyPreds), reverse(Ws0, Ws).

body_pred(File, M, bp(PI, L), B0-W0, B-W) :-
    pi(File, L, body_pred, PI), PI = P/A,
    check_pred(P/A, where(File, L, body_pred, M, bk), Kind),
    (   Kind == unknown
    ->  B = B0, format(atom(Wn), 'line ~w: body_pred ~q/~q: the file does not define it; left out', [L, P, A]),
        W = [Wn|W0]
    ;   B = [P/A|B0], W = W0
    ).

%   Fixed symbols of metarule and ibk bodies that are not body predicates, head predicates or
%   interpreted: called as Prolog (Metagol's compiled predicates), so checked like a body_pred.
compiled_symbols(File, M, BodyPreds, MRs, Decls, Compiled, Ws) :-
    findall(P/A, ( member(mr(_, _, _, Body, _, _, _), MRs), member(l(P, A, _), Body), atom(P) ), Ps1),
    findall(P/A, ( member(ibk(_, Body, _), Decls), member(l(P, A, _), Body), atom(P) ), Ps2),
    append(Ps1, Ps2, Ps0), list_to_set(Ps0, Ps),
    findall(P/A, member(ibk(l(P, A, _), _, _), Decls), IbkHeads),
    findall(compiled(P/A)-Wn,
            ( member(P/A, Ps), \+ memberchk(P/A, BodyPreds), \+ memberchk(P/A, IbkHeads),
              check_pred(P/A, where(File, 0, 'a metarule or ibk body', M, bk), Kind),
              (   Kind == unknown
              ->  format(atom(Wn), '~q/~q, named in a metarule or ibk body, is not defined', [P, A])
              ;   Wn = none
              ) ),
            Pairs),
    pairs_keys_values(Pairs, Compiled, Ws0),
    exclude(==(none), Ws0, Ws).

task_settings(File, Sets, Settings) :-
    catch(settings(Sets, _), E, problem(File, format('bad settings ~q: ~q', [Sets, E]))),
    Settings = Sets.

%% ---- the learning goals

goals(File, _, lv3d, _, Dirs, Exs, [task-examples(Pos, Neg)], []) :- !,
    (   Dirs = [d(D, L)|_] -> problem(File, format('line ~w: directive :- ~q: a task file is data and runs nothing', [L, D])) ; true ),
    findall(E, member(pos(E), Exs), Pos),
    findall(E, member(neg(E), Exs), Neg),
    (   Pos == [] -> problem(File, 'no positive examples (pos/1)') ; true ).
goals(File, M, metagol, Own, Dirs, _, Goals, Ws) :-
    foldl(directive(File, M, Own), Dirs, []-[], Gs0-Ws0),
    reverse(Gs0, DirGoals), reverse(Ws0, Ws),
    (   DirGoals \== [] -> Goals = DirGoals
    ;   findall(N-N, ( member(N/0, Own), M:clause(N, B), learning_body_checked(B) ), Gs1),
        list_to_set(Gs1, Goals)
    ),
    (   Goals == [] -> problem(File, 'no learning goal: no clause or directive calls learn/2, learn/3 or learn_seq/2') ; true ).

learning_body_checked(B) :- sub_term(S, B), compound(S), S = mil_safe:captured(_), !.

%   A directive: loading Metagol or a safe library, a declaration, or a learning goal.
directive(File, M, Own, d(D, L), G0-W0, G-W) :-
    (   loads_metagol(D) -> G = G0, W = W0
    ;   D = use_module(library(Lib)), safe_library(Lib) -> G = G0, W = W0
    ;   D = use_module(library(Lib), _), safe_library(Lib) -> G = G0, W = W0
    ;   D = dynamic(_) -> G = G0, W = W0
    ;   D = discontiguous(_) -> G = G0, W = W0
    ;   D = style_check(_) -> G = G0, W = W0
    ;   D = op(_, _, _) -> G = G0, W = W0
    ;   learning_directive(D, Own)
    ->  check_goal(D, where(File, L, 'the directive', M, goal), D1, Ws),
        format(atom(Name), 'directive at line ~w', [L]),
        G = [Name-D1|G0], append(Ws, W0, W)
    ;   problem(File, format('line ~w: directive :- ~q: a task file is data and runs nothing (only learning goals and declarations are read)', [L, D]))
    ).

loads_metagol(G) :- var(G), !, fail.
loads_metagol(use_module(F)) :- metagol_file(F).
loads_metagol(use_module(F, _)) :- metagol_file(F).
loads_metagol(ensure_loaded(F)) :- metagol_file(F).
loads_metagol(consult(F)) :- metagol_file(F).
loads_metagol([F]) :- metagol_file(F).

metagol_file(F) :- atomic(F), file_base_name(F, B), file_name_extension(metagol, _, B).

safe_library(L) :- memberchk(L, [lists, apply, random, system, aggregate, pairs, ordsets, between, solution_sequences]).

declare_dynamic(File, L, M, Spec) :-
    (   pis(Spec, PIs) -> true ; problem(File, format('line ~w: dynamic(~q): expected Name/Arity', [L, Spec])) ),
    forall(member(P/A, PIs), ( dynamic(M:P/A), ( M:'$mil_own'(P, A) -> true ; assertz(M:'$mil_own'(P, A)) ) )).

pis(V, _) :- var(V), !, fail.
pis((A, B), L) :- !, pis(A, L1), pis(B, L2), append(L1, L2, L).
pis([], []) :- !.
pis([X|Xs], L) :- !, pis(X, L1), pis(Xs, L2), append(L1, L2, L).
pis(P/A, [P/A]) :- atom(P), integer(A).

%   A directive that learns: it calls a learning predicate, or a 0-ary predicate of the file (a
%   goal clause: time(a), a).
learning_directive(D, Own) :-
    (   learning_body(D) -> true
    ;   sub_term(S, D), atom(S), memberchk(S/0, Own) -> true
    ).

%!  task_goals(+TaskFile, -Goals) is det.  [Name-Goal]: the goals the file learns, in order.
task_goals(TF, Goals) :- arg(8, TF, Goals).

%!  goal_call(+TaskFile, +Goal, +Seconds, -Call) is det.
%   Run Goal (its own checked Prolog) up to its learning call: Call = learn(Pos, Neg) or
%   learn_seq([Pos/Neg, ...]).
goal_call(TF, examples(Pos, Neg), _, learn(Pos, Neg)) :- !, arg(1, TF, _).
goal_call(TF, G, T, Call) :-
    TF = taskfile(File, M, _, _, _, _, _, _, _),
    catch(( timed(T, M:G) -> R = done ; R = failed ), E, R = caught(E)),
    (   R = caught(mil_goal(C)) -> learning_call(File, C, Call)
    ;   R == done -> problem(File, format('the goal ~q ended without calling learn/2, learn/3 or learn_seq/2', [G]))
    ;   R == failed -> problem(File, format('the goal ~q failed before its learning call', [G]))
    ;   R = caught(mil_error(time_limit(_))) -> problem(File, format('the goal ~q did not reach its learning call within ~w s', [G, T]))
    ;   R = caught(E1) -> goal_error(File, G, E1)
    ).

goal_error(File, G, E) :-
    message_to_codes(E, Msg),
    problem(File, format('the goal ~q: ~s', [G, Msg])).

message_to_codes(E, Codes) :-
    catch(( message_to_codes(E, [], Codes0) -> true ; fail ), _, fail), !, Codes = Codes0.
message_to_codes(E, Codes) :- format(codes(Codes), '~q', [E]).

message_to_codes(E, _, Codes) :-
    '$messages':translate_message(E, Lines, []),
    with_output_to(codes(Codes0), print_message_lines(current_output, '', Lines)),
    exclude(==(0'\n), Codes0, Codes).

learning_call(File, C, Call) :-
    (   C = learn(Pos, Neg) -> true
    ;   C = learn(Pos, Neg, _) -> true
    ;   C = learn_seq(Seq, _) -> true
    ),
    (   nonvar(Seq)
    ->  (   is_list(Seq), maplist(pos_neg, Seq, Tasks) -> Call = learn_seq(Tasks)
        ;   problem(File, format('learn_seq(~q, _): expected a list of Pos/Neg', [Seq]))
        )
    ;   examples_list(File, Pos), examples_list(File, Neg), Call = learn(Pos, Neg)
    ).

pos_neg(P/N, P-N) :- is_list(P), is_list(N).

examples_list(File, L) :-
    (   is_list(L), maplist(callable, L) -> true
    ;   problem(File, format('the examples ~q are not a list of atoms', [L]))
    ).

%!  learn_call(+TaskFile, +Call, +Settings, +Mode, -Result) is det.
%   Learn the call's task(s).  Mode exact (Metagol's search) or noisy (mil_noisy).  Result:
%   program(Clauses) or none (no program within the bounds); a sequence gives the programs of its
%   tasks together, as Metagol prints them.
learn_call(TF, learn(Pos, Neg), Settings, Mode, Result) :- !,
    (   Pos == [] -> Result = none
    ;   call_task(TF, Pos, Neg, [], Task),
        learn_task(Task, Settings, Mode, Prog),
        (   Prog == none -> Result = none
        ;   program_clauses(Task, Prog, Clauses), Result = program(Clauses)
        )
    ).
learn_call(TF, learn_seq(Tasks), Settings, Mode, program(Clauses)) :-
    foldl(seq_task(TF, Settings, Mode), Tasks, []-[], Progs-_),
    reverse(Progs, InOrder), append(InOrder, All),
    reverse(All, Clauses).

%   A task of a sequence: learned with the predicates learned before it as body predicates (their
%   clauses join the background), Metagol's learn_seq.
seq_task(TF, Settings, Mode, Pos-Neg, Ps0-Extra0, [Cs|Ps0]-Extra) :-
    TF = taskfile(_, M, _, _, _, _, _, _, _),
    (   Pos \== [], call_task(TF, Pos, Neg, Extra0, Task),
        learn_task(Task, Settings, Mode, Prog), Prog \== none
    ->  program_clauses(Task, Prog, Cs1), reverse(Cs1, Cs),
        forall(member(C, Cs1), assertz(M:C)),
        findall(P/A, ( member(C, Cs1), ( C = (H :- _) -> true ; H = C ), functor(H, P, A) ), PAs0),
        list_to_set(PAs0, PAs),
        forall(member(P/A, PAs), ( M:'$mil_own'(P, A) -> true ; assertz(M:'$mil_own'(P, A)) )),
        exclude([PA]>>memberchk(PA, Extra0), PAs, New), append(Extra0, New, Extra)
    ;   Cs = [], Extra = Extra0
    ).

learn_task(Task, Settings, exact, Prog) :-
    (   learn(Task, Settings, P) -> Prog = P ; Prog = none ).
learn_task(Task, Settings0, noisy, Prog) :-
    sample_size(Task, Settings0, Settings),
    (   learn_noisy(Task, Settings, P, _) -> Prog = P ; Prog = none ).

%   For a task file, a sample holds two thirds of the positives (at least two) unless a setting
%   says otherwise: with one wrong label in nine, a third of such samples leave it out, and a
%   sample still needs as many clauses as the whole concept.
sample_size(Task, Settings, Settings) :- memberchk(sample_pos(_), Settings), !, arg(1, Task, _).
sample_size(Task, Settings, [sample_pos(K)|Settings]) :-
    arg(5, Task, Pos), length(Pos, NP), K is max(2, ceiling(2 * NP / 3)).

%   The task of a learning call: the targets are the examples' predicates (Metagol: the first
%   positive's; lv3d: each, in order).
call_task(TF, Pos, Neg, Extra, task(M, Targets, BodyPreds, MRs, Pos, Neg, Decls)) :-
    TF = taskfile(File, M, Format, BodyPreds0, MRs, Decls, _, _, _),
    append(BodyPreds0, Extra, BodyPreds),
    (   Format == metagol -> Pos = [E|_], functor(E, P, A), Targets = [P/A]
    ;   findall(P/A, ( member(E, Pos), functor(E, P, A) ), Ts0), list_to_set(Ts0, Targets),
        forall(member(E, Neg), ( functor(E, P, A), memberchk(P/A, Targets) -> true
                               ; problem(File, format('negative example ~q is not about a target', [E])) ))
    ),
    catch(task_check(task(M, Targets, BodyPreds, MRs, Pos, Neg, Decls)), mil_error(Why), unusable(File, Why)).

unusable(File, unknown_body_pred(P/A)) :- !,
    problem(File, format('body predicate ~w/~w is not defined in the file', [P, A])).
unusable(File, unknown_metarule(N)) :- !, problem(File, format('unknown metarule ~q', [N])).
unusable(File, Why) :- problem(File, format('~q', [Why])).

%!  program_text(+Clauses, -Lines) is det.  Each clause as Metagol prints it: one line, ~q, with
%   its variables named A, B, ...
program_text(Clauses, Lines) :-
    maplist(clause_line, Clauses, Lines).

clause_line(C0, Line) :-
    copy_term(C0, C), numbervars(C, 0, _),
    format(atom(Line), '~q.', [C]).

problem(File, format(F, Args)) :- !, format(atom(Msg), F, Args), throw(mil_error(task(File, Msg))).
problem(File, Msg) :- throw(mil_error(task(File, Msg))).
