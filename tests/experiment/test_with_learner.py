"""The runner drives the real learner (lv3d.learn) through the LogicSystem adapter."""

import json

import pytest

from lv3d.experiment.runner import run_study


def test_real_learner_learns_side_counts(tmp_path, tiny_config, synthetic_facts, monkeypatch):
    learn = pytest.importorskip("lv3d.learn")
    model = pytest.importorskip("lv3d.learn.model")
    monkeypatch.setattr(learn, "Model", getattr(learn, "Model", model.Model), raising=False)
    out = tmp_path / "run"
    run_study(tiny_config, out, ["systems=[lv3d-rgb]", "folds=2"], progress=False)
    rec = json.loads((out / "folds" / "base" / "lv3d-rgb" / "fold0.json").read_text())
    # each class has its own side count, so a one-literal program separates it
    assert all(rec["tasks"][c]["accuracy"] == 1.0 for c in ("cube", "square_pyramid", "triangular_prism"))
    assert rec["tasks"]["multiclass"]["accuracy"] == 1.0
    # every multi-class answer came from a proof, and the report counts how the answers were reached
    assert [set(draw) for draw in rec["answered_by"]] == [{"proof"}] * len(rec["answered_by"])
    assert len(rec["answered_by"][0]) == len(rec["test_ids"])
    summary = json.loads((out / "results.json").read_text())
    kinds = next(iter(summary["conditions"].values()))["systems"]["lv3d-rgb"]["answered_by"]
    assert set(kinds) == {"proof"} and kinds["proof"][0] == kinds["proof"][1] > 0
    assert 0.5 <= kinds["proof"][2] <= 1.0  # their mean confidence: a proof's is at least the threshold
    md = (out / "results.md").read_text()
    assert "How the lv3d systems reached their multi-class answers" in md and f"(100 %, {kinds['proof'][2]:.2f})" in md
    # every answer right: no class confused with another, and the matrix is drawn
    confusion = next(iter(summary["conditions"].values()))["systems"]["lv3d-rgb"]["confusion"]
    assert confusion["pairs"] == [] and sum(confusion["answers"].values()) == kinds["proof"][0]
    assert (out / "confusion.png").is_file()
    programs = out / "programs" / "base" / "lv3d-rgb" / "fold0"
    assert (programs / "cube" / "cube.pl").is_file() and (programs / "multiclass" / "cube.pl").is_file()
    assert "quadrilateral" in (programs / "cube" / "cube.pl").read_text()
    # the report names the version of lv3d's code the figures came from
    from lv3d.experiment.code_version import learner_version
    assert rec["code"] == learner_version() and f"`{learner_version()}`" in (out / "results.md").read_text()
