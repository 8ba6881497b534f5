"""scripts/near_answers.py: other rules and confidences for a study's answers by resemblance, on its own models.

The study's fold files, models and facts are given here; reading them from a run is the study's (tested there)."""

import pytest

from lv3d.facts import Fact, SceneFacts
from lv3d.learn import Model
from lv3d.learn.resemblance import Reference, profile, resemble


@pytest.fixture(scope="module")
def near_answers(load_script):
    return load_script("near_answers")


def _one_face(name: str, pred: str, conf: float) -> SceneFacts:
    o = f"{name}_o1"
    return SceneFacts(name, "depth", [Fact("object", (o,), 1.0), Fact("face_of", (o, f"{o}_f0"), 0.99),
                                      Fact(pred, (f"{o}_f0",), conf)], o)


def test_the_rule_in_use_reproduces_the_answers_and_the_others_are_counted(near_answers):
    facts = {"p": _one_face("p", "cylindrical", 0.9), "a": _one_face("a", "triangle", 0.8),
             "b": _one_face("b", "triangle", 0.3)}
    refs = [Reference("t1", "tetra", profile(_one_face("t1", "triangle", 0.9))),
            Reference("t2", "tetra", {"triangle": 0.1}),
            Reference("c1", "can", profile(_one_face("c1", "cylindrical", 0.9))),
            Reference("c2", "can", {"cylindrical": 0.4, "triangle": 0.35})]
    model = Model({}, references=refs)
    truth = {"p": "can", "a": "tetra", "b": "can"}
    # p proved (kept as the fold file holds it); a and b answered by resemblance with the confidence in use
    held = [["p", "can", 0.9], ["a", "tetra", resemble(profile(facts["a"]), refs).confidence],
            ["b", "tetra", resemble(profile(facts["b"]), refs).confidence]]
    record = {"predictions": {"multiclass": held}, "answered_by": [["proof", "near", "near"]],
              "test_ids": ["p", "a", "b"], "test_classes": [truth[i] for i in ("p", "a", "b")]}
    asked = []

    def load_model(fold, draw, draws):
        asked.append((fold, draw, draws))
        return model

    found = near_answers.weigh([("fold0", record)], load_model, facts, truth)
    assert asked == [("fold0", 0, 1)]
    assert found["answers"] == 3 and found["near"] == 2
    # a (triangle 0.8) lies 0.1 from t1: tetra, right; b (triangle 0.3) lies 0.45 from t2 and 0.7 from c2 (L1 over
    # the predicates and the face count): tetra, wrong, and by the mean of two too (tetra 0.525, can 0.95)
    assert found["right"]["nn"] == 1 and found["right"]["mean2"] == 1
    assert set(found["right"]) == set(near_answers.RULES)
    assert found["ece"]["ratio"] == pytest.approx(found["ece_held"])  # the confidence in use, recomputed
    assert 0 <= found["ece"]["inverse"] <= 1
    assert near_answers.weigh([("fold0", {"predictions": {}})], load_model, facts, truth) is None


def test_a_folder_that_is_not_a_study_run_is_named(tmp_path, near_answers):
    with pytest.raises(SystemExit, match="not a study's --out folder"):
        near_answers.main([str(tmp_path)])
