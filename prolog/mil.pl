/*  mil: a noise-tolerant meta-interpretive learner (Metagol-style).

    A task is data:  task(BK, Targets, BodyPreds, Metarules, Pos, Neg)
      BK         module holding the background knowledge (see body_kinds/3 for the three kinds)
      Targets    [Name/Arity, ...] predicates to learn (several: learned together, may call each other)
      BodyPreds  [Name/Arity, ...] background predicates a clause body may use
      Metarules  [Name | metarule(Name, Subs, Head, Body), ...] names from metarule/4 or own ones
      Pos, Neg   examples, ordinary atoms: cube(s1_o1), grandparent(ann, amy)
    Settings are a list of options (see default/1).  Atoms inside the interpreter are lists
    [Pred|Args] so that a predicate symbol can be a variable, as in Metagol.

    A program is a list of items: sub(MetaruleName, Subs, BodyLength) while learning, cl(Head, Body)
    when fixed (Head an atom list, Body a list of atom lists).  Iterative deepening is on the total
    number of body literals, and within it on the number of clauses (smallest programs first).
    A proof's confidence combines the confidences of the facts it used (option combine: product
    or min); an atom is proved only while that confidence stays >= the threshold.
*/
:- module(mil, [ learn/3,            % +Task, +Settings, -Program   (Metagol: consistent with all examples)
                 learn_noisy/4,      % +Task, +Settings, -Program, -Score  (samples, scored on all)
                 prove_best/5,       % +Task, +Settings, +Clauses, +Atom, -best(Conf, Trace)
                 program_clauses/3,  % +Task, +Program, -Clauses  (Prolog clauses H :- B)
                 task_check/1,       % +Task: throws mil_error(...) for an unusable task
                 default/1,          % ?Option
                 metarule/4          % ?Name, ?Subs, ?Head, ?Body
               ]).
:- use_module(library(lists)).
:- use_module(library(apply)).
:- use_module(library(option)).
:- use_module(library(random)).
:- use_module(library(time)).
:- use_module(library(solution_sequences)).

%!  default(?Option) is nondet.  Settings as data; a task or caller overrides any of them.
default(max_clauses(3)).        % iterative deepening bound on the number of clauses
default(max_literals(6)).       % and on the number of body literals of all clauses together
default(max_inventions(1)).     % invented predicate symbols allowed
default(max_depth(10)).         % bound on nested clause applications in one proof (recursion)
default(time_limit(10)).        % seconds for a search (learn_noisy: shared by its samples)
default(threshold(0.5)).        % an example is covered when its best proof's confidence >= this
default(combine(product)).      % how a proof's confidence combines its facts' confidences
default(samples(8)).            % noisy learning: random samples of the examples
default(sample_pos(2)).         % positives per sample
default(sample_neg(12)).        % negatives per sample
default(solutions(200)).        % hypotheses kept per sample (smallest size found)
default(clause_penalty(0.02)).  % score lost per clause (Occam), see docs/learner.md
default(disjunctions(0)).       % learn_noisy: pair this many best one-clause hypotheses (0: off)
default(thresholds([])).        % learn_noisy: candidate coverage thresholds, one chosen per program ([]: threshold)
default(miss(0)).               % near misses: an absent fact counts as holding with this confidence (0: off)
default(reference([])).         % learn_noisy: unlabelled atoms a hypothesis's extension is measured on ([]: the examples)
default(extra_literals(0)).     % learn_noisy: also keep consistent hypotheses up to this many literals longer than the smallest
default(few_shot(4)).          % learn_noisy: the size principle and extra_literals apply to tasks of at most this many positives
default(size_principle(true)). % learn_noisy: in few-shot tasks break ties of J by the size principle (false: by Soft, support, cost)
default(extension_miss(0)).    % size principle: an uncovered reference object counts its near proof, absent facts at this (0: counts 0)
default(literal_prior(0)).     % size principle: log prior of a hypothesis, -this per body literal (Occam; 0: flat prior)
default(predicate_prior([])).  % size principle: [[P, Nats], ...] log prior -Nats more per body literal of predicate P
default(seed(0)).

%!  metarule(?Name, ?Subs, ?Head, ?Body) is nondet.  The library of metarules; the first element
%   of Subs is the head symbol, the rest are bound while the body is proved.
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

%!  learn(+Task, +Settings, -Program) is semidet.
%   Metagol's search: the smallest programs first that prove every positive and no negative.
learn(Task, Settings0, Prog) :-
    settings(Task, Settings0, Settings),
    option(time_limit(T), Settings),
    timed(T, search(Task, Settings, Prog)).

search(Task, Settings, Prog) :-
    task_ctx(Task, Settings, Ctx0),
    Task = task(_, _, _, _, Pos, Neg),
    size(Settings, Ctx0, Ctx),
    prove_examples(Pos, Ctx, [], Prog0),
    consistent(Ctx, Neg, Prog0, Prog).

%   Program sizes in iterative deepening order: literals, then clauses.
size(Settings, Ctx0, Ctx) :-
    option(max_literals(MaxL), Settings), option(max_clauses(MaxC), Settings),
    between(1, MaxL, L), between(1, MaxC, N), N =< L,
    ctx_size(Ctx0, N, L, Ctx).

%!  learn_noisy(+Task, +Settings, -Program, -Score) is semidet.
%   Hypotheses learned from seeded random samples of the examples, each scored on all of them
%   (score/6, then support/4, literal_cost/3); the best is kept.  Fails when no sample gives any
%   hypothesis.
%   Each sample's search has an equal share of the time limit; a sample that runs out gives no
%   hypothesis (a mislabelled example can make a sample's search exhaustive), and only when every
%   sample runs out is it an error.
learn_noisy(Task, Settings0, Best, Score) :-
    settings(Task, Settings0, Settings),
    task_ctx(Task, Settings, Ctx),
    Task = task(_, _, _, _, Pos, Neg),
    option(seed(Seed), Settings), set_random(seed(Seed)),
    option(samples(K), Settings), option(sample_pos(SP), Settings), option(sample_neg(SN), Settings),
    samples(K, SP, SN, Pos, Neg, Samples),
    option(time_limit(T), Settings), length(Samples, NS), TS is T / NS,
    few_shot(Settings, Pos, SSettings),
    foldl(sample_hypotheses(Ctx, SSettings, TS), Samples, r([], 0), r(Found0, TimedOut)),
    (   TimedOut =:= NS -> throw(mil_error(time_limit(T))) ; true ),
    append(Found0, Found),
    list_to_set(Found, Unique),                     % in the order found: it breaks ties
    option(clause_penalty(Lambda), Settings),
    scoring(Settings, Ctx, SCtx, Ts),
    findall(Key-(Prog-S), (nth1(Order, Unique, Prog),
                           score(SCtx, Lambda-Ts, Prog, Pos, Neg, S),
                           S = score(J, Soft, _, _, _), support(Ctx, Prog, Pos, W),
                           literal_cost(Ctx, Prog, Cost), NCost is -Cost, NOrder is -Order,
                           Key = k(J, Soft, W, NCost, NOrder)), Scored),
    Scored \== [],
    option(disjunctions(KD), Settings),
    disjunctions(SCtx, Lambda-Ts, KD, Pos, Neg, Scored, Pairs),
    append(Scored, Pairs, All),
    best_specific(SCtx, Settings, Pos, All, Best, Score).

%   Among the hypotheses of the best J, the most probable under the size principle (Tenenbaum
%   1999; docs/learner.md): the positives are taken as drawn from the objects a hypothesis covers,
%   so P(positives | h) = prod over covered positives of c(h, e) / |h|, with |h| the size of the
%   hypothesis's extension over the reference objects (option reference: the unlabelled objects of
%   the scenes; the examples too).  An object it covers counts 1; with extension_miss(Eps) > 0 an
%   object it does not cover counts the chance that h holds of it all the same, its best near
%   proof (a fact it lacks counts Eps, the chance perception missed it; see miss/1), so that a
%   dozen reference objects still tell a conjunction from its parts.  It prefers, of the
%   hypotheses the few examples cannot tell apart, the one that covers the positives confidently
%   (robust to a doubtful fact) and holds of few other objects (not over-general); with many
%   examples J decides and this only breaks its ties.  With literal_prior(L) > 0 the prior
%   exp(-L * literals) multiplies it (Occam): a literal must shrink |h| by more than e^L; with
%   predicate_prior([[P, N], ...]) each literal of P costs N nats more (a predicate the caller
%   knows to generalise badly from one view: docs/learner.md).
%   Then the old key (Soft, support, cost, order).
%   Only for few-shot tasks (at most few_shot(K) positives): with many positives the n log |h|
%   term favours the most specific of J's ties, and J has the data to decide.
best_specific(_, Settings, Pos, All, Best, Score) :-
    (   option(size_principle(false), Settings) -> true
    ;   option(few_shot(K), Settings), length(Pos, NP), NP > K
    ), !,
    max_member(_-(Best-Score), All).
best_specific(Ctx, Settings, Pos, All, Best, Score) :-
    aggregate_all(max(J), member(k(J, _, _, _, _)-_, All), JMax),
    option(reference(Ref0), Settings), append(Pos, Ref0, Ref1), sort(Ref1, Ref),
    option(extension_miss(Eps), Settings), near_ctx(Ctx, Eps, NCtx),
    option(literal_prior(LP), Settings), option(predicate_prior(PP), Settings),
    findall(k(B, Soft, W, C, O)-(Prog-S),
            ( member(k(J, Soft, W, C, O)-(Prog-S), All), J >= JMax - 1.0e-9,
              size_likelihood(Ctx, NCtx, Prog, Pos, Ref, L),
              literals(Prog, NL), predicate_cost(PP, Prog, PC), B is L - LP * NL - PC ), Top),
    max_member(_-(Best-Score), Top).

size_likelihood(Ctx, NCtx, Prog, Pos, Ref, B) :-
    maplist(best_conf(Ctx, Prog), Pos, CP),
    foldl(extension(Ctx, NCtx, Prog), Ref, 0.0, Ext),
    foldl(log_likelihood(Ext), CP, 0.0, B).

%   The number of body literals of a program (its clauses' together).
literals(Prog, N) :- aggregate_all(sum(K), (member(sub(_, [_|Syms], _), Prog), length(Syms, K)), N).

%   The log prior a program's body literals cost under predicate_prior: Nats per literal of P.
predicate_cost([], _, 0) :- !.
predicate_cost(PP, Prog, Cost) :-
    aggregate_all(sum(N), ( member(sub(_, [_|Syms], _), Prog), member(Q, Syms), memberchk([Q, N], PP) ), Cost).

%   An object's share of |h|: 1 when h covers it, else the confidence of its best near proof
%   (none without extension_miss).
extension(Ctx, NCtx, Prog, E, X0, X) :-
    best_conf(Ctx, Prog, E, C),
    (   C > 0 -> X is X0 + 1
    ;   NCtx == none -> X = X0
    ;   best_conf(NCtx, Prog, E, CN), X is X0 + CN
    ).

%   The context of near proofs: absent facts count Eps, and no threshold but a floor against
%   underflow.
near_ctx(_, Eps, none) :- Eps =< 0, !.
near_ctx(ctx(A, B, C, D, E, _, G, H, I, J, _), Eps, ctx(A, B, C, D, E, 1.0e-12, G, H, I, J, Eps)).

log_likelihood(Ext, C, B0, B) :- ( C > 0, Ext > 0 -> B is B0 + log(C / Ext) ; B = B0 ).

%   Longer hypotheses (extra_literals) only for few-shot tasks, of at most few_shot(K) positives:
%   there the smallest consistent programs are few and often over-general, while with more
%   examples J tells hypotheses apart and the longer ones would only cost time.
few_shot(Settings, Pos, Settings) :-
    option(few_shot(K), Settings), length(Pos, NP), NP =< K, !.
few_shot(Settings, _, [extra_literals(0)|Settings]).

%   The coverage thresholds a program may take and the context to score with: with
%   thresholds(Ts) \== [], best proofs are found down to the lowest of them and each program
%   takes the one that scores it best on the training examples (a fixed threshold would let
%   confidences that are calibrated differently in another noise condition decide coverage);
%   else the one threshold.  The search itself keeps the threshold option.
scoring(Settings, Ctx, SCtx, Ts) :-
    option(threshold(T0), Settings), option(thresholds(Ts0), Settings),
    (   Ts0 == [] -> Ts = [T0] ; Ts = Ts0 ),
    min_list(Ts, TMin),
    Ctx = ctx(A, B, C, D, E, _, G, H, I, J, K), SCtx = ctx(A, B, C, D, E, TMin, G, H, I, J, K).

%   Two-clause programs: one view of a solid seldom shows every pose's evidence (a triangular prism
%   lying on a side shows no triangle), and a sample of two positives rarely needs two clauses, so
%   the search seldom proposes them.  The KD best one-clause, non-recursive hypotheses are paired;
%   a pair proves what either clause proves, so its best confidence per example is the larger of
%   the two, and it is scored like any program (its second clause pays clause_penalty).  Support
%   is the sum of the two clauses' supports and cost the sum of their literal costs.
disjunctions(_, _, 0, _, _, _, []) :- !.
disjunctions(Ctx, Lambda-Ts, KD, Pos, Neg, Scored, Pairs) :-
    ctx(Ctx, targets, Targets),
    include(single_clause(Targets), Scored, Singles),
    sort(1, @>=, Singles, Ranked),
    findall(h(Prog, CP, CN, W, C, O),
            ( limit(KD, member(k(_, _, W, C, O)-(Prog-_), Ranked)),
              maplist(best_conf(Ctx, Prog), Pos, CP), maplist(best_conf(Ctx, Prog), Neg, CN) ), Hs),
    findall(k(J, Soft, W, NC, NO)-(Prog-S),
            ( append(_, [h(P1, CP1, CN1, W1, C1, O1)|Rest], Hs), member(h(P2, CP2, CN2, W2, C2, O2), Rest),
              maplist(max_of, CP1, CP2, CP), maplist(max_of, CN1, CN2, CN),
              Penalty is 2 * Lambda, best_threshold(Ts, Penalty, CP, CN, S), S = score(J, Soft, _, _, _),
              W is W1 + W2, NC is C1 + C2, NO is min(O1, O2), append(P1, P2, Prog) ),
            Pairs).

single_clause(Ts, _-([sub(_, [P|Syms], _)]-_)) :-
    memberchk(P/_, Ts),
    \+ ( member(S, Syms), memberchk(S/_, Ts) ).

max_of(A, B, C) :- C is max(A, B).

%!  score(+Ctx, +Lambda-Thresholds, +Prog, +Pos, +Neg, -Score) is det.
%   Score = score(J, Soft, TP/NPos, FP/NNeg, Thr): at coverage threshold Thr (the one of
%   Thresholds that scores best), J = TP/NPos - FP/NNeg - Lambda * clauses (Youden's J, a
%   balanced accuracy: why in docs/learner.md); Soft = mean best-proof confidence over positives
%   minus that over negatives (a proof below Thr counts 0), which breaks ties between equal J.
score(Ctx, Lambda-Ts, Prog, Pos, Neg, S) :-
    maplist(best_conf(Ctx, Prog), Pos, CP), maplist(best_conf(Ctx, Prog), Neg, CN),
    length(Prog, L), Penalty is Lambda * L,
    best_threshold(Ts, Penalty, CP, CN, S).

%   The best score over the candidate thresholds: highest J, then Soft, then the higher threshold
%   (the stricter reading of the same evidence).
best_threshold(Ts, Penalty, CP, CN, Best) :-
    findall(k(J, Soft, T)-score(J, Soft, TP/NP, FP/NN, T),
            ( member(T, Ts),
              covered(T, CP, TP, MP), covered(T, CN, FP, MN),
              length(CP, NP), length(CN, NN), rate(TP, NP, TPR), rate(FP, NN, FPR),
              J is TPR - FPR - Penalty, Soft is MP - MN ), Ks),
    max_member(_-Best, Ks).

%   How many confidences reach T, and their mean with those below T counted 0.
covered(T, Cs, K, M) :-
    foldl(count_covered(T), Cs, 0-0, K-S),
    length(Cs, N), ( N =:= 0 -> M = 0.0 ; M is S / N ).

count_covered(T, C, K0-S0, K1-S1) :-
    (   C > 0, C >= T -> K1 is K0 + 1, S1 is S0 + C ; K1 = K0, S1 = S0 ).

%   Support: the mean number of proofs of a positive (at most 16 counted).  Between programs equal
%   so far it prefers the one that holds for more parts of each positive, so that it still holds
%   when another view hides some of them.
support(Ctx, Prog, Pos, W) :-
    findall(K, ( member(E, Pos), aggregate_all(count, limit(16, covers(Ctx, Prog, E, _, _)), K) ), Ks),
    mean(Ks, W).

%   The last tie-break: each body literal costs its predicate's place in the body predicate list
%   (0 for a target or invented predicate), so that the caller's order of preference decides
%   between equally good programs.
literal_cost(Ctx, Prog, Cost) :-
    ctx(Ctx, bps, BPs),
    findall(R, ( member(sub(_, [_|Syms], _), Prog), member(Q, Syms),
                 ( nth0(R, BPs, bp(Q, _, _, _)) -> true ; R = 0 ) ), Rs),
    sum_list(Rs, Cost).

best_conf(Ctx, Prog, E, C) :-
    (   aggregate_all(max(C0), covers(Ctx, Prog, E, C0, _), C) -> true ; C = 0 ).

rate(_, 0, 0.0) :- !.
rate(K, N, R) :- R is K / N.
mean([], 0.0) :- !.
mean(Xs, M) :- sum_list(Xs, S), length(Xs, N), M is S / N.

sample_hypotheses(Ctx, Settings, TS, P1-N1, r(Found0, Out0), r(Found, Out)) :-
    catch(call_with_time_limit(TS, findall(P, sample_hypothesis(Ctx, Settings, P1, N1, P), Ps)),
          time_limit_exceeded, Ps = timeout),
    (   Ps == timeout -> Found = Found0, Out is Out0 + 1
    ;   append(Found0, [Ps], Found), Out = Out0
    ).

%   The smallest hypotheses consistent with one sample, at most `solutions` of them: every program
%   of the size that proves the positives, once each, then those that prove no negative.
sample_hypothesis(Ctx0, Settings, Pos, Neg, Prog) :-
    option(solutions(J), Settings), option(extra_literals(X), Settings),
    size(Settings, Ctx0, Ctx),
    sized_hypotheses(Ctx, J, Pos, Neg, Progs0),
    Progs0 \== [], !,
    ctx(Ctx, lits, L0), Lim is L0 + X,
    findall(P, ( size(Settings, Ctx0, C1), ctx(C1, lits, L), L > L0, L =< Lim,
                 sized_hypotheses(C1, J, Pos, Neg, Ps), member(P, Ps) ), More),
    append(Progs0, More, Progs),
    member(Prog, Progs).

sized_hypotheses(Ctx, J, Pos, Neg, Progs) :-
    findall(P, prove_examples(Pos, Ctx, [], P), Ps0), list_to_set(Ps0, Ps),
    findall(P, limit(J, (member(P0, Ps), consistent(Ctx, Neg, P0, P))), Progs).

%   K samples: the whole set when it is small, else random subsets (seeded by the caller).
samples(_, SP, SN, Pos, Neg, [Pos-Neg]) :-
    length(Pos, NP), NP =< SP, length(Neg, NN), NN =< SN, !.
samples(K, SP, SN, Pos, Neg, Samples) :-
    length(Samples, K),
    maplist(sample(SP, SN, Pos, Neg), Samples).
sample(SP, SN, Pos, Neg, P1-N1) :- pick(SP, Pos, P1), pick(SN, Neg, N1).
pick(K, Xs, Ys) :- random_permutation(Xs, Zs), length(Xs, L), M is min(K, L), length(Ys, M), append(Ys, _, Zs).

%   A program that proves every positive has exactly the size asked, no clause twice, and
%   proves no negative.
consistent(Ctx, Neg, Prog0, Prog) :-
    ctx(Ctx, max, N), length(Prog0, N),
    ctx(Ctx, lits, L), prog_lits(Prog0, L),
    sort(Prog0, Sorted), length(Sorted, N),
    \+ ( member(Item, Prog0), repeated_literal(Ctx, Item) ),
    \+ (member(E, Neg), covers(Ctx, Prog0, E, _, _)),
    reverse(Prog0, Prog).

%   A clause whose body holds one literal twice (part2 with R = S) says no more than a shorter one
%   found before it, but under combine(product) its proofs are less confident, which can game
%   the coverage threshold: it is not a hypothesis.
repeated_literal(Ctx, sub(Name, Subs, _)) :-
    ctx(Ctx, metarules, MRs), template(Name, MRs, MR),
    copy_term(MR, metarule(Name, Subs, _, Body)),
    append(_, [L1|Rest], Body), member(L2, Rest), L1 == L2, !.

prog_lits(Prog, L) :- foldl(add_lits, Prog, 0, L).
add_lits(sub(_, _, K), L0, L) :- L is L0 + K.

%   Each example's proof may extend the program; other proofs that give the same program are
%   pruned (distinct/2), else every proof of every later example would repeat a hypothesis.
prove_examples([], _, Prog, Prog).
prove_examples([E|Es], Ctx, Prog1, Prog3) :-
    E =.. Atom, ctx(Ctx, depth, D),
    distinct(Prog2, prove([Atom], Ctx, D, Prog1, Prog2, 1.0, _, _, [])),
    prove_examples(Es, Ctx, Prog2, Prog3).

%!  covers(+Ctx, +Prog, +Example, -Conf, -Trace) is nondet.  A proof with the fixed program Prog.
covers(Ctx0, Prog, E, C, Trace) :-
    length(Prog, N), ctx_size(Ctx0, N, 0, Ctx),         % no new clauses
    E =.. Atom, ctx(Ctx, depth, D),
    prove([Atom], Ctx, D, Prog, _, 1.0, C, Trace, []).

%% ---- the meta-interpreter: prove(Atoms, Ctx, Depth, Prog1, Prog2, Conf1, Conf2, Trace1, Trace2)

prove([], _, _, Prog, Prog, C, C, T, T).
prove([Atom|Atoms], Ctx, D, Prog1, Prog3, C1, C3, T1, T3) :-
    kind(Ctx, Atom, Kind),
    prove_aux(Kind, Atom, Ctx, D, Prog1, Prog2, C1, C2, T1, T2),
    prove(Atoms, Ctx, D, Prog2, Prog3, C2, C3, T2, T3).

%   What proves an atom: a body predicate's kind (fact, rule, prolog), else the program.  A bound
%   name is looked up once; an unbound one ranges over the visible body predicates, then the program.
kind(Ctx, [P|Args], Kind) :-
    ctx(Ctx, bps, BPs),
    (   atom(P)
    ->  (   memberchk(bp(P, A, K, _), BPs) -> length(Args, A), Kind = K ; Kind = program )
    ;   (   member(bp(P, A, Kind, visible), BPs), length(Args, A)
        ;   Kind = program
        )
    ).

% a background fact with a confidence: BK stores P(Args..., Conf)
prove_aux(fact, [P|Args], Ctx, _, Prog, Prog, C1, C2, [fact(G, Cf)|T], T) :-
    ctx(Ctx, bk, BK), append(Args, [Cf], Args1), G1 =.. [P|Args1],
    call(BK:G1),
    combine(Ctx, C1, Cf, C2),
    G =.. [P|Args].
% near misses (option miss(Eps) > 0, for classifying what no program covers): a fact the scene
% lacks is taken to hold with confidence Eps, the chance that perception missed a true fact, so
% the best proof is the one missing the fewest facts, then the most confident; bindings the
% missing fact would bind are bound by BK:near_miss(BK, G) when BK defines it (shape_bk: to the
% same object's faces), else left open
prove_aux(fact, [P|Args], Ctx, _, Prog, Prog, C1, C2, [miss(G, Eps)|T], T) :-
    ctx(Ctx, miss, Eps), Eps > 0,
    C2 is C1 * Eps, ctx(Ctx, threshold, Thr), C2 >= Thr,
    G =.. [P|Args], ctx(Ctx, bk, BK),
    catch(BK:near_miss(BK, G), error(existence_error(procedure, _), _), true).
% a derived background predicate: BK:bk_rule(Head, Body), its body proved by this interpreter
prove_aux(rule, [P|Args], Ctx, D, Prog, Prog, C1, C2, [bk(G)|T1], T2) :-
    G =.. [P|Args], ctx(Ctx, bk, BK),
    call(BK:bk_rule(G, Body)),
    maplist(term_list, Body, Atoms),
    prove(Atoms, Ctx, D, Prog, _, C1, C2, T1, T2).
% an ordinary Prolog background predicate: holds with confidence 1
prove_aux(prolog, [P|Args], Ctx, _, Prog, Prog, C, C, [call(G)|T], T) :-
    G =.. [P|Args], ctx(Ctx, bk, BK),
    call(BK:G).
% use a clause already in the program (a learned one or a meta-substitution being built)
prove_aux(program, Atom, Ctx, D, Prog1, Prog2, C1, C2, [clause(I)|T1], T2) :-
    D > 0, D1 is D - 1,
    nth1(I, Prog1, Item),
    item_instance(Item, Ctx, Atom, Body),
    prove(Body, Ctx, D1, Prog1, Prog2, C1, C2, T1, T2).
% add a clause: a metarule instance whose head symbol is a target or an invented predicate
prove_aux(program, Atom, Ctx, D, Prog1, Prog2, C1, C2, [clause(new)|T1], T2) :-
    D > 0, D1 is D - 1,
    ctx(Ctx, max, Max), length(Prog1, N), N < Max,
    Atom = [P|Args], length(Args, A),
    head_symbol(Ctx, Prog1, P, A),
    ctx(Ctx, metarules, MRs), member(MR, MRs),
    copy_term(MR, metarule(Name, Subs, Atom, Body)),
    length(Body, K), prog_lits(Prog1, L0), ctx(Ctx, lits, L), L0 + K =< L,
    Body = [[Q|_]|_], dif(Q, P),                      % no left recursion
    prove(Body, Ctx, D1, [sub(Name, Subs, K)|Prog1], Prog2, C1, C2, T1, T2).

%   The head and body of a program item, renamed apart, with the head unified with Atom.
item_instance(sub(Name, Subs, _), Ctx, Atom, Body) :-
    Atom = [P|_], Subs = [P|_],
    ctx(Ctx, metarules, MRs), template(Name, MRs, MR),
    copy_term(MR, metarule(Name, Subs, Atom, Body)).
item_instance(cl(Head, Body0), _, Atom, Body) :-
    Atom = [P|_], Head = [P|_],
    copy_term(Head-Body0, Atom-Body).

%   A new clause defines a target, an invented symbol already used, or the next fresh one.
head_symbol(Ctx, _, P, A) :- ctx(Ctx, targets, Ts), member(P/A, Ts).
head_symbol(Ctx, Prog, P, _) :-
    invented(Ctx, Prog, Used),
    (   member(P, Used)
    ;   var(P), ctx(Ctx, inventions, MaxInv), length(Used, K), K < MaxInv,
        ctx(Ctx, targets, [T/_|_]), K1 is K + 1, format(atom(P), '~w_~w', [T, K1])
    ).

invented(Ctx, Prog, Used) :-
    ctx(Ctx, targets, Ts),
    findall(P, (member(sub(_, [P|_], _), Prog), atom(P), \+ memberchk(P/_, Ts)), Ps),
    sort(Ps, Used).

combine(Ctx, C1, Cf, C2) :-
    ctx(Ctx, combine, How),
    (   How == min -> C2 is min(C1, Cf) ; C2 is C1 * Cf ),
    ctx(Ctx, threshold, Thr), C2 >= Thr.

term_list(T, L) :- T =.. L.

%% ---- context: the task and settings the interpreter reads, in one term

task_ctx(task(BK, Targets, BodyPreds, MRs0, _, _), Settings, Ctx) :-
    body_kinds(BK, BodyPreds, BPs),
    maplist(metarule_term, MRs0, MRs),
    option(max_depth(D), Settings), option(threshold(Thr), Settings),
    option(combine(How), Settings), option(max_inventions(Inv), Settings),
    option(max_clauses(Max), Settings), option(max_literals(Lits), Settings),
    option(miss(Eps), Settings),
    Ctx = ctx(BK, Targets, BPs, MRs, D, Thr, How, Inv, Max, Lits, Eps).

ctx(ctx(BK, _, _, _, _, _, _, _, _, _, _), bk, BK).
ctx(ctx(_, Ts, _, _, _, _, _, _, _, _, _), targets, Ts).
ctx(ctx(_, _, BPs, _, _, _, _, _, _, _, _), bps, BPs).
ctx(ctx(_, _, _, MRs, _, _, _, _, _, _, _), metarules, MRs).
ctx(ctx(_, _, _, _, D, _, _, _, _, _, _), depth, D).
ctx(ctx(_, _, _, _, _, Thr, _, _, _, _, _), threshold, Thr).
ctx(ctx(_, _, _, _, _, _, How, _, _, _, _), combine, How).
ctx(ctx(_, _, _, _, _, _, _, Inv, _, _, _), inventions, Inv).
ctx(ctx(_, _, _, _, _, _, _, _, Max, _, _), max, Max).
ctx(ctx(_, _, _, _, _, _, _, _, _, L, _), lits, L).
ctx(ctx(_, _, _, _, _, _, _, _, _, _, E), miss, E).
ctx_size(ctx(A, B, C, E, F, G, H, I, _, _, M), Max, L, ctx(A, B, C, E, F, G, H, I, Max, L, M)).

%   Each body predicate is a fact with a confidence (BK defines P/(A+1)), a derived rule
%   (BK:bk_rule/2 has a head P/A) or plain Prolog (BK defines P/A, confidence 1).  The predicates
%   that derived rules use follow, hidden: proved when a rule calls them, never put in a clause.
body_kinds(BK, BodyPreds, BPs) :-
    maplist(body_kind(BK, visible), BodyPreds, Visible),
    findall(Q/B, ( member(bp(P, A, rule, _), Visible), functor(H, P, A),
                   catch(BK:bk_rule(H, Body), _, fail), member(G, Body), functor(G, Q, B),
                   \+ memberchk(Q/B, BodyPreds) ), Hidden0),
    sort(Hidden0, Hidden),
    maplist(body_kind(BK, hidden), Hidden, HiddenBPs),
    append(Visible, HiddenBPs, BPs).

body_kind(BK, Vis, P/A, bp(P, A, Kind, Vis)) :-
    functor(H, P, A),
    (   A1 is A + 1, current_predicate(BK:P/A1) -> Kind = fact
    ;   catch(BK:bk_rule(H, _), error(existence_error(_, _), _), fail) -> Kind = rule
    ;   current_predicate(BK:P/A) -> Kind = prolog
    ;   throw(mil_error(unknown_body_pred(P/A)))
    ).

metarule_term(Name, MR) :- atom(Name), !,
    (   metarule(Name, S, H, B) -> MR = metarule(Name, S, H, B)
    ;   throw(mil_error(unknown_metarule(Name)))
    ).
metarule_term(metarule(N, S, H, B), metarule(N, S, H, B)).

settings(task(_, _, _, _, _, _), Given, Settings) :-
    findall(O, (default(O), functor(O, F, 1), functor(G, F, 1), \+ memberchk(G, Given)), Defaults),
    append(Given, Defaults, Settings).

task_check(Task) :- settings(Task, [], S), task_ctx(Task, S, _).

%   The metarule called Name, without binding its variables (it is a template).
template(Name, MRs, MR) :- member(MR, MRs), arg(1, MR, Name), !.

%   Run Goal under a time limit; running out is an error term, never a hang.
timed(T, Goal) :-
    catch(call_with_time_limit(T, Goal), time_limit_exceeded,
          throw(mil_error(time_limit(T)))).

%% ---- fixed programs: best proof, clauses

%!  prove_best(+Task, +Settings, +Clauses, +Atom, -Best) is semidet.
%   Best = best(Conf, Trace): the most confident proof of Atom with the clauses (H :- B terms).
prove_best(Task, Settings0, Clauses, Atom, best(C, Trace)) :-
    settings(Task, Settings0, Settings),
    task_ctx(Task, Settings, Ctx),
    maplist(clause_item, Clauses, Prog),
    aggregate_all(max(C0, T0), covers(Ctx, Prog, Atom, C0, T0), max(C, Trace)).

clause_item((H :- B), cl(HL, BL)) :- !, H =.. HL, conj_list(B, Bs), maplist(term_list, Bs, BL).
clause_item(H, cl(HL, [])) :- H =.. HL.

conj_list((A, B), [A|Bs]) :- !, conj_list(B, Bs).
conj_list(true, []) :- !.
conj_list(A, [A]).

%!  program_clauses(+Task, +Program, -Clauses) is det.  Program items as Prolog clauses,
%   targets' clauses first.
program_clauses(task(_, _, _, MRs0, _, _), Prog, Clauses) :-
    maplist(metarule_term, MRs0, MRs),
    maplist(item_clause(MRs), Prog, Clauses0),
    findall(P, (member((H :- _), Clauses0), functor(H, P, _)), Ps0), list_to_set(Ps0, Ps),
    findall(C, (member(P, Ps), member(C, Clauses0), C = (H :- _), functor(H, P, _)), Clauses).

item_clause(MRs, sub(Name, Subs, _), (H :- B)) :-
    template(Name, MRs, MR),
    copy_term(MR, metarule(Name, Subs, HL, BL)),
    H =.. HL, maplist(term_list, Bs, BL), list_conj(Bs, B).
item_clause(_, cl(HL, BL), (H :- B)) :- H =.. HL, maplist(term_list, Bs, BL), list_conj(Bs, B).

list_conj([], true).
list_conj([A], A) :- !.
list_conj([A|As], (A, B)) :- list_conj(As, B).
