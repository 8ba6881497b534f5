import pytest

from lv3d.errors import InputError
from lv3d.facts import Fact, SceneFacts


def test_fact_renders_as_prolog_and_round_trips_through_json():
    facts = [Fact("object", ("s1_o1",), 0.9), Fact("perpendicular", ("s1_o1_f1", "s1_o1_f2"), 0.8, 91.0)]
    sf = SceneFacts("s1", "rgbd", facts, target="s1_o1")
    assert facts[1].to_prolog() == "fact(perpendicular(s1_o1_f1,s1_o1_f2), 0.8000)."
    back = SceneFacts.from_json(sf.to_json())
    assert back.facts == facts and back.target == "s1_o1"


@pytest.mark.parametrize("bad", [("nosuch", ("a",), 0.5), ("object", ("a", "b"), 0.5),
                                 ("object", ("A",), 0.5), ("object", ("a",), 0.0), ("object", ("a",), 1.5)])
def test_fact_rejects_unknown_predicates_bad_arity_atoms_and_confidences(bad):
    with pytest.raises(ValueError):
        Fact(*bad)


def test_modality_filter_hides_depth_facts_from_rgb():
    sf = SceneFacts("s1", "rgbd", [Fact("perpendicular", ("f", "g"), 0.9), Fact("triangle", ("f",), 0.9)])
    assert [f.pred for f in sf.for_modality("rgb").facts] == ["triangle"]
    with pytest.raises(InputError):
        sf.for_modality("infrared")
