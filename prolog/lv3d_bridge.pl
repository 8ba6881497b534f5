/*  The learner as lv3d's Python side calls it (lv3d/learn/engine.py): scenes' facts in a
    module per use, fit one target, classify with fixed programs, check program files.
    Everything handed back is atoms and numbers, which pyswip maps to str and float.
*/
:- module(lv3d_bridge, [guard/4, load_scene/3, drop_scene/1, fit/8, classify/6, check_program/4]).
:- use_module(library(lists)).
:- use_module(library(apply)).
:- use_module(library(solution_sequences)).
:- use_module(mil).
:- use_module(shape_bk).

%!  guard(:Goal, -Kind, -Where, -Message) is nondet.
%   Kind = ok, or when Goal throws (atoms): Kind is time_limit, input (a bad task or program
%   file: Where names it), learn or prolog.
:- meta_predicate guard(0, -, -, -).
guard(Goal, Kind, Where, Msg) :-
    catch((call(Goal), Kind = ok, Where = '', Msg = ''), E, error_status(E, error(Kind, Where, Msg))).

error_status(mil_error(time_limit(T)), error(time_limit, '', Msg)) :- !,
    format(atom(Msg), 'the search reached its time limit of ~w s without an answer', [T]).
error_status(mil_error(classify_time_limit(Label, T)), error(time_limit, '', Msg)) :- !,
    format(atom(Msg), 'the best proof with the program of ~w was not found within the time limit of ~w s', [Label, T]).
error_status(mil_error(task(F, M)), error(input, F, M)) :- !.
error_status(mil_error(program(F, M)), error(input, F, M)) :- !.
error_status(mil_error(X), error(learn, '', Msg)) :- !, format(atom(Msg), '~q', [X]).
error_status(E, error(prolog, '', Msg)) :-
    catch(message_text(E, Msg), _, fail), !.
error_status(E, error(prolog, '', Msg)) :- format(atom(Msg), '~q', [E]).

message_text(E, Msg) :-
    '$messages':translate_message(E, Lines, []),
    with_output_to(string(S), print_message_lines(current_output, '', Lines)),
    split_string(S, "", " \n", [T]), atom_string(Msg, T).

%!  load_scene(+M, +FactPreds, +Facts) is det.
%   Module M holds Facts (atoms with the confidence as a last argument, square(f1, 0.97)) and
%   sees shape_bk's derived rules.  FactPreds: every Name/Arity of the fact contract, declared
%   even when no fact uses it, so that the learner knows its kind.
load_scene(M, FactPreds, Facts) :-
    drop_scene(M),
    forall(member(P/A, FactPreds), ( A1 is A + 1, dynamic(M:P/A1) )),
    dynamic(M:'$mil_fact'/3),
    forall(member(P/A, FactPreds), assertz(M:'$mil_fact'(P, A, P))),
    ( import_module(M, shape_bk) -> true ; add_import_module(M, shape_bk, end) ),
    maplist(assert_fact(M), Facts).

assert_fact(M, F) :- assertz(M:F).

%!  drop_scene(+M) is det.  Empty M (its facts only; the module name is reused).
drop_scene(M) :-
    forall(( current_predicate(M:P/A), functor(H, P, A), predicate_property(M:H, dynamic),
             \+ predicate_property(M:H, imported_from(_)) ),
           retractall(M:H)).

%!  fit(+M, +Target, +BodyPreds, +Metarules, +PosObjs, +NegObjs, +Settings, -Result) is semidet.
%   Learn Target/1 over the objects in M.  Result = result(Clauses, J, Soft, TP, NPos, FP, NNeg, Thr),
%   Clauses as atoms (portray_clause text), Thr the coverage threshold the program takes.  Fails when no hypothesis covers any sample.
fit(M, Target, BodyPreds, MRs, PosObjs, NegObjs, Settings, result(Texts, J, Soft, TP, NP, FP, NN, Thr)) :-
    maplist(example(Target), PosObjs, Pos), maplist(example(Target), NegObjs, Neg),
    Task = task(M, [Target/1], BodyPreds, MRs, Pos, Neg),
    % the reference population of the size principle (mil:best_specific/6): every object of
    % the scenes, the clutter around the targets included
    findall(E, ( distinct(O, M:face_of(O, _, _)), example(Target, O, E) ), Ref),
    learn_noisy(Task, [reference(Ref)|Settings], Prog, score(J, Soft, TP/NP, FP/NN, Thr)),
    program_clauses(Task, Prog, Clauses),
    maplist(clause_text, Clauses, Texts).

example(Target, O, E) :- E =.. [Target, O].

clause_text(C, Text) :-
    with_output_to(string(S), portray_clause(C)),
    split_string(S, "", " \n", [T]), atom_string(Text, T).

%!  classify(+M, +Programs, +BodyPreds, +Obj, +Settings, -Results) is det.
%   Programs = [Label-ClauseTexts, ...].  Results = [[Label, Conf, Trace], ...] for the labels
%   whose program proves Label(Obj) (best proof); Trace = [[Kind, AtomText, Conf], ...], Kind
%   fact, derived, call, clause or missing (a fact the scene lacks, under option miss(Eps))
%   (lists, which pyswip hands back as lists; compound terms would come back as text).
classify(M, Programs, BodyPreds, Obj, Settings, Results) :-
    findall([Label, C, Trace],
            ( member(Label-Texts, Programs),
              maplist(text_clause, Texts, Clauses),
              program_heads(Clauses, Heads),
              example(Label, Obj, E),
              catch(prove_best(task(M, Heads, BodyPreds, [], [], []), Settings, Clauses, E, best(C, T0)),
                    mil_error(time_limit(T)), throw(mil_error(classify_time_limit(Label, T)))),
              maplist(trace_item, T0, Trace) ),
            Results).

text_clause(Text, C) :- term_string(C, Text).

program_heads(Clauses, Heads) :-
    findall(P/A, ( member(C, Clauses), ( C = (H :- _) -> true ; H = C ), functor(H, P, A) ), Hs),
    sort(Hs, Heads).

trace_item(fact(G, C), [fact, A, C]) :- term_to_atom(G, A).
trace_item(bk(G), [derived, A, 1.0]) :- term_to_atom(G, A).
trace_item(call(G), [call, A, 1.0]) :- term_to_atom(G, A).
trace_item(miss(G, E), [missing, A, E]) :- term_to_atom(G, A).
trace_item(clause(I), [clause, I, 1.0]).

%!  check_program(+File, +Known, +Target, -Texts) is det.
%   Read a program file as data: every clause's body may call only Known predicates (Name/Arity)
%   or predicates the file defines; Target/1 must be defined.  Problems are
%   mil_error(program(File, Message)).
check_program(File, Known, Target, Texts) :-
    catch(setup_call_cleanup(open(File, read, S), read_clauses(S, Clauses), close(S)), E,
          ( E = error(syntax_error(Msg), stream(_, L, _, _)) -> bad(File, 'syntax error at line ~w: ~w', [L, Msg])
          ; E = error(syntax_error(Msg), file(_, L, _, _)) -> bad(File, 'syntax error at line ~w: ~w', [L, Msg])
          ; E = error(syntax_error(Msg), _) -> bad(File, 'syntax error: ~w', [Msg])
          ; E = error(existence_error(source_sink, _), _) -> bad(File, 'no such file', [])
          ; throw(E) )),
    ( Clauses == [] -> bad(File, 'no clauses', []) ; true ),
    maplist(clause_head(File), Clauses, Heads0), sort(Heads0, Defined),
    ( memberchk(Target/1, Defined) -> true ; bad(File, 'does not define ~w/1', [Target]) ),
    forall(( member(C, Clauses), C = (_ :- B), body_goal(B, G) ),
           ( callable(G) -> functor(G, P, A),
             (   ( memberchk(P/A, Known) ; memberchk(P/A, Defined) ) -> true
             ;   bad(File, 'unknown predicate ~w/~w in a clause body', [P, A]) )
           ; bad(File, 'clause body goal ~q is not an atom', [G]) )),
    maplist(clause_text, Clauses, Texts).

read_clauses(S, Cs) :-
    read_term(S, T, [syntax_errors(error)]),
    ( T == end_of_file -> Cs = [] ; Cs = [T|Cs1], read_clauses(S, Cs1) ).

clause_head(File, C, P/A) :-
    ( C = (:- _) -> bad(File, 'directives are not allowed in a program file', [])
    ; C = (H :- _) -> true ; H = C ),
    ( callable(H) -> functor(H, P, A) ; bad(File, 'clause head ~q is not an atom', [H]) ).

body_goal((A, B), G) :- !, ( body_goal(A, G) ; body_goal(B, G) ).
body_goal(G, G).

bad(File, F, Args) :- format(atom(Msg), F, Args), throw(mil_error(program(File, Msg))).
