/*  mil_safe: what a task's own Prolog may call, checked before any of it runs.

    Every clause of a task file is checked when the file is read, before any clause runs: its body
    may call the task's own predicates, the built-ins of safe/1 (arithmetic, comparison, type
    checks, terms, atoms and strings, lists, seeded random numbers) and, through the control and
    meta-call constructs of meta/3 (conjunction, if-then-else, negation, findall, forall,
    maplist, ...), only such goals again.  Anything else is refused with an error naming the
    clause and its line: a module-qualified goal, assert/retract, I/O, shell, halt, catch/throw,
    loading code, flags.  A goal the check cannot see (a variable, a closure built at run time) is
    wrapped in checked_call/2, which makes the same check when the goal is known and refuses
    (an error) what the file could not have called by name.  A call to a predicate that is neither
    defined in the file nor a built-in is kept as an error when reached (Metagol's reading of such
    a file: an unknown procedure), and reported as a warning.

    The learning goals' clauses and the file's directives (role goal) may also call learn/2,
    learn/3, learn_seq/2, pprint/1, time/1 and print (write/1, writeln/1, print/1, nl/0,
    format/1,2): the learning calls end the goal's run with the task they name (mil_task reads it),
    printing does nothing.

    Every problem is mil_error(task(File, Message)); warnings are returned as text.
*/
:- module(mil_safe, [ check_clause/4,     % +Clause, +Where, -Checked, -Warnings
                      check_goal/4,       % +Goal, +Where, -Checked, -Warnings
                      check_pred/3,       % +Name/Arity, +Where, -Kind  (own, builtin, unknown)
                      checked_call/2,     % +Module, +Goal
                      checked/3, checked/4, checked/5, checked/6, checked/7, checked/8, checked/9,
                      captured/1,         % +LearningCall
                      undefined/1,        % +Name/Arity
                      safe/1              % ?Name/Arity
                    ]).
:- use_module(library(lists)).
:- use_module(library(apply)).

%   Where = where(File, Line, What, Module, Role): What names the clause (p/2, a directive, ...),
%   Module holds the task's own predicates ('$mil_own'(Name, Arity) facts), Role is bk or goal.

%!  check_clause(+Clause, +Where, -Checked, -Warnings) is det.
check_clause((H :- B), W, (H :- B1), Ws) :- !,
    check_head(H, W),
    body(B, W, B1, Ws0, []), sort(Ws0, Ws).
check_clause(H, W, H, []) :-
    check_head(H, W).

%!  check_goal(+Goal, +Where, -Checked, -Warnings) is det.
check_goal(G, W, G1, Ws) :-
    body(G, W, G1, Ws0, []), sort(Ws0, Ws).

check_head(H, W) :-
    (   var(H) -> refuse(W, 'a clause head is a variable', [])
    ;   H = M:_ -> refuse(W, 'the clause is module-qualified (~q): a task defines its own predicates only', [M])
    ;   \+ callable(H) -> refuse(W, 'the clause head ~q is not an atom', [H])
    ;   functor(H, P, A), builtin(P, A) -> refuse(W, 'defines ~q/~q, a built-in', [P, A])
    ;   functor(H, P, A), sub_atom(P, 0, _, _, '$') -> refuse(W, 'defines ~q/~q: names starting with $ are reserved', [P, A])
    ;   true
    ).

%   body(+Goal, +Where, -Checked, -Warnings0, -Warnings)
body(G, W, mil_safe:checked_call(M, G), Ws, Ws) :- var(G), !, where_module(W, M).
body(M:G, W, _, _, _) :- !,
    refuse(W, 'calls ~q, a module-qualified goal: a task calls its own predicates and safe built-ins only', [M:G]).
body(G, W, _, _, _) :- \+ callable(G), !, refuse(W, 'calls ~q, which is not a goal', [G]).
body((A, B), W, (A1, B1), Ws0, Ws) :- !, body(A, W, A1, Ws0, Ws1), body(B, W, B1, Ws1, Ws).
body((A ; B), W, (A1 ; B1), Ws0, Ws) :- !, body(A, W, A1, Ws0, Ws1), body(B, W, B1, Ws1, Ws).
body((A -> B), W, (A1 -> B1), Ws0, Ws) :- !, body(A, W, A1, Ws0, Ws1), body(B, W, B1, Ws1, Ws).
body((A *-> B), W, (A1 *-> B1), Ws0, Ws) :- !, body(A, W, A1, Ws0, Ws1), body(B, W, B1, Ws1, Ws).
body(\+ A, W, \+ A1, Ws0, Ws) :- !, body(A, W, A1, Ws0, Ws).
body(G, W, G1, Ws0, Ws) :-
    functor(G, call, N), N >= 1, !,
    G =.. [call, C|Extra],
    (   var(C) -> where_module(W, M), checked_goal(M, C, Extra, G1), Ws0 = Ws
    ;   callable(C), C \= _:_ -> extend(C, Extra, G2), body(G2, W, G3, Ws0, Ws), G1 = call(G3)
    ;   refuse(W, 'calls ~q, which is not a goal', [C])
    ).
body(time(G), W, G1, Ws0, Ws) :- where_role(W, goal), !, body(G, W, G1, Ws0, Ws).
body(G, W, G1, Ws0, Ws) :-
    functor(G, P, A), meta(P/A, Spec, Role), !,
    (   Role == goal, where_role(W, bk) -> refuse(W, 'calls ~q/~q outside a learning goal', [P, A]) ; true ),
    G =.. [P|Args], maplist(meta_arg(W), Spec, Args, Args1, Wss),
    append(Wss, Ws1), append(Ws1, Ws, Ws0),
    G1 =.. [P|Args1].
body(G, W, G1, Ws0, Ws) :-
    functor(G, P, A),
    goal_role(P/A, G, G1, W), !, Ws0 = Ws.
body(G, W, G1, Ws0, Ws) :-
    functor(G, P, A),
    check_pred(P/A, W, Kind),
    (   Kind == unknown
    ->  G1 = mil_safe:undefined(P/A),
        where_what(W, What), where_line(W, Line),
        format(atom(Wn), 'line ~w: ~w calls ~q/~q, which the file does not define', [Line, What, P, A]),
        Ws0 = [Wn|Ws]
    ;   special(G, W), G1 = G, Ws0 = Ws
    ).

%!  check_pred(+Name/Arity, +Where, -Kind) is det.
%   own (the file defines it), builtin (on the safe list) or unknown (not defined anywhere); a
%   built-in or library predicate off the list is refused.
check_pred(P/A, W, Kind) :-
    where_module(W, M),
    (   own(M, P, A) -> Kind = own
    ;   safe(P/A) -> Kind = builtin
    ;   known_elsewhere(P, A) -> refuse(W, 'calls ~q/~q, which a task may not call (a task is data: it runs only its own predicates and safe built-ins)', [P, A])
    ;   Kind = unknown
    ).

own(M, P, A) :-
    catch(M:'$mil_own'(P, A), error(existence_error(_, _), _), fail), !,
    \+ builtin(P, A), \+ sub_atom(P, 0, _, _, '$').

known_elsewhere(P, A) :- builtin(P, A), !.
known_elsewhere(P, A) :- '$in_library'(P, A, _), !.
known_elsewhere(P, _) :- sub_atom(P, 0, _, _, '$').

builtin(P, A) :- functor(H, P, A), predicate_property(system:H, defined), !.
builtin(P, A) :- memberchk(P/A, [learn/2, learn/3, learn_seq/2, pprint/1]).

%   Arguments of the meta-predicates: g (a goal), c(N) (a closure called with N more arguments),
%   s (an aggregate_all spec: count, sum(E), ...), ^ (a goal under ^ of bagof/setof), - (data).
meta_arg(W, g, G, G1, Ws) :- !, body(G, W, G1, Ws, []).
meta_arg(W, ^, G, G1, Ws) :- !, caret(G, W, G1, Ws).
meta_arg(W, c(N), C, C1, Ws) :- !, closure(C, N, W, C1, Ws).
meta_arg(_, _, X, X, []).

caret(V^G, W, V^G1, Ws) :- nonvar(G), !, caret(G, W, G1, Ws).
caret(G, W, G1, Ws) :- body(G, W, G1, Ws, []).

%   A closure named in the file (an own predicate or a safe built-in, with its N arguments added)
%   stays; any other, or one only known at run time, is checked when called.
closure(C, _, W, mil_safe:checked(M, C), []) :- var(C), !, where_module(W, M).
closure(C, N, W, C1, Ws) :-
    callable(C), C \= _:_, !,
    length(Extra, N), extend(C, Extra, G),
    body(G, W, G1, Ws, []),
    (   G1 == G, \+ meta_goal(G) -> C1 = C ; where_module(W, M), C1 = mil_safe:checked(M, C) ).
closure(C, _, W, _, _) :- refuse(W, 'calls ~q, which is not a goal', [C]).

meta_goal(G) :- functor(G, P, A), ( meta(P/A, _, _) ; P == call ), !.

checked_goal(M, C, [], mil_safe:checked_call(M, C)) :- !.
checked_goal(M, C, Extra, mil_safe:G) :- G =.. [checked, M, C|Extra].

extend(C, Extra, G) :- C =.. L0, append(L0, Extra, L), G =.. L.

%   The learning goals' own calls (role goal only): learning calls end the run with the task
%   they name, printing does nothing, time/1 runs its goal.
goal_role(P/A, G, G1, W) :-
    memberchk(P/A, [learn/2, learn/3, learn_seq/2, pprint/1, write/1, writeln/1, print/1, nl/0,
                    format/1, format/2, portray_clause/1]),
    (   where_role(W, goal) -> true
    ;   refuse(W, 'calls ~q/~q outside a learning goal (a background predicate prints and learns nothing)', [P, A])
    ),
    (   memberchk(P, [learn, learn_seq]) -> G1 = mil_safe:captured(G) ; G1 = true ).

%   Built-ins on the list whose arguments are checked too.
special(set_random(S), W) :- !,
    (   nonvar(S), S = seed(_) -> true ; refuse(W, 'calls set_random(~q): only set_random(seed(N)) is allowed', [S]) ).
special(_, _).

%!  captured(+LearningCall).  A learning goal reached learn/2, learn/3 or learn_seq/2: its run ends
%   here with the call (mil_task reads the task it names).
captured(G) :- throw(mil_goal(G)).

%!  undefined(+Name/Arity).  A call to a predicate the task does not define.
undefined(P/A) :- throw(error(existence_error(procedure, P/A), _)).

%!  checked_call(+Module, +Goal).  Goal, known only now, checked as the file's clauses are, then run.
checked_call(M, G) :-
    (   var(G) -> throw(error(instantiation_error, mil_safe:checked_call/2))
    ;   G = _:_ -> throw(mil_error(unsafe(G)))
    ;   callable(G) -> true
    ;   throw(error(type_error(callable, G), _))
    ),
    functor(G, P, A),
    (   own(M, P, A) -> call(M:G)
    ;   safe(P/A), \+ meta(P/A, _, _), special_ok(G) -> call(M:G)
    ;   catch(check_goal(G, where(runtime, 0, 'a goal built at run time', M, bk), G1, _), mil_error(task(_, Msg)),
              throw(mil_error(unsafe_call(Msg)))),
        call(M:G1)
    ).

special_ok(set_random(S)) :- !, nonvar(S), S = seed(_).
special_ok(_).

checked(M, C, A1) :- extend(C, [A1], G), checked_call(M, G).
checked(M, C, A1, A2) :- extend(C, [A1, A2], G), checked_call(M, G).
checked(M, C, A1, A2, A3) :- extend(C, [A1, A2, A3], G), checked_call(M, G).
checked(M, C, A1, A2, A3, A4) :- extend(C, [A1, A2, A3, A4], G), checked_call(M, G).
checked(M, C, A1, A2, A3, A4, A5) :- extend(C, [A1, A2, A3, A4, A5], G), checked_call(M, G).
checked(M, C, A1, A2, A3, A4, A5, A6) :- extend(C, [A1, A2, A3, A4, A5, A6], G), checked_call(M, G).
checked(M, C, A1, A2, A3, A4, A5, A6, A7) :- extend(C, [A1, A2, A3, A4, A5, A6, A7], G), checked_call(M, G).

where_module(where(_, _, _, M, _), M).
where_role(where(_, _, _, _, R), R).
where_what(where(_, _, What, _, _), What).
where_line(where(_, L, _, _, _), L).

refuse(where(File, Line, What, _, _), Fmt, Args) :-
    format(atom(Msg0), Fmt, Args),
    (   Line == 0 -> format(atom(Msg), '~w ~w', [What, Msg0])
    ;   format(atom(Msg), 'line ~w: ~w ~w', [Line, What, Msg0])
    ),
    throw(mil_error(task(File, Msg))).

%!  meta(?Name/Arity, ?ArgSpecs, ?Role).  The control and meta-call built-ins a task may use.
meta(findall/3, [-, g, -], bk).
meta(findall/4, [-, g, -, -], bk).
meta(forall/2, [g, g], bk).
meta(aggregate_all/3, [-, g, -], bk).
meta(bagof/3, [-, ^, -], bk).
meta(setof/3, [-, ^, -], bk).
meta(once/1, [g], bk).
meta(ignore/1, [g], bk).
meta(not/1, [g], bk).
meta((^)/2, [-, g], bk).
meta(time/1, [g], goal).
meta(maplist/2, [c(1), -], bk).
meta(maplist/3, [c(2), -, -], bk).
meta(maplist/4, [c(3), -, -, -], bk).
meta(maplist/5, [c(4), -, -, -, -], bk).
meta(maplist/6, [c(5), -, -, -, -, -], bk).
meta(maplist/7, [c(6), -, -, -, -, -, -], bk).
meta(foldl/4, [c(3), -, -, -], bk).
meta(foldl/5, [c(4), -, -, -, -], bk).
meta(foldl/6, [c(5), -, -, -, -, -], bk).
meta(include/3, [c(1), -, -], bk).
meta(exclude/3, [c(1), -, -], bk).
meta(partition/4, [c(1), -, -, -], bk).
meta(predsort/3, [c(3), -, -], bk).

%!  safe(?Name/Arity) is nondet.  Built-ins a task may call: they compute on terms and nothing else
%   (the control constructs and meta/3 come on top).
safe(P) :- safe_list(L), member(P, L).

safe_list([
    true/0, fail/0, false/0, !/0,
    % unification and comparison
    (=)/2, (\=)/2, (==)/2, (\==)/2, (@<)/2, (@>)/2, (@=<)/2, (@>=)/2, compare/3, (=@=)/2, (\=@=)/2,
    unify_with_occurs_check/2, dif/2,
    % arithmetic
    (is)/2, (=:=)/2, (=\=)/2, (<)/2, (>)/2, (=<)/2, (>=)/2, succ/2, plus/3, between/3,
    % type checks
    var/1, nonvar/1, atom/1, number/1, integer/1, float/1, atomic/1, compound/1, callable/1,
    is_list/1, ground/1, string/1, is_assoc/1, cyclic_term/1, acyclic_term/1,
    % terms
    functor/3, arg/3, (=..)/2, copy_term/2, term_variables/2, setarg/3, numbervars/3,
    % atoms and strings
    atom_codes/2, atom_chars/2, char_code/2, atom_length/2, atom_concat/3, sub_atom/5, atom_number/2,
    number_codes/2, number_chars/2, atom_string/2, atomic_list_concat/2, atomic_list_concat/3,
    upcase_atom/2, downcase_atom/2, char_type/2, code_type/2, string_chars/2, string_codes/2,
    string_concat/3, string_length/2, string_lower/2, string_upper/2, sub_string/5, split_string/4,
    string_code/3, number_string/2, string_to_atom/2, text_concat/3, term_to_atom/2,
    % lists
    length/2, append/3, append/2, member/2, memberchk/2, last/2, reverse/2, nth0/3, nth1/3, nth0/4,
    nth1/4, msort/2, sort/2, sort/4, keysort/2, delete/3, subtract/3, intersection/3, union/3,
    select/3, selectchk/3, select/4, permutation/2, list_to_set/2, sum_list/2, sumlist/2,
    max_list/2, min_list/2, max_member/2, min_member/2, numlist/3, flatten/2, nextto/3,
    pairs_keys_values/3, pairs_keys/2, pairs_values/2, proper_length/2,
    list_to_ord_set/2, ord_union/3, ord_subtract/3, ord_memberchk/2, ord_subset/2, ord_intersection/3,
    subsumes_term/2,
    % seeded random numbers
    random/1, random/3, random_between/3, random_member/2, random_select/3, random_permutation/2,
    randseq/3, randset/3, set_random/1, setrand/1, getrand/1
]).
