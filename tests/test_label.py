"""``lv3d label``: a first objects.csv for a folder of frames, a row per object perception finds."""

import csv
import json

import cv2
import numpy as np
import pytest

from lv3d.cli.app import main
from lv3d.cli.label import inner_pixel
from lv3d.frame_folder import FrameFolder
from tests.conftest import write_frame_folder


@pytest.fixture(scope="module")
def unlabelled(tmp_path_factory):
    """Two rendered frames in the real layout, their objects.csv removed, and the second also written at four
    times its size (1280x960, read at half of it: lv3d.rgbd.working_factor)."""
    folder = write_frame_folder(tmp_path_factory.mktemp("label") / "frames",
                           [("a-1", "cube", 11), ("b 2", "triangular_prism", 12)])
    truth = {row["frame"]: (int(row["u"]), int(row["v"])) for row in csv.DictReader((folder / "objects.csv").open())}
    (folder / "objects.csv").unlink()
    intr = json.loads((folder / "intrinsics.json").read_text())
    color = cv2.imread(str(folder / "b 2_rgb.png"))
    depth = cv2.imread(str(folder / "b 2_depth_mm.png"), cv2.IMREAD_UNCHANGED)
    cv2.imwrite(str(folder / "big_rgb.png"), cv2.resize(color, None, fx=4, fy=4, interpolation=cv2.INTER_NEAREST))
    cv2.imwrite(str(folder / "big_depth_mm.png"), cv2.resize(depth, None, fx=4, fy=4, interpolation=cv2.INTER_NEAREST))
    k = intr["frames"]["b 2"]
    intr["frames"]["big"] = {"fx": 4 * k["fx"], "fy": 4 * k["fy"], "cx": 4 * k["cx"], "cy": 4 * k["cy"],
                             "depth_scale_m": 0.001, "width": 1280, "height": 960}
    (folder / "intrinsics.json").write_text(json.dumps(intr))
    return folder, truth


def test_the_pixel_of_a_mask_is_the_one_farthest_from_its_edge():
    ring = np.zeros((40, 40), bool)
    ring[5:35, 5:35] = True
    ring[12:28, 12:28] = False  # a hole at the centre: the centroid lies on no pixel of the object
    u, v = inner_pixel(ring)
    assert ring[v, u] and min(u - 5, v - 5, 34 - u, 34 - v, max(12 - u, u - 27, 12 - v, v - 27)) >= 3
    edge = np.zeros((10, 10), bool)
    edge[:, :4] = True  # against the image's border: the border is an edge too
    assert inner_pixel(edge)[0] in (1, 2)


def test_a_row_per_perceived_object_whose_filled_in_file_is_read_back_onto_the_same_objects(unlabelled, tmp_path,
                                                                                          capsys):
    folder, truth = unlabelled
    before = sorted(p.name for p in folder.iterdir())
    out = tmp_path / "proposal"
    assert main(["label", str(folder), "--out", str(out)]) == 0
    said = capsys.readouterr().out
    assert "objects in 3 frames" in said and "objects.csv" in said
    assert sorted(p.name for p in folder.iterdir()) == before  # the folder is only read
    rows = list(csv.DictReader((out / "objects.csv").open()))
    assert {r["frame"] for r in rows} == {"a-1", "b 2", "big"}
    assert all(r["shape"] == "" and r["notes"].startswith("perceived: ") for r in rows)
    assert sorted(p.name for p in (out / "overlays").iterdir()) == ["a-1.png", "b 2.png", "big.png"]
    # with depth settings of its own: perception keeps one object a frame
    assert main(["label", str(folder), "--out", str(tmp_path / "one"), "--depth-set", "max_objects=1"]) == 0
    assert sorted(r["frame"] for r in csv.DictReader((tmp_path / "one" / "objects.csv").open())) == \
        ["a-1", "b 2", "big"]
    assert main(["label", str(folder), "--out", str(tmp_path / "bad"), "--depth-set", "nope=1"]) == 2
    assert "--depth-set: nope: unknown setting 'nope'" in capsys.readouterr().err
    assert not (tmp_path / "bad").exists()
    first = {r["frame"]: r for r in rows if r["object"] == "1"}
    # the frame at four times the size (1280x960) is read at half of it: its object's pixel is a cell of that grid,
    # in the pixels of its files, and lies where the small frame's does (within two of its cells)
    small, big = first["b 2"], first["big"]
    assert int(big["u"]) % 2 == 0 and int(big["v"]) % 2 == 0
    assert abs(int(big["u"]) - 4 * int(small["u"])) <= 8 and abs(int(big["v"]) - 4 * int(small["v"])) <= 8
    # with the classes filled in, the file reads back, and each row's pixel lies on the object it was made from
    for r in rows:
        r["shape"] = "thing"
    filled = tmp_path / "filled"
    import shutil

    shutil.copytree(folder, filled)
    with (filled / "objects.csv").open("w", newline="") as f:
        writer = csv.DictWriter(f, fieldnames=list(rows[0]))
        writer.writeheader()
        writer.writerows(rows)
    objects, problems = FrameFolder(filled).objects()
    assert problems == [] and len(objects) == len(rows)
    from lv3d.object_facts import frame_facts
    from lv3d.rgbd import load_real

    for name in ("a-1", "big"):
        labs = [(o.object, o.u, o.v) for o in objects if o.frame == name]
        ff = frame_facts(load_real(filled, name), "f", "depth", labs, refine=False)
        assert [ff.under[k] for k, _, _ in labs] == [f"f_o{k}" for k, _, _ in labs]
    u, v = truth["a-1"]  # the pixel at the centre of the rendered solid lies on the proposal's first object
    assert frame_facts(load_real(filled, "a-1"), "f", "depth", [(1, u, v)], refine=False).under[1] == "f_o1"
    # left empty, a shape is a row left out with its line named
    (filled / "objects.csv").write_text((out / "objects.csv").read_text())
    with pytest.raises(Exception, match="no usable row"):
        FrameFolder(filled).objects()


def test_a_folder_that_cannot_be_labelled_is_one_line(tmp_path, capsys):
    empty = tmp_path / "empty"
    empty.mkdir()
    assert main(["label", str(empty), "--out", str(tmp_path / "o")]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "no intrinsics.json" in err[0]
    (empty / "intrinsics.json").write_text("{}")
    assert main(["label", str(empty), "--out", str(tmp_path / "o")]) == 2
    assert "no frames" in capsys.readouterr().err
    assert main(["label", str(tmp_path / "nowhere"), "--out", str(tmp_path / "o")]) == 2
    assert "not a folder" in capsys.readouterr().err
    assert not (tmp_path / "o").exists()


def test_a_model_learned_on_labelled_frames_proposes_the_classes(frames, unlabelled, tmp_path, capsys, monkeypatch):
    import importlib

    import lv3d.perception

    perceive_module = importlib.import_module("lv3d.perception.perceive")  # the module: the package names the function

    seen, perceive = [], perceive_module.perceive  # each frame is perceived once, for its rows and its facts alike
    for where in (lv3d.perception, perceive_module):
        monkeypatch.setattr(where, "perceive", lambda frame, *a, **k: seen.append(frame.name) or perceive(frame, *a, **k))
    model = tmp_path / "model"
    assert main(["learn", "fit", "--data", str(frames), "--modality", "depth", "--cache", str(tmp_path / "cache"),
                 "--out", str(model), "--time-limit", "20"]) == 0
    capsys.readouterr()
    folder, truth = unlabelled
    out = tmp_path / "proposal"
    seen.clear()
    assert main(["label", str(folder), "--out", str(out), "--model", str(model)]) == 0
    assert "with the class" in capsys.readouterr().out
    assert sorted(seen) == ["a-1", "b 2", "big"]
    rows = {(r["frame"], r["object"]): r for r in csv.DictReader((out / "objects.csv").open())}
    # the rendered cube and prism (object 1 of their frames) get the classes the labelled frames taught
    assert rows[("a-1", "1")]["shape"] == "box" and rows[("b 2", "1")]["shape"] == "prism"
    assert rows[("big", "1")]["shape"] == "prism"  # the prism again, at four times the size
    assert "; model: box " in rows[("a-1", "1")]["notes"]
    assert all(r["shape"] in ("", "box", "prism") for r in rows.values())
    assert main(["label", str(folder), "--out", str(tmp_path / "p2"), "--model", str(tmp_path / "nowhere")]) == 2

