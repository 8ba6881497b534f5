"""make_dataset and the `lv3d dataset` command: layout, reproducibility, atomic writes, bad input."""

import hashlib
import json

import numpy as np
import pytest

from lv3d.cli import main
from lv3d.errors import InputError
from lv3d.render import make_dataset, noise_config
from lv3d.rgbd import load_item

ARGS = dict(classes=["cube", "tetrahedron"], per_class=2, noise="realsense", seed=11, width=160, height=120,
            progress=False)


def _hashes(folder):
    return {str(p.relative_to(folder)): hashlib.sha256(p.read_bytes()).hexdigest()
            for p in sorted(folder.rglob("*")) if p.is_file()}


@pytest.fixture(scope="module")
def made(tmp_path_factory):
    root = tmp_path_factory.mktemp("ds")
    return make_dataset(root / "one", workers=1, **ARGS)


def test_layout_follows_docs_dataset_md(made):
    m = json.loads((made / "manifest.json").read_text())
    assert m["schema"] == "lv3d.dataset/1" and m["noise"] == "realsense" and m["seed"] == 11
    assert [it["class"] for it in m["items"]] == ["cube", "tetrahedron", "cube", "tetrahedron"]
    for it in m["items"]:
        assert sorted(p.name for p in (made / it["dir"]).iterdir()) == \
            ["color.png", "depth.png", "faces.png", "meta.json"]
        frame = load_item(made / it["dir"])
        assert frame.meta["truth"]["class"] == it["class"] and frame.meta["id"] == it["id"]
        assert frame.color.shape == (120, 160, 3) and frame.depth.max() < 10


def test_items_reload_equal_to_render(made):
    from lv3d.render import render_scene
    m = json.loads((made / "manifest.json").read_text())
    it = m["items"][1]
    frame, faces = render_scene(it["class"], it["seed"], "realsense", 160, 120, scene_id=it["id"])
    back = load_item(made / it["dir"])
    assert np.array_equal(back.color, frame.color)
    assert np.allclose(back.depth, frame.depth, atol=1e-6)
    assert back.meta == json.loads(json.dumps(frame.meta))


def test_same_seed_same_bytes_for_any_worker_count(made, tmp_path):
    two = make_dataset(tmp_path / "two", workers=2, **ARGS)
    assert _hashes(made) == _hashes(two)
    other = make_dataset(tmp_path / "three", workers=2, **{**ARGS, "seed": 12})
    assert _hashes(other) != _hashes(made)


def test_finished_set_is_returned_and_mismatch_refused(made):
    before = _hashes(made)
    assert make_dataset(made, workers=1, **ARGS) == made
    assert _hashes(made) == before
    with pytest.raises(InputError, match="not empty"):
        make_dataset(made, workers=1, **{**ARGS, "seed": 99})


def test_bad_inputs(tmp_path):
    with pytest.raises(InputError, match="unknown class 'dodecahedron'"):
        make_dataset(tmp_path / "a", **{**ARGS, "classes": ["cube", "dodecahedron"]})
    with pytest.raises(InputError, match="unknown noise preset 'fog'"):
        make_dataset(tmp_path / "a", **{**ARGS, "noise": "fog"})
    with pytest.raises(InputError, match="per-class"):
        make_dataset(tmp_path / "a", **{**ARGS, "per_class": 0})
    (tmp_path / "full").mkdir()
    (tmp_path / "full" / "x.txt").write_text("x")
    with pytest.raises(InputError, match="full: exists and is not empty"):
        make_dataset(tmp_path / "full", **ARGS)
    (tmp_path / "file").write_text("x")
    with pytest.raises(InputError, match="not a folder"):
        make_dataset(tmp_path / "file", **ARGS)
    assert sorted(p.name for p in tmp_path.iterdir()) == ["file", "full"]  # nothing half-written


def test_failed_run_leaves_nothing(tmp_path, monkeypatch):
    import lv3d.render.dataset as ds

    def boom(job):
        if job[1]["id"] == "s000002":
            raise RuntimeError("disk full")
        return real(job)

    real = ds._render_job
    monkeypatch.setattr(ds, "_render_job", boom)
    with pytest.raises(RuntimeError):
        make_dataset(tmp_path / "x", workers=1, **ARGS)
    assert list(tmp_path.iterdir()) == []


def test_override_knobs_are_recorded(tmp_path):
    out = make_dataset(tmp_path / "k", **{**ARGS, "per_class": 1, "noise": noise_config("clean", clutter=2)},
                       workers=1)
    m = json.loads((out / "manifest.json").read_text())
    assert m["noise"] == "clean" and m["noise_knobs"]["clutter"] == 2


def test_cli_make_show_and_errors(tmp_path, capsys):
    out = tmp_path / "cli"
    assert main(["dataset", "make", "--classes", "cube,square_pyramid", "--per-class", "1", "--noise", "mild",
                 "--seed", "3", "--out", str(out), "--workers", "1", "--width", "160", "--height", "120"]) == 0
    assert (out / "manifest.json").is_file()
    sheet = tmp_path / "sheet.png"
    assert main(["dataset", "show", str(out), "--out", str(sheet)]) == 0 and sheet.stat().st_size > 1000
    assert main(["dataset", "make", "--classes", "cube,blob", "--per-class", "1", "--out", str(tmp_path / "b")]) == 2
    assert main(["dataset", "make", "--classes", "cube", "--per-class", "1", "--noise", "fog",
                 "--out", str(tmp_path / "b")]) == 2
    assert main(["dataset", "show", str(tmp_path / "nope")]) == 2
    err = capsys.readouterr().err
    assert "unknown class 'blob'" in err and "unknown noise preset 'fog'" in err and "not a data set" in err


def test_dataset_show_writes_over_its_own_sheet_and_nothing_else(tmp_path):
    from lv3d.cli import main
    from lv3d.render import make_dataset

    data = tmp_path / "data"
    make_dataset(data, classes=["cube"], per_class=1, noise="clean", seed=0, width=160, height=120, progress=False)
    sheet = tmp_path / "sheet.png"
    assert main(["dataset", "show", str(data), "--out", str(sheet)]) == 0
    assert main(["dataset", "show", str(data), "--out", str(sheet)]) == 0  # its own sheet: replaced
    mine = tmp_path / "photo.png"
    mine.write_bytes(b"not lv3d's")
    assert main(["dataset", "show", str(data), "--out", str(mine)]) == 2
    assert mine.read_bytes() == b"not lv3d's"
    assert not [p for p in tmp_path.iterdir() if ".partial-" in p.name]


def test_a_data_set_made_on_a_dask_cluster_is_the_same_byte_for_byte(tmp_path):
    import hashlib

    from lv3d.experiment.executor import DaskExecutor
    from lv3d.render import make_dataset

    def digest(folder):
        return {p.relative_to(folder).as_posix(): hashlib.sha256(p.read_bytes()).hexdigest()
                for p in sorted(folder.rglob("*")) if p.is_file()}

    kw = dict(classes=["cube", "tetrahedron"], per_class=2, noise="realsense", seed=3, width=160, height=120,
              progress=False)
    make_dataset(tmp_path / "local", workers=1, **kw)
    ex = DaskExecutor(workers=2, processes=False)
    try:
        make_dataset(tmp_path / "dask", executor=ex, **kw)
    finally:
        ex.close()
    assert digest(tmp_path / "local") == digest(tmp_path / "dask")
