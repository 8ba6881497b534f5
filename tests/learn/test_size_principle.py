"""One-shot learning: among the hypotheses the few examples cannot tell apart, the size principle
(docs/learner.md) prefers the one that holds of few of the scenes' objects, and believes the
positive's facts."""

from lv3d.facts import Fact, SceneFacts
from lv3d.learn import fit


def _scene(k: int, target: list[tuple[str, float]], clutter: list[str]) -> SceneFacts:
    """A target object with one face holding ``target`` (pred, conf) facts, and one clutter object
    per entry of ``clutter``, each with one face holding that predicate."""
    s, o = f"s{k:06d}", f"s{k:06d}_o1"
    facts = [Fact("object", (o,), 1.0), Fact("face_of", (o, f"{o}_f1"), 1.0)]
    facts += [Fact(p, (f"{o}_f1",), c) for p, c in target]
    for j, p in enumerate(clutter, 2):
        c, f = f"{s}_o{j}", f"{s}_o{j}_f1"
        facts += [Fact("object", (c,), 1.0), Fact("face_of", (c, f), 1.0), Fact(p, (f,), 1.0)]
    return SceneFacts(s, "rgbd", facts, target=o)


def _one_shot(square_conf: float):
    # the positive's face is a quadrilateral and a square; every scene's clutter shows plain
    # quadrilaterals, so "a quadrilateral face" holds of many objects, "a square face" of one
    pos = _scene(0, [("quadrilateral", 1.0), ("square", square_conf)], ["quadrilateral", "quadrilateral"])
    negs = [_scene(k, [(p, 1.0)], ["quadrilateral"]) for k, p in ((1, "triangle"), (2, "pentagon"), (3, "hexagon"))]
    return [pos] + negs, ["box"] + ["other"] * 3


def test_prefers_the_hypothesis_true_of_fewer_objects():
    scenes, labels = _one_shot(1.0)
    prog = fit(scenes, labels, "box", settings={"metarules": ["part"], "disjunctions": 0})
    assert "square(B)" in prog.clauses[0] and "quadrilateral" not in prog.clauses[0]
    # without the size principle the caller's predicate order decides: quadrilateral comes first
    old = fit(scenes, labels, "box", settings={"metarules": ["part"], "disjunctions": 0,
                                                "size_principle": False})
    assert "quadrilateral(B)" in old.clauses[0]


def test_a_doubtful_fact_weighs_against_its_hypothesis():
    # likelihood c / |h|: "a rectangle face" holds of the positive (1.0) and one clutter object,
    # 1/2; "a square face" of the positive alone, believed c: c/1 wins for c = 0.6, loses for 0.4
    def learn(c):
        pos = _scene(0, [("rectangle", 1.0), ("square", c)], ["rectangle"])
        negs = [_scene(k, [(p, 1.0)], ["triangle"]) for k, p in ((1, "triangle"), (2, "pentagon"))]
        return fit([pos] + negs, ["box", "other", "other"], "box",
                   settings={"metarules": ["part"], "disjunctions": 0, "threshold": 0.3}).clauses[0]
    assert "square(B)" in learn(0.6)
    assert "rectangle(B)" in learn(0.4)


def test_extra_literals_offer_a_more_specific_clause():
    # a quadrilateral face holds of 5 objects, a rectangle one of 2, a face that is both of the
    # positive alone: with one literal more allowed, that clause is the most probable
    pos = _scene(0, [("quadrilateral", 1.0), ("rectangle", 1.0)], ["quadrilateral", "rectangle"])
    negs = [_scene(k, [(p, 1.0)], ["quadrilateral"]) for k, p in ((1, "triangle"), (2, "pentagon"), (3, "hexagon"))]
    scenes, labels = [pos] + negs, ["box"] + ["other"] * 3
    opts = {"metarules": ["part", "part2"], "disjunctions": 0}
    short = fit(scenes, labels, "box", settings={**opts, "extra_literals": 0}).clauses[0]
    assert "rectangle(B)" in short and "quadrilateral" not in short
    both = fit(scenes, labels, "box", settings={**opts, "extra_literals": 1}).clauses[0]
    assert "rectangle(B)" in both and "quadrilateral(B)" in both


def _square_regular_task():
    """One positive with a square, regular face among clutter triangles, two negatives: (scenes, labels)."""
    pos = _scene(0, [("square", 1.0), ("regular", 1.0)], ["triangle", "triangle"])
    negs = [_scene(k, [(p, 1.0)], ["triangle"]) for k, p in ((1, "pentagon"), (2, "hexagon"))]
    return [pos] + negs, ["box", "other", "other"]


def test_extension_miss_counts_near_proofs_of_uncovered_objects():
    # "a square face" and "a square, regular face" both hold of the positive alone (|h| = 1 by
    # count), so the caller's predicate order picks the shorter; measured with near proofs
    # (extension_miss), a clutter triangle nearly holds "a square face" (0.1) but the conjunction
    # only at 0.01, so the conjunction is the smaller hypothesis
    scenes, labels = _square_regular_task()
    opts = {"metarules": ["part", "part2"], "disjunctions": 0, "extra_literals": 1, "predicate_prior": []}
    count = fit(scenes, labels, "box", settings=opts).clauses[0]
    assert "square(B)" in count and "regular" not in count
    near = fit(scenes, labels, "box", settings={**opts, "extension_miss": 0.1}).clauses[0]
    assert "square(B)" in near and "regular(B)" in near


def test_literal_prior_charges_each_literal_against_the_extension_it_saves():
    # the scene of the test above: with near proofs, |"a square face"| = 1 + 6 x 0.1 = 1.6 and
    # |"a square, regular face"| = 1 + 6 x 0.01 = 1.06, a gain of log(1.6 / 1.06) = 0.41 nats for
    # one more literal; a prior of exp(-0.2) a literal lets it pay, exp(-1) does not
    scenes, labels = _square_regular_task()
    opts = {"metarules": ["part", "part2"], "disjunctions": 0, "extra_literals": 1, "extension_miss": 0.1,
            "predicate_prior": []}
    cheap = fit(scenes, labels, "box", settings={**opts, "literal_prior": 0.2}).clauses[0]
    assert "square(B)" in cheap and "regular(B)" in cheap
    dear = fit(scenes, labels, "box", settings={**opts, "literal_prior": 1.0}).clauses[0]
    assert "square(B)" in dear and "regular" not in dear


def test_predicate_prior_charges_the_literals_of_a_named_predicate():
    # "a regular face" (believed 1.0) and "a square face" (0.9) both hold of the positive alone:
    # by c / |h| the regular one wins; a prior of 0.5 nats a `regular` literal (the shape
    # default, docs/learner.md) outweighs log(1 / 0.9) = 0.11 nats, so the square one wins
    pos = _scene(0, [("square", 0.9), ("regular", 1.0)], [])
    negs = [_scene(k, [(p, 1.0)], []) for k, p in ((1, "triangle"), (2, "pentagon"))]
    scenes, labels = [pos] + negs, ["box", "other", "other"]
    opts = {"metarules": ["part"], "disjunctions": 0}
    flat = fit(scenes, labels, "box", settings={**opts, "predicate_prior": []}).clauses[0]
    assert "regular(B)" in flat
    charged = fit(scenes, labels, "box", settings={**opts, "predicate_prior": [["regular", 0.5]]}).clauses[0]
    assert "square(B)" in charged and "regular" not in charged
    assert fit(scenes, labels, "box", settings=opts).clauses[0] == charged
