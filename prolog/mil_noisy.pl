/*  mil_noisy: the noise-tolerant selection.  Hypotheses learned from seeded random samples of the
    examples are scored on all of them, and the best is kept (docs/learner.md, "Noise tolerance
    and the scoring rule").

    A sample's hypotheses are the smallest programs (mil_exact:size/3's rounds) that prove its
    positives and no negative; each example's proof may extend the program, and proofs that give
    the same program are pruned (distinct/2), so every such program is found once.
*/
:- module(mil_noisy, [ learn_noisy/6,       % +Ctx, +Settings, +Pos, +Neg, -Prog, -Score
                       best_conf/4          % +Ctx, +Prog, +Atom, -Conf
                     ]).
:- use_module(library(lists)).
:- use_module(library(apply)).
:- use_module(library(option)).
:- use_module(library(random)).
:- use_module(library(time)).
:- use_module(library(aggregate)).
:- use_module(library(solution_sequences)).
:- use_module(mil_prove).
:- use_module(mil_exact, [size/3, exact_size/2]).

%!  learn_noisy(+Ctx, +Settings, +Pos, +Neg, -Prog, -Score) is semidet.
%   Pos and Neg are l/3 atoms.  Hypotheses from seeded random samples of the examples, each scored
%   on all of them (score/6, then support/4, literal_cost/3); the best is kept if it is better than
%   chance on them (J > 0).  Fails when no sample gives a hypothesis that is kept (with
%   shrink_samples(true), down to the smallest samples: scored_hypotheses/4), or the best is no
%   better than chance.  Each sample's search has an equal share of the time left; a sample that
%   runs out gives no hypothesis (a mislabelled example can make a sample's search exhaustive), and
%   only when every sample of the first size runs out is it an error.
learn_noisy(Ctx, Settings, Pos, Neg, Best, Score) :-
    option(seed(Seed), Settings), set_random(seed(Seed)),
    option(samples(K), Settings), option(sample_pos(SP), Settings), option(sample_neg(SN), Settings),
    option(time_limit(T), Settings), get_time(Start), Deadline is Start + T,
    few_shot(Settings, Pos, SSettings),
    option(clause_penalty(Lambda), Settings),
    scoring(Settings, Ctx, SCtx, Ts),
    length(Pos, NP), length(Neg, NN), SP1 is min(SP, NP), SN1 is min(SN, NN),
    Search = search(Ctx, SSettings, SCtx, Lambda-Ts, K, Deadline, T, Pos, Neg),
    scored_hypotheses(Search, SP1-SN1, Scored, Round),
    Scored \== [],
    option(disjunctions(KD), Settings),
    disjunctions(SCtx, Lambda-Ts, KD, Pos, Neg, Scored, Pairs0),
    kept(Round, SP1-SN1, Pairs0, Pairs),
    append(Scored, Pairs, All),
    best_specific(SCtx, Settings, Pos, All, Best, Score),
    Score = score(JBest, _, _, _, _), JBest > 0.

%   The distinct hypotheses of samples of the first size (First = SP-SN: SP positives and SN
%   negatives), each scored on all examples as Key-(Prog-Score) (keys: J, Soft, support, then
%   literal cost and the order found, which break ties), and the round that found them (first, or
%   smaller).  Each sample's search has an equal share of the time left before the deadline.  With
%   shrink_samples(true), where no sample of the first size gives any hypothesis (each drawn sample
%   held a positive whose facts no small program shares with the others', or a negative that
%   shares them), samples half the size, positives rounded up and negatives down, down to one
%   positive and no negative (each positive alone: the minimal samples of sample consensus, all of
%   them): the programs of every smaller size, each once in the order found, are scored together and
%   those kept (kept/4) compete, so an unlucky draw of a middle size cannot end the search with one
%   positive's idiosyncrasy before the minimal samples are seen.  Only when every sample of the
%   first size runs out of time is it the time-limit error; a smaller size that runs out gives
%   nothing.
scored_hypotheses(Search, First, Scored, Which) :-
    Search = search(_, Settings, _, _, _, _, _, _, _),
    sample_programs(Search, First, first, Progs1),
    scored(Search, Progs1, Scored1),
    (   Scored1 \== []
    ->  Scored-Which = Scored1-first
    ;   option(shrink_samples(true), Settings)
    ->  smaller_programs(Search, First, Progs2),
        scored(Search, Progs2, Scored2), kept(smaller, First, Scored2, Scored), Which = smaller
    ;   Scored-Which = []-first
    ).

%   The distinct programs the samples of SP positives and SN negatives give, in the order found.
sample_programs(Search, SP-SN, Round, Progs) :-
    Search = search(Ctx, Settings, _, _, K, Deadline, T, Pos, Neg),
    samples(K, SP, SN, Pos, Neg, Drawn),
    length(Drawn, ND), list_to_set(Drawn, Samples), length(Samples, NS),
    get_time(Now), TS is (Deadline - Now) / ND,
    foldl(sample_hypotheses(Ctx, Settings, TS), Samples, r([], 0), r(Found0, TimedOut)),
    (   TimedOut =:= NS, Round == first -> throw(mil_error(time_limit(T))) ; true ),
    append(Found0, Found),
    list_to_set(Found, Progs).

%   The distinct programs of every size smaller than Size (smaller/2) while time is left, in the
%   order found.
smaller_programs(Search, Size, Progs) :-
    Search = search(_, _, _, _, _, Deadline, _, _, _),
    (   smaller(Size, Smaller), get_time(Now), Now < Deadline
    ->  sample_programs(Search, Smaller, smaller, Progs1),
        smaller_programs(Search, Smaller, Progs2),
        append(Progs1, Progs2, Progs12), list_to_set(Progs12, Progs)
    ;   Progs = []
    ).

%   Each program scored on all examples, keyed for selection (the order found breaks ties).
scored(Search, Progs, Scored) :-
    Search = search(Ctx, _, SCtx, LT, _, _, _, Pos, Neg),
    findall(Key-(Prog-S), (nth1(Order, Progs, Prog),
                           score(SCtx, LT, Prog, Pos, Neg, S),
                           S = score(J, Soft, _, _, _), support(Ctx, Prog, Pos, W),
                           literal_cost(Ctx, Prog, Cost), NCost is -Cost, NOrder is -Order,
                           Key = k(J, Soft, W, NCost, NOrder)), Scored).

smaller(SP-SN, SP1-SN1) :- ( SP > 1 ; SN > 0 ), SP1 is max(1, (SP + 1) // 2), SN1 is SN // 2.

%   A hypothesis of a smaller sample is kept only where it leaves a first-size sample's negatives (SN)
%   unproved: samples shrink because every first-size sample held a positive whose facts no small
%   program shares with the others' (one perception spoiled: a can cut into planes), so a smaller
%   sample's hypothesis may miss positives, and J on all examples weighs what it misses; but one that
%   proves more negatives than a first-size sample may leave out is over-general, whatever its J.
%   Those of the first size are kept.
kept(first, _, Hs, Hs) :- !.
kept(smaller, Size, Hs0, Hs) :- include(leaves_sample_negatives(Size), Hs0, Hs).

leaves_sample_negatives(_-SN, _-(_-score(_, _, _, FP/NN, _))) :- NN - FP >= SN.

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
    option(reference(Ref0), Settings), maplist(to_lit, Ref0, Ref00),
    append(Pos, Ref00, Ref1), sort(Ref1, Ref),
    option(extension_miss(Eps), Settings), near_ctx(Ctx, Eps, NCtx),
    option(literal_prior(LP), Settings), option(predicate_prior(PP), Settings),
    findall(k(B, Soft, W, C, O)-(Prog-S),
            ( member(k(J, Soft, W, C, O)-(Prog-S), All), J >= JMax - 1.0e-9,
              size_likelihood(Ctx, NCtx, Prog, Pos, Ref, L),
              prog_lits(Prog, NL), predicate_cost(Ctx, PP, Prog, PC), B is L - LP * NL - PC ), Top),
    max_member(_-(Best-Score), Top).

to_lit(E, L) :- ( E = l(_, _, _) -> L = E ; atom_lit(E, L) ).

size_likelihood(Ctx, NCtx, Prog, Pos, Ref, B) :-
    maplist(best_conf(Ctx, Prog), Pos, CP),
    foldl(extension(Ctx, NCtx, Prog), Ref, 0.0, Ext),
    foldl(log_likelihood(Ext), CP, 0.0, B).

%   The body symbols of a program's clauses (ordering literals aside).
body_symbols(Ctx, Prog, Syms) :-
    findall(Q, ( member(Item, Prog), item_clause(Ctx, Item, Cl), Cl = (_ :- B),
                 conj_member(G, B), functor(G, Q, _) ), Syms).

conj_member(G, (A, B)) :- !, ( conj_member(G, A) ; conj_member(G, B) ).
conj_member(G, G).

%   The log prior a program's body literals cost under predicate_prior: Nats per literal of P.
predicate_cost(_, [], _, 0) :- !.
predicate_cost(Ctx, PP, Prog, Cost) :-
    body_symbols(Ctx, Prog, Syms),
    aggregate_all(sum(N), ( member(Q, Syms), memberchk([Q, N], PP) ), Cost).

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
near_ctx(Ctx, Eps, NCtx) :-
    set_threshold_of_ctx(1.0e-12, Ctx, C1), set_miss_of_ctx(Eps, C1, NCtx).

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
    set_threshold_of_ctx(TMin, Ctx, SCtx).

%   Two-clause programs: one view of a solid seldom shows every pose's evidence (a triangular prism
%   lying on a side shows no triangle), and a sample of two positives rarely needs two clauses, so
%   the search seldom proposes them.  The KD best one-clause, non-recursive hypotheses are paired;
%   a pair proves what either clause proves, so its best confidence per example is the larger of
%   the two, and it is scored like any program (its second clause pays clause_penalty).  Support
%   is the sum of the two clauses' supports and cost the sum of their literal costs.
disjunctions(_, _, 0, _, _, _, []) :- !.
disjunctions(Ctx, Lambda-Ts, KD, Pos, Neg, Scored, Pairs) :-
    include(single_clause(Ctx), Scored, Singles),
    sort(1, @>=, Singles, Ranked),
    findall(h(Prog, CP, CN, W, C, O),
            ( limit(KD, member(k(_, _, W, C, O)-(Prog-_), Ranked)),
              maplist(best_conf(Ctx, Prog), Pos, CP), maplist(best_conf(Ctx, Prog), Neg, CN) ), Hs),
    findall(k(J, Soft, W, NC, NO)-(Prog-S),
            ( append(_, [h(P1, CP1, CN1, W1, C1, O1)|Rest], Hs), member(h(P2, CP2, CN2, W2, C2, O2), Rest),
              maplist(max_of, CP1, CP2, CP), maplist(max_of, CN1, CN2, CN),
              Penalty is 2 * Lambda, best_threshold(Ts, Penalty, CP, CN, S), S = score(J, Soft, _, _, _),
              W is W1 + W2, NC is C1 + C2, NO is min(O1, O2), append(P2, P1, Prog) ),
            Pairs).

%   One clause of a target whose body names no target (no recursion).
single_clause(Ctx, _-([Item]-_)) :-
    Item = sub(_, P, A, _, _),
    ctx_targets(Ctx, Ts), memberchk(P/A, Ts),
    body_symbols(Ctx, [Item], Syms),
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
    ctx_bps(Ctx, BPs),
    body_symbols(Ctx, Prog, Syms),
    findall(R, ( member(Q, Syms), ( nth0(R, BPs, bp(Q, _, _)) -> true ; R = 0 ) ), Rs),
    sum_list(Rs, Cost).

%!  best_conf(+Ctx, +Prog, +Atom, -Conf) is det.  The confidence of Atom's best proof with Prog, 0
%   when there is none.
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
%   With extra_literals(X) and a literal bound, those up to X literals longer too.
sample_hypothesis(Ctx0, Settings, Pos, Neg, Prog) :-
    option(solutions(J), Settings), option(extra_literals(X), Settings),
    size(Settings, Ctx0, Ctx),
    sized_hypotheses(Ctx, J, Pos, Neg, Progs0),
    Progs0 \== [], !,
    ctx_maxl(Ctx, L0),
    (   L0 == inf -> More = []
    ;   Lim is L0 + X,
        findall(P, ( size(Settings, Ctx0, C1), ctx_maxl(C1, L), L > L0, L =< Lim,
                     sized_hypotheses(C1, J, Pos, Neg, Ps), member(P, Ps) ), More)
    ),
    append(Progs0, More, Progs),
    member(Prog, Progs).

sized_hypotheses(Ctx, J, Pos, Neg, Progs) :-
    findall(P, all_examples(Pos, Ctx, [], P), Ps0), list_to_set(Ps0, Ps),
    findall(P, limit(J, (member(P, Ps), consistent(Ctx, Pos, Neg, P))), Progs).

%   Each example's proof may extend the program; other proofs that give the same program are
%   pruned (distinct/2), else every proof of every later example would repeat a hypothesis.
all_examples([], _, Prog, Prog).
all_examples([E|Es], Ctx, Prog1, Prog3) :-
    length(Prog1, N0), ctx_depth(Ctx, D), ctx_sig(Ctx, Sig),
    distinct(Prog2, prove([E], Ctx, Sig, [], D, Prog1, Prog2, N0, _, 1.0, _, _, [])),
    all_examples(Es, Ctx, Prog2, Prog3).

%   K samples: the whole set when it is small, each positive alone for samples of one positive and no
%   negative, else random subsets (seeded by the caller).
samples(_, SP, SN, Pos, Neg, [Pos-Neg]) :-
    length(Pos, NP), NP =< SP, length(Neg, NN), NN =< SN, !.
samples(_, 1, 0, Pos, _, Samples) :- !,
    findall([P]-[], member(P, Pos), Samples).
samples(K, SP, SN, Pos, Neg, Samples) :-
    length(Samples, K),
    maplist(sample(SP, SN, Pos, Neg), Samples).
sample(SP, SN, Pos, Neg, P1-N1) :- pick(SP, Pos, P1), pick(SN, Neg, N1).
pick(K, Xs, Ys) :- random_permutation(Xs, Zs), length(Xs, L), M is min(K, L), length(Ys, M), append(Ys, _, Zs).

%   A program that proves every positive has the round's size, no clause twice, no clause with a
%   literal twice, proves no negative and passes the functional check (setting functional(true)).  A clause whose body holds one literal twice (part2
%   with R = S) says no more than a shorter one found before it, but under combine(product) its
%   proofs are less confident, which can game the coverage threshold.
consistent(Ctx, Pos, Neg, Prog) :-
    ground(Prog),
    ctx_maxn(Ctx, N), length(Prog, N),
    exact_size(Ctx, Prog),
    sort(Prog, Sorted), length(Sorted, N),
    \+ ( member(Item, Prog), repeated_literal(Ctx, Item) ),
    \+ ( member(E, Neg), covers(Ctx, Prog, E, _, _) ),
    functional_ok(Ctx, Prog, Pos).
