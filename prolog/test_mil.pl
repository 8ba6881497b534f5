/*  plunit tests of the learner.  Run: swipl -g run_tests -t halt prolog/test_mil.pl
    Background knowledge lives in modules of this file (static facts): nothing to clean up.
*/
:- use_module(library(plunit)).
:- use_module(mil).
:- use_module(mil_task).
:- use_module(mil_safe).
:- use_module(shape_bk).

% two objects with faces; confidences as a last argument, as lv3d_bridge:load_scene/3 stores them
bk:face_of(o1, f1, 1.0).  bk:face_of(o1, f2, 1.0).  bk:face_of(o2, f3, 1.0).  bk:face_of(o3, f4, 1.0).
bk:face_of(o4, f5, 1.0).
bk:square(f1, 0.9).       bk:square(f2, 0.6).       bk:square(f3, 0.3).       bk:square(f5, 0.95).
bk:triangle(f4, 1.0).     bk:triangle(f3, 0.7).
bk:adjacent(f1, f2, 1.0). bk:adjacent(f2, f1, 1.0).
bk:perpendicular(f1, f2, 0.8). bk:perpendicular(f2, f1, 0.8).
% they are facts with a confidence, stored under their own name (lv3d_bridge:load_scene/3 declares them so)
bk:'$mil_fact'(P, A, P) :- member(P/A, [face_of/2, square/1, triangle/1, adjacent/2, perpendicular/2]).

shape_task(Pos, Neg, task(bk, [cube/1], [face_of/2, square/1, triangle/1, adjacent/2, perpendicular/2],
                          [part, part2], Pos, Neg)).

% family background for classic tasks, plain Prolog facts (confidence 1)
fam:mother(ann, amy).  fam:mother(amy, amelia).  fam:mother(linda, gavin).
fam:father(steve, amy).  fam:father(gavin, amelia).

:- begin_tests(mil).

test(invents_parent_for_grandparent, [nondet]) :-
    T = task(fam, [grandparent/2], [mother/2, father/2], [ident, chain],
             [grandparent(ann, amelia), grandparent(steve, amelia), grandparent(linda, amelia)],
             [grandparent(amy, amelia)]),
    learn(T, [max_inventions(1)], Prog),
    program_clauses(T, Prog, Cs),
    length(Cs, 3),
    memberchk((grandparent(A, B) :- (I1, I2)), Cs),
    I1 =.. [Inv, A, C], I2 =.. [Inv, C, B],
    Inv \== grandparent.

test(best_proof_multiplies_confidences) :-
    shape_task([], [], T),
    prove_best(T, [], [(cube(X) :- face_of(X, Y), square(Y))], cube(o1), best(C, Trace)),
    C =:= 0.9,
    memberchk(fact(square(f1), 0.9), Trace).

test(min_combination) :-
    shape_task([], [], T),
    prove_best(T, [combine(min)],
               [(cube(X) :- face_of(X, Y), square(Y), adjacent(Y, Z), perpendicular(Y, Z))], cube(o1), best(C, _)),
    C =:= 0.8.                                  % f1: min(0.9, 1, 0.8); f2 gives only 0.6

test(below_threshold_is_not_covered, [fail]) :-
    shape_task([], [], T),
    prove_best(T, [threshold(0.5)], [(cube(X) :- face_of(X, Y), square(Y))], cube(o2), _).

test(derived_predicates_are_proved_over_facts) :-
    T = task(bk, [cube/1], [face_of/2, perpendicular_neighbour/1], [part], [], []),
    bk_module(T, T1),
    prove_best(T1, [], [(cube(X) :- face_of(X, Y), perpendicular_neighbour(Y))], cube(o1), best(C, Trace)),
    C =:= 0.8, memberchk(bk(perpendicular_neighbour(f1)), Trace).

test(learns_consistent_shape_program, [nondet]) :-
    shape_task([cube(o1), cube(o4)], [cube(o3)], T),
    learn(T, [max_clauses(1)], Prog),
    program_clauses(T, Prog, [(cube(_) :- face_of(_, _), square(_))]).

test(noisy_labels_best_program_kept, [nondet]) :-
    % o3 (triangles only) is wrongly labelled a cube: the kept program must still be the square one
    shape_task([cube(o1), cube(o4), cube(o3)], [cube(o2)], T),
    learn_noisy(T, [max_clauses(1), sample_pos(1), sample_neg(1), samples(6)], Prog, score(J, _, TP/3, FP/1, _)),
    program_clauses(T, Prog, [(cube(_) :- face_of(_, _), square(_))]),
    TP =:= 2, FP =:= 0, J > 0.

test(time_limit_is_an_error, [throws(mil_error(time_limit(_)))]) :-
    T = task(fam, [p/2], [mother/2, father/2], [ident, chain, inverse, precon, postcon],
             [p(ann, amelia), p(steve, gavin), p(linda, amy), p(amy, ann)], [p(ann, amy)]),
    learn(T, [max_clauses(8), max_literals(14), max_inventions(4), time_limit(0.3)], _).

test(unknown_body_predicate, [throws(mil_error(unknown_body_pred(nothere/1)))]) :-
    task_check(task(bk, [cube/1], [nothere/1], [part], [cube(o1)], [])).

test(task_file_directive_rejected, [throws(mil_error(task(_, _)))]) :-
    tmp_file_stream(text, File, S), format(S, ":- halt.~n", []), close(S),
    load_task(File, task_test, _, _).

test(task_file_learned, [nondet]) :-
    module_property(mil, file(MilFile)), file_directory_name(MilFile, Dir),
    atom_concat(Dir, '/tasks/even_odd.pl', File),
    load_task(File, task_test, T, S),
    learn(T, S, Prog), program_clauses(T, Prog, Cs),
    length(Cs, 3), memberchk((odd(X) :- prev(X, Y), even(Y)), Cs).

:- end_tests(mil).

:- begin_tests(mil_task).

% a Metagol example file, unchanged in form: the directive loads Metagol, metarule/3, a goal clause
metagol_file(File) :-
    tmp_file_stream(text, File, S),
    format(S, ":- use_module('../metagol').~n", []),
    format(S, "body_pred(mother/2).~nbody_pred(father/2).~n", []),
    format(S, "metarule([P,Q], [P,A,B], [[Q,A,B]]).~nmetarule([P,Q,R], [P,A,B], [[Q,A,C],[R,C,B]]).~n", []),
    format(S, "mother(ann,amy). mother(amy,amelia). father(steve,amy). father(gavin,amelia).~n", []),
    format(S, "a :- Pos = [gp(ann,amelia), gp(steve,amelia)], learn(Pos, [gp(amy,amelia)]).~n", []),
    close(S).

test(metagol_file_read_as_data) :-
    metagol_file(File),
    read_task_file(File, task_test, TF),
    task_goals(TF, [a-a]),
    goal_call(TF, a, 5, Call),
    Call == learn([gp(ann,amelia), gp(steve,amelia)], [gp(amy,amelia)]),
    learn_call(TF, Call, [], exact, program(Cs)),
    program_text(Cs, ['gp(A,B):-mother(A,C),mother(C,B).', 'gp(A,B):-father(A,C),mother(C,B).']).

test(unsafe_clause_refused, [throws(mil_error(task(_, Msg)))]) :-
    tmp_file_stream(text, File, S),
    format(S, "body_pred(p/1).~nmetarules([base]).~np(X) :- shell(X).~npos(t(a)).~n", []), close(S),
    catch(read_task_file(File, task_test, _), mil_error(task(F, Msg)), true),
    sub_atom(Msg, _, _, _, 'line 3: clause p/1 calls shell/1'),
    throw(mil_error(task(F, Msg))).

test(confidence_facts_declared) :-
    tmp_file_stream(text, File, S),
    format(S, "body_pred(p/1).~nmetarules([base]).~n0.4::p(a).~np(b).~npos(t(b)).~n", []), close(S),
    read_task_file(File, task_test, _),
    task_test:'$mil_fact'(p, 1, Store),
    G1 =.. [Store, a, C1], call(task_test:G1), C1 =:= 0.4,
    G2 =.. [Store, b, C2], call(task_test:G2), C2 =:= 1.0.

:- end_tests(mil_task).

:- begin_tests(mil_safe).

where(M, where(test, 1, 'clause p/1', M, bk)).

test(variable_goal_checked_when_called) :-
    where(safe_test, W),
    check_clause((p(G) :- call(G)), W, (p(_) :- C), []),
    C = mil_safe:checked_call(safe_test, _).

test(safe_closure_kept) :-
    where(safe_test, W),
    check_clause((p(L) :- maplist(succ, L, _)), W, (p(_) :- maplist(succ, _, _)), []).

test(runtime_goal_refused, [throws(mil_error(unsafe_call(_)))]) :-
    checked_call(safe_test, halt).

test(catch_refused, [throws(mil_error(task(test, _)))]) :-
    where(safe_test, W),
    check_clause((p(X) :- catch(q(X), _, true)), W, _, _).

:- end_tests(mil_safe).

% the shape background's derived rules, seen from bk as a scene module sees them
bk_module(task(_, Ts, BPs, MRs, P, N), task(bk, Ts, BPs, MRs, P, N)) :-
    ( import_module(bk, shape_bk) -> true ; add_import_module(bk, shape_bk, end) ).
