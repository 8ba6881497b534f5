"""Every command that writes an --out refuses, in one line and before any work, a regular file, a folder
lv3d did not write and a folder that holds its inputs, and leaves them as they were."""

import json

import cv2
import numpy as np
import pytest

from lv3d.cli import main
from lv3d.output import MARKER


def _snapshot(folder):
    return {p.relative_to(folder).as_posix(): p.read_bytes() if p.is_file() else None for p in folder.rglob("*")}


@pytest.fixture
def photos(tmp_path):
    """A user's folder with one frame and other files of theirs."""
    folder = tmp_path / "photos"
    folder.mkdir()
    cv2.imwrite(str(folder / "box_rgb.png"), np.full((48, 64, 3), 128, np.uint8))
    cv2.imwrite(str(folder / "box_depth.png"), np.full((48, 64), 900, np.uint16))
    (folder / "k.json").write_text(json.dumps({"fx": 60, "fy": 60, "cx": 32, "cy": 24, "width": 64, "height": 48}))
    (folder / "notes.txt").write_text("mine")
    return folder


def _extract(photos, out):
    return main(["extract", str(photos / "box_rgb.png"), "--depth", str(photos / "box_depth.png"),
                 "--intrinsics", str(photos / "k.json"), "--out", str(out)])


def _refused(rc, capsys, *words):
    err = capsys.readouterr().err
    assert rc == 2 and len(err.strip().splitlines()) == 1 and "Traceback" not in err, err
    for w in words:
        assert w in err, err


@pytest.mark.parametrize("out", [".", "..", "{photos}", "{photos}/notes.txt", "{photos}/box_rgb.png", "{other}"])
def test_extract_refuses_and_keeps_the_data(tmp_path, photos, monkeypatch, capsys, out):
    monkeypatch.chdir(photos)
    other = tmp_path / "other"
    other.mkdir()
    (other / "draft.md").write_text("keep")
    before = _snapshot(tmp_path)
    _refused(_extract(photos, out.format(photos=photos, other=other)), capsys, "--out")
    assert _snapshot(tmp_path) == before


def test_learn_fit_refuses_the_data_folder_and_a_folder_of_the_users(tmp_path, capsys):
    data = tmp_path / "data"
    data.mkdir()
    (data / "manifest.json").write_text("{}")
    mine = tmp_path / "mine"
    mine.mkdir()
    (mine / "model.json").write_text("my own")
    before = _snapshot(tmp_path)
    for out in (data, tmp_path, mine, data / "manifest.json"):
        _refused(main(["learn", "fit", "--data", str(data), "--out", str(out)]), capsys, "--out", str(out))
    assert _snapshot(tmp_path) == before


def test_learn_fit_replaces_its_own_output(tmp_path, capsys, monkeypatch):
    import lv3d.cli.learn as learn_cli
    from lv3d.learn.model import Model

    class Fitted:
        programs, failures, arbiters = {}, {}, {}

        def __init__(self, n):
            self.n = n

        def save(self, out_dir):
            (out_dir / f"run{self.n}.pl").write_text("% program\n")

    runs = iter([1, 2])
    from lv3d.examples import Examples
    from lv3d.facts import SceneFacts

    one = SceneFacts("s0", "rgbd", [], "s0_o1")
    monkeypatch.setattr(learn_cli, "_examples", lambda *a, **k: Examples([one], ["cube"]))
    monkeypatch.setattr(Model, "fit", classmethod(lambda cls, *a, **k: Fitted(next(runs))))
    data = tmp_path / "data"
    data.mkdir()
    out = tmp_path / "model"
    for _ in range(2):
        assert main(["learn", "fit", "--data", str(data), "--out", str(out)]) == 0
    assert sorted(p.name for p in out.iterdir()) == [MARKER, "depth_settings.json", "run2.pl"]
    assert sorted(p.name for p in tmp_path.iterdir()) == ["data", "model"]  # no temporary or old folder


def test_experiment_run_refuses_a_folder_of_the_users(tmp_path, capsys):
    config = tmp_path / "study.yaml"
    config.write_text("data: {classes: [cube, square_pyramid], per_class: 6}\n")
    mine = tmp_path / "mine"
    mine.mkdir()
    (mine / "notes.txt").write_text("mine")
    before = _snapshot(tmp_path)
    for out in (mine, tmp_path, config):
        _refused(main(["experiment", "run", str(config), "--out", str(out), "--quiet"]), capsys, "--out")
    assert _snapshot(tmp_path) == before


def test_demo_refuses_a_folder_of_the_users(tmp_path, capsys):
    (tmp_path / "notes.txt").write_text("mine")
    before = _snapshot(tmp_path)
    _refused(main(["demo", "--out", str(tmp_path)]), capsys, "--out", MARKER)
    assert _snapshot(tmp_path) == before


def test_the_demo_runs_end_to_end_on_data_it_makes(tmp_path, capsys):
    # `make demo`'s command at its smallest: it renders, learns, compares, explains and writes what it says
    out = tmp_path / "demo"
    assert main(["demo", "--out", str(out), "--per-class", "2", "--train", "1",
                 "--systems", "lv3d-depth,tree-rgbd", "--no-real"]) == 0
    said = capsys.readouterr().out
    assert "lv3d-depth:" in said and "tree-rgbd:" in said and "Why lv3d-depth says" in said
    results = json.loads((out / "results.json").read_text())
    assert set(results["accuracy"]) == {"lv3d-depth", "tree-rgbd"} and len(results["test"]) == 4
    assert (out / "accuracy.png").is_file() and list((out / "programs" / "lv3d-depth").glob("*.pl"))
