"""Shape concepts from one positive and a few negatives per class, checked on held-out scenes."""

from learn_scenes import SHAPES

from lv3d.learn import Model, fit


def one_positive(scenes, labels, cls):
    """The first scene of ``cls`` and every scene of the other classes."""
    first = labels.index(cls)
    keep = [first] + [i for i, y in enumerate(labels) if y != cls]
    return [scenes[i] for i in keep], [labels[i] for i in keep]


def test_programs_from_one_positive_classify_heldout(shape_train, shape_heldout):
    train_x, train_y = shape_train
    test_x, test_y = shape_heldout
    programs = {}
    for cls in SHAPES:
        x, y = one_positive(train_x, train_y, cls)
        assert y.count(cls) == 1 and len(y) == 16
        programs[cls] = fit(x, y, cls, seed=0)
    model = Model(programs)
    proofs = [{p["label"] for p in model._proofs(s)} for s in test_x]
    binary = {c: sum((c in got) == (y == c) for got, y in zip(proofs, test_y)) / len(test_y) for c in SHAPES}
    four_way = sum(model.predict(s)[0] == y for s, y in zip(test_x, test_y)) / len(test_y)
    report = "\n".join(f"% {c}: held-out accuracy {binary[c]:.3f}\n{programs[c]}" for c in SHAPES)
    report += f"\n% four-way accuracy (most confident program, 'unknown' if none): {four_way:.3f}"
    print("\n" + report)
    assert all(a >= 0.95 for a in binary.values()), report


def test_explanation_names_clause_and_facts(shape_train):
    x, y = shape_train
    model = Model.fit(x, y, seed=0)
    e = model.explain(x[0])
    assert e.label == y[0] and e.confidence == 1.0
    assert e.clauses and e.clauses[0].startswith(f"{y[0]}(")
    assert all(atom.split("(")[0] for atom, _ in e.facts) and any(x[0].target in a for a, _ in e.facts)
    assert f"is a {y[0]}" in str(e)


def test_unknown_when_no_program_proves(shape_train):
    x, y = shape_train
    prog = fit(x, y, "cube", seed=0)
    model = Model({"cube": prog})
    pyramid = x[y.index("square_pyramid")]
    assert model.predict(pyramid) == ("unknown", 0.0)
    assert "unknown" in str(model.explain(pyramid))
