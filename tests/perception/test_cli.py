import json

import cv2
import numpy as np

from lv3d.cli import main


def _write_frame(tmp_path, frame):
    c = tmp_path / "box_rgb.png"
    d = tmp_path / "box_depth.png"
    cv2.imwrite(str(c), cv2.cvtColor(frame.color, cv2.COLOR_RGB2BGR))
    cv2.imwrite(str(d), np.round(frame.depth * 1000).astype(np.uint16))
    k = tmp_path / "k.json"
    k.write_text(json.dumps(frame.intrinsics.to_dict()))
    return c, d, k


def test_extract_writes_scene_and_overlay(tmp_path, box_frame):
    c, d, k = _write_frame(tmp_path, box_frame[0])
    out = tmp_path / "out"
    rc = main(["extract", str(c), "--depth", str(d), "--intrinsics", str(k), "--modality", "rgbd", "--out", str(out)])
    assert rc == 0
    scene = json.loads((out / "scene.json").read_text())
    assert scene["modality"] == "rgbd" and scene["target"] == "box_o1"  # the scene is named after the frame
    assert len(scene["objects"][0]["faces"]) == 3
    assert cv2.imread(str(out / "overlay.png")).shape == (240, 320, 3)
    assert not [p for p in tmp_path.iterdir() if p.name.startswith(".out")]  # no temporary folder left


def test_extract_needs_depth_for_depth_modality(tmp_path, box_frame, capsys):
    c, _, k = _write_frame(tmp_path, box_frame[0])
    out = tmp_path / "out"
    rc = main(["extract", str(c), "--intrinsics", str(k), "--modality", "depth", "--out", str(out)])
    assert rc == 2
    assert "--depth" in capsys.readouterr().err
    assert not out.exists()


def test_extract_needs_no_intrinsics_for_colour_alone(tmp_path, box_frame):
    c, _, _ = _write_frame(tmp_path, box_frame[0])
    out = tmp_path / "out"
    rc = main(["extract", str(c), "--modality", "rgb", "--out", str(out), "--facts"])
    assert rc == 0
    scene = json.loads((out / "scene.json").read_text())
    assert scene["modality"] == "rgb" and len(scene["objects"][0]["faces"]) == 3
    assert (out / "facts.pl").read_text().count("quadrilateral(") >= 3


def test_extract_needs_intrinsics_with_depth(tmp_path, box_frame, capsys):
    c, d, _ = _write_frame(tmp_path, box_frame[0])
    rc = main(["extract", str(c), "--depth", str(d), "--modality", "rgbd", "--out", str(tmp_path / "o")])
    assert rc == 2
    assert "--intrinsics" in capsys.readouterr().err and not (tmp_path / "o").exists()


def test_extract_rejects_a_missing_image(tmp_path, box_frame, capsys):
    _, d, k = _write_frame(tmp_path, box_frame[0])
    rc = main(["extract", str(tmp_path / "nope.png"), "--depth", str(d), "--intrinsics", str(k),
               "--out", str(tmp_path / "o")])
    assert rc == 2
    assert "nope.png" in capsys.readouterr().err


def test_extract_names_the_missing_image_before_looking_up_its_intrinsics(tmp_path, capsys):
    k = tmp_path / "intrinsics.json"
    k.write_text('{"width": 640, "height": 480, "frames": {"a": {"fx": 525, "fy": 525, "cx": 320, "cy": 240}}}')
    rc = main(["extract", str(tmp_path / "nope_rgb.png"), "--modality", "rgb", "--intrinsics", str(k),
               "--out", str(tmp_path / "o")])
    assert rc == 2
    err = capsys.readouterr().err
    assert "nope_rgb.png: image not found" in err and not (tmp_path / "o").exists()


def test_extract_replaces_its_own_output_and_nothing_else(tmp_path, box_frame, capsys):
    from lv3d.output import MARKER

    c, d, k = _write_frame(tmp_path, box_frame[0])
    out = tmp_path / "out"
    args = ["extract", str(c), "--depth", str(d), "--intrinsics", str(k), "--out", str(out)]
    assert main(args + ["--facts"]) == 0 and (out / "facts.pl").is_file() and (out / MARKER).is_file()
    assert main(args) == 0  # a rerun into lv3d's own output replaces it
    assert sorted(p.name for p in out.iterdir()) == [MARKER, "overlay.png", "scene.json"]
    assert sorted(p.name for p in tmp_path.iterdir()) == ["box_depth.png", "box_rgb.png", "k.json", "out"]
    (out / MARKER).unlink()  # no longer marked as lv3d's: refused, left as it is
    capsys.readouterr()
    assert main(args) == 2 and "lv3d did not write" in capsys.readouterr().err
    assert sorted(p.name for p in out.iterdir()) == ["overlay.png", "scene.json"]


def test_extract_caps_objects_and_says_how_many_it_left_out(tmp_path, capsys):
    from lv3d.render import noise_config, render_scene

    frame = render_scene("cube", 0, noise_config("clean", stacked=1.0))[0]  # a box on a box: two objects
    c, d, k = _write_frame(tmp_path, frame)
    out = tmp_path / "out"
    rc = main(["extract", str(c), "--depth", str(d), "--intrinsics", str(k), "--modality", "depth",
               "--max-objects", "1", "--out", str(out)])
    assert rc == 0
    assert "1 smaller objects left out by --max-objects" in capsys.readouterr().out
    scene = json.loads((out / "scene.json").read_text())
    assert len(scene["objects"]) == 1 and scene["dropped_objects"] == 1
    rc = main(["extract", str(c), "--depth", str(d), "--intrinsics", str(k), "--max-objects", "0",
               "--out", str(tmp_path / "out2")])
    assert rc == 2 and "--max-objects" in capsys.readouterr().err


def test_extract_names_the_scene_after_a_frame_whose_name_is_no_prolog_atom(tmp_path, box_frame):
    c, d, k = _write_frame(tmp_path, box_frame[0])
    c2, d2 = tmp_path / "frame-000000_rgb.png", tmp_path / "frame-000000_depth.png"
    c.rename(c2)
    d.rename(d2)
    out = tmp_path / "out"
    assert main(["extract", str(c2), "--depth", str(d2), "--intrinsics", str(k), "--modality", "rgbd",
                 "--out", str(out), "--facts"]) == 0
    scene = json.loads((out / "scene.json").read_text())
    assert scene["id"].startswith("frame_000000_") and scene["target"].startswith(scene["id"])
    facts = json.loads((out / "facts.json").read_text())
    assert facts["scene"] == scene["id"] and facts["facts"]


def test_extract_perceives_with_the_depth_settings_given_and_refuses_a_bad_one(tmp_path, capsys, monkeypatch):
    import importlib

    from lv3d.perception.depth import with_overrides
    from lv3d.render import noise_config, render_scene

    frame = render_scene("cube", 0, noise_config("clean", stacked=1.0))[0]  # a box on a box: two objects
    c, d, k = _write_frame(tmp_path, frame)
    module = importlib.import_module("lv3d.perception.perceive")
    seen, perceive = [], module.perceive
    monkeypatch.setattr(module, "perceive", lambda *a, **kw: seen.append(kw["depth_settings"]) or perceive(*a, **kw))
    args = ["extract", str(c), "--depth", str(d), "--intrinsics", str(k), "--modality", "depth"]
    assert main([*args, "--depth-set", "max_objects=1", "--depth-set", "sensor.base_m=0.005",
                 "--out", str(tmp_path / "out")]) == 0
    assert seen == [with_overrides({"max_objects": 1, "sensor.base_m": 0.005})]
    assert "1 smaller objects left out" in capsys.readouterr().out  # the setting took: one object described
    for bad, says in (("sensor.nope=1", "--depth-set: sensor.nope: unknown setting 'nope'"),
                      ("max_objects=many", "--depth-set: max_objects: must be of type int"),
                      ("stride", "--depth-set: expected key=value")):
        assert main([*args, "--depth-set", bad, "--out", str(tmp_path / "bad")]) == 2
        err = capsys.readouterr().err
        assert says in err and len(err.strip().splitlines()) == 1
    assert not (tmp_path / "bad").exists()  # refused before any output
