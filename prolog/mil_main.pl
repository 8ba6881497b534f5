/*  mil_main: learn a task file in a process of its own (lv3d/learn/task.py starts it):

      swipl --stack-limit=1g -q mil_main.pl FILE SETTINGS MODE GOAL

    SETTINGS is a Prolog option list (text), MODE exact or noisy, GOAL a goal's name or '' (every
    goal of the file).  What it finds goes to standard output, one record a line, fields separated
    by tabs (messages hold no tab or newline):

      warning <text>                      a warning about the file
      goal    <name>                      a goal starts
      clause  <text>                      a clause of its program, as Metagol prints it
      none                                no program within the bounds
      failed  <kind> <message>            the goal could not be learned (time_limit, memory, error)
      time    <cpu seconds> <wall seconds>  the goal's learning time (running it and the search)
      fatal   <kind> <where> <message>    the file cannot be learned at all (then exit code 2)

    The process exits 0 when it could read the file.  It is the caller's bound on time and memory
    that stops it for sure: the Prolog limits here (call_with_time_limit, the stack limit) end a
    search with a message first.
*/
:- module(mil_main, [main/0]).
:- use_module(library(lists)).
:- use_module(library(apply)).
:- use_module(library(option)).
:- use_module(mil).
:- use_module(mil_task).

:- initialization(main, main).

main :-
    current_prolog_flag(argv, Argv),
    (   Argv = [File, SetText, ModeA, GoalA] -> true
    ;   fatal(usage, '', 'expected FILE SETTINGS MODE GOAL'), halt(2)
    ),
    catch(term_string(Overrides, SetText), _, ( fatal(usage, '', 'bad settings'), halt(2) )),
    atom_string(Mode, ModeA), atom_string(GoalName, GoalA),
    catch(run(File, Overrides, Mode, GoalName), E, ( fatal_error(File, E), halt(2) )),
    halt(0).

run(File, _, validate, _) :- !,
    validate(File),
    record([ok]).
run(File, Overrides, Mode, GoalName) :-
    atom_concat('check:', ClausesFile, Mode), !,
    read_task_file(File, mil_task_bk, TF),
    goals_named(TF, File, GoalName, [_-G|_]),
    mil:settings(Overrides, Settings), option(time_limit(T), Settings),
    goal_call(TF, G, T, Call),
    read_file_to_string(ClausesFile, Text, []),
    split_string(Text, "\n", " \r\t", Lines0), exclude(==(""), Lines0, Lines),
    maplist([L, C]>>term_string(C, L), Lines, Clauses),
    catch(timed(T, coverage(TF, Call, Clauses, Settings, PosBits, NegBits)), E,
          ( failure(E, Kind, Msg), record([failed, Kind, Msg]), fail )),
    record([coverage, PosBits, NegBits]).

run(File, Overrides, Mode, GoalName) :-
    read_task_file(File, mil_task_bk, TF),
    TF = taskfile(_, _, _, _, _, _, FileSettings, _, Warnings),
    forall(member(W, Warnings), record([warning, W])),
    goals_named(TF, File, GoalName, Goals),
    append(Overrides, FileSettings, Settings0),
    forall(member(O, Settings0), read_here(File, Mode, O)),
    mil:settings(Settings0, Settings1),
    (   Mode == noisy, \+ memberchk(sample_pos(_), Settings0)
    ->  select_option(sample_pos(_), Settings1, Settings)        % mil_task: two thirds of the positives
    ;   Settings = Settings1
    ),
    option(time_limit(T), Settings),
    forall(member(Name-G, Goals), learn_goal(TF, Name, G, T, Settings, Mode)).

%   A file another process will read (a program file): it reads as Prolog terms nested at most
%   max_depth/1 deep, which an embedded Prolog reads without running out of C stack.
max_depth(100).

validate(File) :-
    catch(setup_call_cleanup(open(File, read, S), validate_terms(S, File), close(S)), E,
          validate_error(File, E)).

validate_terms(S, File) :-
    read_term(S, T, [syntax_errors(error), term_position(P)]),
    (   T == end_of_file -> true
    ;   max_depth(Max), stream_position_data(line_count, P, Line),
        (   deeper(T, Max) -> format(atom(Msg), 'line ~w: a term is nested more than ~w deep', [Line, Max]),
            throw(mil_error(task(File, Msg)))
        ;   true
        ),
        validate_terms(S, File)
    ).

deeper(T, Max) :- Max < 0, !, nonvar(T).
deeper(T, Max) :- compound(T), M1 is Max - 1, arg(_, T, A), deeper(A, M1), !.

validate_error(File, E) :-
    (   E = error(syntax_error(Msg), stream(_, L, C, _)) -> format(atom(M), 'syntax error at line ~w column ~w: ~w', [L, C, Msg])
    ;   E = error(syntax_error(Msg), file(_, L, C, _)) -> format(atom(M), 'syntax error at line ~w column ~w: ~w', [L, C, Msg])
    ;   E = error(syntax_error(Msg), _) -> format(atom(M), 'syntax error: ~w', [Msg])
    ;   E = error(existence_error(source_sink, _), _) -> M = 'no such file'
    ;   E = error(resource_error(_), _) -> M = 'a term is nested too deeply to read'
    ;   E = mil_error(_) -> throw(E)
    ;   format(atom(M), 'cannot be read: ~q', [E])
    ),
    throw(mil_error(task(File, M))).

%   A setting the chosen search does not read is an error, not ignored.
read_here(File, Mode, O) :-
    functor(O, Name, _),
    (   read_by(Name, Parts) -> true
    ;   format(atom(Msg), 'unknown setting ~q', [O]), throw(mil_error(task(File, Msg)))
    ),
    (   memberchk(Mode, Parts) -> true
    ;   Parts == [noisy]
    ->  format(atom(Msg), 'setting ~q is read only by the noise-tolerant search (lv3d mil --noisy)', [Name]),
        throw(mil_error(task(File, Msg)))
    ;   format(atom(Msg), 'setting ~q is not read when learning (only when classifying)', [Name]),
        throw(mil_error(task(File, Msg)))
    ).

goals_named(TF, File, GoalName, Goals) :-
    TF = taskfile(_, M, _, _, _, _, _, Goals0, _),
    (   GoalName == ''
    ->  Goals = Goals0
    ;   member(GoalName-G, Goals0) -> Goals = [GoalName-G]
    ;   M:'$mil_own'(GoalName, 0) -> Goals = [GoalName-GoalName]
    ;   findall(N, member(N-_, Goals0), Ns), atomic_list_concat(Ns, ', ', NsA),
        format(atom(Msg), 'no learning goal ~w (the file learns: ~w)', [GoalName, NsA]),
        throw(mil_error(task(File, Msg)))
    ).

%   Which of the call's examples the clauses prove: a string of 1 and 0 for the positives, another
%   for the negatives (a sequence's tasks together).
coverage(TF, Call, Clauses, Settings, PosBits, NegBits) :-
    (   Call = learn(Pos, Neg) -> true
    ;   Call = learn_seq(Tasks), findall(P, member(P-_, Tasks), Ps), append(Ps, Pos),
        findall(N, member(_-N, Tasks), Ns), append(Ns, Neg)
    ),
    findall(P/A, ( member(C, Clauses), ( C = (H :- _) -> true ; H = C ), functor(H, P, A) ), Hs0),
    list_to_set(Hs0, Heads),
    TF = taskfile(_, M, _, BodyPreds, _, Decls, _, _, _),
    Task = task(M, Heads, BodyPreds, [], [], [], Decls),
    maplist(proved(Task, Settings, Clauses), Pos, PB), atomic_list_concat(PB, PosBits),
    maplist(proved(Task, Settings, Clauses), Neg, NB), atomic_list_concat(NB, NegBits).

proved(Task, Settings, Clauses, E, Bit) :-
    (   proves(Task, Settings, Clauses, E) -> Bit = 1 ; Bit = 0 ).

learn_goal(TF, Name, G, T, Settings, Mode) :-
    record([goal, Name]),
    statistics(cputime, C0), get_time(W0),
    catch(( goal_call(TF, G, T, Call),
            learn_call(TF, Call, Settings, Mode, Result) ), E, true),
    statistics(cputime, C1), get_time(W1),
    (   var(E), Result = program(Clauses)
    ->  program_text(Clauses, Lines),
        forall(member(L, Lines), record([clause, L]))
    ;   var(E) -> record([none])
    ;   failure(E, Kind, Msg), record([failed, Kind, Msg])
    ),
    C is C1 - C0, Wl is W1 - W0,
    format(atom(CA), '~4f', [C]), format(atom(WA), '~4f', [Wl]),
    record([time, CA, WA]),
    garbage_collect.

failure(mil_error(time_limit(T)), time_limit, Msg) :- !,
    format(atom(Msg), 'the search reached its time limit of ~w s without an answer', [T]).
failure(mil_error(task(_, M)), input, M) :- !.
failure(error(resource_error(c_stack), _), memory, 'a term is nested too deeply (the C stack ran out)') :- !.
failure(error(resource_error(R), _), memory, Msg) :- !,
    format(atom(Msg), 'the search ran out of memory (~w)', [R]).
failure(mil_error(unsafe_call(M)), input, M) :- !.
failure(E, error, Msg) :- message(E, Msg).

fatal_error(_, mil_error(task(F, M))) :- !, fatal(input, F, M).
fatal_error(File, mil_error(time_limit(T))) :- !,
    format(atom(Msg), 'reached its time limit of ~w s', [T]), fatal(time_limit, File, Msg).
fatal_error(File, error(resource_error(c_stack), _)) :- !,
    fatal(input, File, 'a term is nested too deeply (the C stack ran out)').
fatal_error(File, error(resource_error(R), _)) :- !,
    format(atom(Msg), 'ran out of memory (~w)', [R]), fatal(memory, File, Msg).
fatal_error(File, E) :- message(E, Msg), fatal(error, File, Msg).

message(E, Msg) :-
    catch(( '$messages':translate_message(E, Lines, []),
            with_output_to(string(S), print_message_lines(current_output, '', Lines)) ), _, fail), !,
    atom_string(Msg, S).
message(E, Msg) :- format(atom(Msg), '~q', [E]).

fatal(Kind, Where, Msg) :- record([fatal, Kind, Where, Msg]).

%   One record: fields joined by tabs, each field's tabs and newlines made spaces.
record(Fields) :-
    maplist(field, Fields, Fs),
    atomic_list_concat(Fs, '\t', Line),
    format(user_output, '~w~n', [Line]),
    flush_output(user_output).

field(X, F) :-
    (   atomic(X) -> atom_string(X, S) ; format(string(S), '~q', [X]) ),
    split_string(S, "\t\n\r", "", Parts), atomic_list_concat(Parts, ' ', F0),
    normalize_space(atom(F), F0).
