/*  Metagol-style task files, read as data (never consulted: a task file runs no code at load).

      body_pred(mother/2).                    a background predicate clause bodies may use
      metarules([ident, chain]).              metarules from mil:metarule/4, by name
      metarule(Name, Subs, Head, Body).       or one of the task's own, in mil's list form
      setting(max_clauses(3)).                overrides of mil:default/1
      pos(grandparent(ann, amelia)).          positive and negative examples; their predicates
      neg(grandparent(amy, amelia)).            are the targets (several are learned together)
      mother(ann, amy).                       anything else: background knowledge (facts, rules)

    Every problem is an error term mil_error(task(File, Problem)).
*/
:- module(mil_task, [load_task/4]).
:- use_module(library(lists)).
:- use_module(library(apply)).
:- use_module(mil).

%!  load_task(+File, +Module, -Task, -Settings) is det.
%   Read File; its background knowledge goes into Module (emptied first).
load_task(File, M, task(M, Targets, BodyPreds, MRs, Pos, Neg), Settings) :-
    read_terms(File, Terms),
    clear_module(M),
    foldl(task_term(File, M), Terms, t([], [], [], [], []), t(BPs0, MRs0, Ss0, Pos0, Neg0)),
    maplist(reverse, [BPs0, MRs0, Ss0, Pos0, Neg0], [BodyPreds, MRs1, Settings, Pos, Neg]),
    (   Pos == [] -> problem(File, 'no positive examples (pos/1)') ; true ),
    (   MRs1 == [] -> problem(File, 'no metarules (metarules/1 or metarule/4)') ; true ),
    append(MRs1, MRs),
    findall(P/A, (member(E, Pos), functor(E, P, A)), Ts0), sort(Ts0, Targets),
    forall(member(E, Neg), ( functor(E, P, A), memberchk(P/A, Targets) -> true
                           ; problem(File, format('negative example ~q is not about a target', [E])) )),
    catch(task_check(task(M, Targets, BodyPreds, MRs, Pos, Neg)), mil_error(Why), unusable(File, Why)).

unusable(File, unknown_body_pred(P/A)) :- !,
    problem(File, format('body predicate ~w/~w is not defined in the file', [P, A])).
unusable(File, unknown_metarule(N)) :- !, problem(File, format('unknown metarule ~q', [N])).
unusable(File, Why) :- problem(File, format('~q', [Why])).

read_terms(File, Terms) :-
    catch(setup_call_cleanup(open(File, read, S), read_all(S, Terms), close(S)), E,
          ( E = error(syntax_error(Msg), Ctx) -> syntax_where(Ctx, Where),
                problem(File, format('syntax error ~w: ~w', [Where, Msg]))
          ; E = error(existence_error(source_sink, _), _) -> problem(File, 'no such file')
          ; E = error(permission_error(_, _, _), _) -> problem(File, 'cannot be read')
          ; throw(E) )).

read_all(S, Terms) :-
    read_term(S, T, [syntax_errors(error)]),
    (   T == end_of_file -> Terms = [] ; Terms = [T|Ts], read_all(S, Ts) ).

syntax_where(stream(_, Line, Col, _), W) :- !, format(atom(W), 'at line ~w column ~w', [Line, Col]).
syntax_where(file(_, Line, Col, _), W) :- !, format(atom(W), 'at line ~w column ~w', [Line, Col]).
syntax_where(_, '').

task_term(File, _, (:- D), _, _) :- !,
    problem(File, format('directive :- ~q: a task file is data and runs nothing', [D])).
task_term(File, _, body_pred(S), t(B, M, Se, P, N), t([S|B], M, Se, P, N)) :- !,
    ( S = Name/A, atom(Name), integer(A), A >= 0 -> true
    ; problem(File, format('body_pred(~q): expected Name/Arity', [S])) ).
task_term(File, _, metarules(L), t(B, M, Se, P, N), t(B, [L|M], Se, P, N)) :- !,
    ( is_list(L), maplist(atom, L) -> true ; problem(File, format('metarules(~q): expected a list of names', [L])) ),
    forall(member(X, L), ( mil:metarule(X, _, _, _) -> true ; problem(File, format('unknown metarule ~q', [X])) )).
task_term(File, _, metarule(Nm, Subs, H, Bd), t(B, M, Se, P, N), t(B, [[metarule(Nm, Subs, H, Bd)]|M], Se, P, N)) :- !,
    ( atom(Nm), is_list(Subs), is_list(H), is_list(Bd), Bd \== [] -> true
    ; problem(File, format('metarule ~q: expected metarule(Name, Subs, [P|Args], [[Q|Args]|...])', [Nm])) ).
task_term(File, _, setting(O), t(B, M, Se, P, N), t(B, M, [O|Se], P, N)) :- !,
    ( compound(O), functor(O, F, 1), functor(G, F, 1), mil:default(G) -> true
    ; problem(File, format('unknown setting ~q', [O])) ).
task_term(File, _, pos(E), t(B, M, Se, P, N), t(B, M, Se, [E|P], N)) :- !, example(File, E).
task_term(File, _, neg(E), t(B, M, Se, P, N), t(B, M, Se, P, [E|N])) :- !, example(File, E).
task_term(_, M, Clause, S, S) :- assertz(M:Clause).

example(File, E) :-
    ( callable(E), ground(E) -> true ; problem(File, format('example ~q is not a ground atom', [E])) ).

clear_module(M) :-
    forall(( current_predicate(M:P/A), functor(H, P, A), \+ predicate_property(M:H, imported_from(_)) ),
           abolish(M:P/A)).

problem(File, format(F, Args)) :- !, format(atom(Msg), F, Args), throw(mil_error(task(File, Msg))).
problem(File, Msg) :- throw(mil_error(task(File, Msg))).
