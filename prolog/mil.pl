/*  mil: a noise-tolerant meta-interpretive learner (Metagol-style).  The API, the settings and the
    library of metarules; the parts live in

      mil_prove.pl   the context record and the meta-interpreter both searches share
      mil_exact.pl   the exact search (Metagol's): consistent with every example
      mil_noisy.pl   the noise-tolerant selection: samples, scored on all examples
      mil_task.pl    task files (Metagol's, unchanged, and lv3d's) read as data
      mil_safe.pl    what a task's own Prolog may call, checked before any of it runs

    A task is data:  task(BK, Targets, BodyPreds, Metarules, Pos, Neg) or task/7 with a list of
    declarations last (ibk(Head, Body, Cond), head_pred(P/A); mil_prove:task_ctx/3)
      BK         module holding the background knowledge (mil_prove: the kinds of body predicates)
      Targets    [Name/Arity, ...] predicates to learn (several: learned together, may call each other)
      BodyPreds  [Name/Arity, ...] background predicates a clause body may use, in search order
      Metarules  [Name | metarule(Name, Subs, Head, Body) | compiled mr/7, ...]
      Pos, Neg   examples, ordinary atoms: cube(s1_o1), grandparent(ann, amy)
    Settings are a list of options (default/1 lists them); a task or caller overrides any of them.
    A program is a list of items, newest first (mil_prove); program_clauses/3 gives its clauses in
    the order they were made, as Metagol prints them.
*/
:- module(mil, [ learn/3,            % +Task, +Settings, -Program   (consistent with all examples)
                 learn_noisy/4,      % +Task, +Settings, -Program, -Score  (samples, scored on all)
                 prove_best/5,       % +Task, +Settings, +Clauses, +Atom, -best(Conf, Trace)
                 proves/4,           % +Task, +Settings, +Clauses, +Atom
                 program_clauses/3,  % +Task, +Program, -Clauses
                 task_check/1,       % +Task: throws mil_error(...) for an unusable task
                 settings/2,         % +Given, -Settings  (defaults filled in)
                 default/1,          % ?Option
                 read_by/2,          % ?Option, ?Parts
                 metarule/4,         % ?Name, ?Subs, ?Head, ?Body
                 timed/2             % +Seconds, :Goal
               ]).
:- use_module(library(lists)).
:- use_module(library(apply)).
:- use_module(library(option)).
:- use_module(library(time)).
:- use_module(mil_prove).
:- use_module(mil_exact).
:- use_module(mil_noisy).

:- meta_predicate timed(+, 0).

%!  default(?Option) is nondet.  Settings as data; a task or caller overrides any of them.
default(max_clauses(10)).       % iterative deepening bound on the number of clauses (Metagol's default)
default(min_clauses(1)).        % where the deepening starts
default(max_literals(inf)).     % a bound on the body literals of all clauses together (inf: none; finite:
                                %   the deepening runs on literals first, then clauses)
default(max_inventions(auto)).  % invented predicate symbols allowed (auto: max_clauses - 1, Metagol's)
default(max_depth(inf)).        % bound on nested clause applications in one proof (the path check
                                %   already stops every proof that would loop)
default(functional(false)).     % Metagol's functional check with the task's func_test/3
default(time_limit(10)).        % seconds for a search (learn_noisy: shared by its samples) or a classification
default(threshold(0.5)).        % an example is covered when its best proof's confidence >= this
default(combine(product)).      % how a proof's confidence combines its facts' confidences
default(samples(8)).            % noisy learning: random samples of the examples
default(sample_pos(2)).         % positives per sample
default(sample_neg(12)).        % negatives per sample
default(shrink_samples(false)). % learn_noisy: where no sample gives a hypothesis, try smaller samples
default(solutions(200)).        % hypotheses kept per sample (smallest size found)
default(clause_penalty(0.02)).  % score lost per clause (Occam), see docs/learner.md
default(disjunctions(0)).       % learn_noisy: pair this many best one-clause hypotheses (0: off)
default(thresholds([])).        % learn_noisy: candidate coverage thresholds, one chosen per program ([]: threshold)
default(miss(0)).               % near misses: an absent fact counts as holding with this confidence (0: off)
default(reference([])).         % learn_noisy: unlabelled atoms a hypothesis's extension is measured on ([]: the examples)
default(extra_literals(0)).     % learn_noisy: also keep consistent hypotheses up to this many literals longer than the smallest
default(few_shot(4)).           % learn_noisy: the size principle and extra_literals apply to tasks of at most this many positives
default(size_principle(true)).  % learn_noisy: in few-shot tasks break ties of J by the size principle (false: by Soft, support, cost)
default(extension_miss(0)).     % size principle: an uncovered reference object counts its near proof, absent facts at this (0: counts 0)
default(literal_prior(0)).      % size principle: log prior of a hypothesis, -this per body literal (Occam; 0: flat prior)
default(predicate_prior([])).   % size principle: [[P, Nats], ...] log prior -Nats more per body literal of predicate P
default(seed(0)).

%!  read_by(?Option, ?Parts) is nondet.  Which parts of the learner read each setting: exact (the
%   exact search), noisy (the noise-tolerant selection), classify (proving with a fixed program).
%   A setting given to a part that does not read it is refused (mil_main), not ignored.
read_by(max_clauses, [exact, noisy]).
read_by(min_clauses, [exact, noisy]).
read_by(max_literals, [exact, noisy]).
read_by(max_inventions, [exact, noisy]).
read_by(max_depth, [exact, noisy, classify]).
read_by(functional, [exact, noisy]).
read_by(time_limit, [exact, noisy, classify]).
read_by(threshold, [exact, noisy, classify]).
read_by(combine, [exact, noisy, classify]).
read_by(miss, [classify]).
read_by(O, [noisy]) :-
    memberchk(O, [samples, sample_pos, sample_neg, shrink_samples, solutions, clause_penalty, disjunctions,
                  thresholds, reference, extra_literals, few_shot, size_principle, extension_miss, literal_prior,
                  predicate_prior, seed]).

%!  metarule(?Name, ?Subs, ?Head, ?Body) is nondet.  The library of metarules, in Metagol's list
%   form; the first element of Subs is the head symbol.
metarule(ident,     [P,Q],     [P,A,B], [[Q,A,B]]).                       % P(A,B) :- Q(A,B)
metarule(inverse,   [P,Q],     [P,A,B], [[Q,B,A]]).                       % P(A,B) :- Q(B,A)
metarule(precon,    [P,Q,R],   [P,A,B], [[Q,A],[R,A,B]]).                 % P(A,B) :- Q(A), R(A,B)
metarule(postcon,   [P,Q,R],   [P,A,B], [[Q,A,B],[R,B]]).                 % P(A,B) :- Q(A,B), R(B)
metarule(chain,     [P,Q,R],   [P,A,B], [[Q,A,C],[R,C,B]]).               % P(A,B) :- Q(A,C), R(C,B)
metarule(tailrec,   [P,Q],     [P,A,B], [[Q,A,C],[P,C,B]]).               % P(A,B) :- Q(A,C), P(C,B)
metarule(base,      [P,Q],     [P,A],   [[Q,A]]).                         % P(A) :- Q(A)
metarule(conj,      [P,Q,R],   [P,A],   [[Q,A],[R,A]]).                   % P(A) :- Q(A), R(A)
metarule(part,      [P,Q,R],   [P,A],   [[Q,A,B],[R,B]]).                 % P(A) :- Q(A,B), R(B)  exists a part
metarule(part2,     [P,Q,R,S], [P,A],   [[Q,A,B],[R,B],[S,B]]).           % P(A) :- Q(A,B), R(B), S(B)
metarule(part_and,  [P,Q,R,S], [P,A],   [[Q,A,B],[R,B],[S,A]]).           % P(A) :- Q(A,B), R(B), S(A)
metarule(part_pair, [P,Q,R,S,T], [P,A], [[Q,A,B],[R,B],[S,B,C],[T,C]]).   % P(A) :- Q(A,B), R(B), S(B,C), T(C)
metarule(has,       [P,Q],     [P,A],   [[Q,A,_]]).                       % P(A) :- Q(A,_)  a relation to something
metarule(part_rel,  [P,Q,R],   [P,A],   [[Q,A,B],[R,A,B]]).               % P(A) :- Q(A,B), R(A,B)  two relations to one part

%!  settings(+Given, -Settings) is det.
%   Given first, then the defaults of the options it does not set; max_inventions(auto) becomes
%   max_clauses - 1.
settings(Given, Settings) :-
    findall(O, ( default(O), functor(O, F, 1), functor(G, F, 1), \+ memberchk(G, Given) ), Defaults),
    append(Given, Defaults, S0),
    (   option(max_inventions(auto), S0)
    ->  option(max_clauses(MC), S0), Inv is max(0, MC - 1),
        select_option(max_inventions(_), S0, S1), Settings = [max_inventions(Inv)|S1]
    ;   Settings = S0
    ).

%!  learn(+Task, +Settings, -Program) is semidet.
%   The exact search (mil_exact): the first program, smallest first, that proves every positive
%   and no negative.  Fails when there is none within the bounds.
learn(Task, Settings0, Prog) :-
    settings(Settings0, Settings),
    task_ctx(Task, Settings, X),
    examples(Task, Pos, Neg),
    option(time_limit(T), Settings),
    timed(T, learn_exact(X, Settings, Pos-Neg, Prog)).

%!  learn_noisy(+Task, +Settings, -Program, -Score) is semidet.  The noise-tolerant selection
%   (mil_noisy); Score = score(J, Soft, TP/NPos, FP/NNeg, Threshold).
learn_noisy(Task, Settings0, Prog, Score) :-
    settings(Settings0, Settings),
    task_ctx(Task, Settings, X),
    examples(Task, Pos, Neg),
    mil_noisy:learn_noisy(X, Settings, Pos, Neg, Prog, Score).

examples(Task, Pos, Neg) :-
    arg(5, Task, Pos0), arg(6, Task, Neg0),
    maplist(atom_lit, Pos0, Pos), maplist(atom_lit, Neg0, Neg).

%!  prove_best(+Task, +Settings, +Clauses, +Atom, -Best) is semidet.
%   Best = best(Conf, Trace): the most confident proof of Atom with the clauses (H :- B terms),
%   within the time limit.  Trace: fact(Atom, Conf), miss(Atom, Eps), bk(Atom), call(Goal),
%   clause(I) (the I-th of Clauses).
prove_best(Task, Settings0, Clauses, Atom, best(C, Trace)) :-
    settings(Settings0, Settings),
    task_ctx(Task, Settings, X0), set_trace_of_ctx(true, X0, X),
    program_items(Clauses, Prog),
    option(time_limit(T), Settings),
    timed(T, aggregate_all(max(C0, T0), covers(X, Prog, Atom, C0, T0), max(C, Trace))).

%!  proves(+Task, +Settings, +Clauses, +Atom) is semidet.
%   The clauses (H :- B terms) prove Atom (a first proof, at the coverage threshold), within the
%   time limit.
proves(Task, Settings0, Clauses, Atom) :-
    settings(Settings0, Settings),
    task_ctx(Task, Settings, X),
    program_items(Clauses, Prog),
    option(time_limit(T), Settings),
    timed(T, once(covers(X, Prog, Atom, _, _))).

%!  program_clauses(+Task, +Program, -Clauses) is det.
%   The program's clauses (H :- B, or H), in the order they were made.
program_clauses(Task, Prog, Clauses) :-
    task_ctx_mrs(Task, X),
    reverse(Prog, Items),
    maplist(item_clause(X), Items, Clauses).

task_ctx_mrs(Task, X) :-
    arg(4, Task, MRs0),
    task_ctx(task(user, [], [], MRs0, [], []), [], X).

task_check(Task) :- settings([], S), task_ctx(Task, S, _).

%!  timed(+Seconds, :Goal) is semidet.
%   Run Goal under a time limit; running out is an error term, never a hang.
timed(T, Goal) :-
    catch(call_with_time_limit(T, Goal), time_limit_exceeded,
          throw(mil_error(time_limit(T)))).
