"""The real-frame benchmark's figures on tiny hand-made scenes and masks, and its command line."""

import csv
import json
from pathlib import Path

import numpy as np
import pytest

import benchmarks.bench_real as bench
from lv3d.camera import Intrinsics
from lv3d.facts import Fact, SceneFacts
from lv3d.frame_folder import FrameFolder, LabelledObject, natural_key
from lv3d.object_facts import face_cover, held_object, merged_flags
from lv3d.plane import Plane
from lv3d.rgbd import RGBD
from lv3d.scene import Face, Scene, SceneObject


OSD = Path(__file__).resolve().parents[3] / "shared" / "data" / "real" / "osd-learn"
H, W = 60, 80
K = Intrinsics(fx=100.0, fy=100.0, cx=39.5, cy=29.5, width=W, height=H)


def _rect(u0, v0, u1, v1):
    """A rectangle's polygon covering pixel columns u0..u1 and rows v0..v1."""
    return np.array([(u0, v0), (u1, v0), (u1, v1), (u0, v1)], float)


def _obj(oid, rects, adjacency=()):
    faces = [Face(f"{oid}_f{j + 1}", _rect(*r), "depth") for j, r in enumerate(rects)]
    return SceneObject(oid, faces, list(adjacency))


def _lab(obj, u, v, shape="box", partial=False, stacked=False, frame="f0"):
    return LabelledObject(frame, obj, u, v, shape, partial, stacked)


def _mask(u0, v0, u1, v1):
    m = np.zeros((H, W), bool)
    m[v0:v1 + 1, u0:u1 + 1] = True
    return m


def test_frames_sort_naturally():
    assert sorted(["learn10", "learn2", "learn1", "learn0"], key=natural_key) == \
        ["learn0", "learn1", "learn2", "learn10"]


def test_the_object_under_a_pixel_is_the_one_with_most_faces_there_ties_to_the_first():
    a = _obj("o1", [(0, 0, 40, 40)])
    b = _obj("o2", [(20, 20, 60, 50), (30, 30, 60, 50)])
    covers = [face_cover(o, (H, W)) for o in (a, b)]
    assert covers[1][35, 35] == 2 and covers[0][35, 35] == 1
    assert held_object(covers, 35, 35) == 1   # two of o2's faces cover it, one of o1's
    assert held_object(covers, 25, 25) == 0   # one face each: the first listed
    assert held_object(covers, 5, 5) == 0
    assert held_object(covers, 75, 55) is None


def test_recall_needs_iou_one_half_and_split_needs_two_holders_of_a_fifth():
    label = np.zeros((H, W), np.uint16)
    label[_mask(0, 0, 19, 19)] = 1          # 400 px
    label[_mask(40, 0, 79, 19)] = 2         # 800 px
    label[_mask(0, 40, 9, 49)] = 3          # 100 px, missed
    masks = [_mask(0, 0, 19, 21),           # IoU 400/440 with object 1
             _mask(40, 0, 59, 19),          # half of object 2 (IoU 0.5)
             _mask(60, 0, 79, 19)]          # the other half
    n, matched, split = bench.gt_matches(label, masks)
    assert (n, matched, split) == (3, 2, 1)
    _, matched, split = bench.gt_matches(label, [_mask(0, 0, 79, 29)])  # one blob over objects 1 and 2
    assert matched == 0 and split == 0


def test_merged_with_masks_needs_a_fifth_of_the_other_and_without_masks_its_pixel():
    regions = [np.nonzero(_mask(0, 0, 9, 9)), np.nonzero(_mask(20, 0, 29, 9))]  # 100 px each
    big = _mask(0, 0, 21, 9)    # all of the first, 20 % of the second
    small = _mask(0, 0, 20, 9)  # 10 % of the second
    assert merged_flags([0, None], [big], regions) == [True, False]  # not found: not merged
    assert merged_flags([0, None], [small], regions) == [False, False]
    pixels = [(np.array([5]), np.array([5])), (np.array([5]), np.array([21]))]  # (rows, cols) of (u, v)
    assert merged_flags([0, 0], [big], pixels) == [True, True]
    assert merged_flags([0, 0], [small], pixels) == [False, True]


def _standing(h0, h1, n=400, seed=0):
    """Camera-frame points of an object whose heights above the plane y = 0.3 (normal up) span h0..h1 metres."""
    rng = np.random.default_rng(seed)
    h = rng.uniform(h0, h1, n)
    return np.stack([rng.uniform(-0.1, 0.1, n), 0.3 - h, rng.uniform(0.8, 1.0, n)], 1)


def test_support_is_where_objects_stand_nothing_sinks_and_a_stack_counts():
    table = Plane.from_arrays((0.0, -1.0, 0.0), 0.3)  # y = 0.3, the camera's side above it
    assert table.distance(_standing(0.1, 0.1, 1))[0] == pytest.approx(0.1)
    on, floating, sunk = _standing(0.0, 0.1), _standing(0.5, 0.6), _standing(-0.1, 0.05)
    assert bench.support_ok(table, [on]) is True
    assert bench.support_ok(table, [on, _standing(0.1, 0.2)]) is True   # a box on a box
    assert bench.support_ok(table, [floating]) is False                  # the floor under the table
    assert bench.support_ok(table, [on, sunk]) is False                  # a box top taken for the table
    assert bench.support_ok(None, [on]) is False
    assert bench.support_ok(table, [on[:10]]) is None                    # too few points to say
    far = _standing(0.03, 0.2) + np.array([0, 0, 3.0])                   # 4 m away: noise allows more
    assert bench.support_ok(table, [far]) is True


def test_pair_confidences_take_each_adjacent_pair_once_and_absent_facts_as_zero():
    o = _obj("o1", [(0, 0, 5, 5)] * 3, [("o1_f1", "o1_f2"), ("o1_f2", "o1_f1"), ("o1_f1", "o1_f3")])
    perp = {("o1_f1", "o1_f2"): 0.8, ("o1_f3", "o1_f1"): 0.3}
    assert bench.pair_confidences(o, perp) == [0.8, 0.3]
    assert bench.pair_confidences(o, {}) == [0.0, 0.0]


def _scene(modality="depth"):
    """A box of three faces (two perpendicular pairs) at left and a cylinder read as two faces at right, on a
    flat table seen straight on at 1 m (heights from the plane z = 1 do not matter here)."""
    box = _obj("s0_o1", [(2, 2, 20, 20), (21, 2, 35, 20), (2, 21, 20, 30)],
               [("s0_o1_f1", "s0_o1_f2"), ("s0_o1_f1", "s0_o1_f3")])
    cyl = _obj("s0_o2", [(45, 5, 60, 40), (61, 5, 75, 40)], [("s0_o2_f1", "s0_o2_f2")])
    support = Plane.from_arrays((0.0, 0.0, -1.0), 1.0) if modality != "rgb" else None
    scene = Scene("s0", modality, K, [box, cyl], support)
    facts = [Fact("perpendicular", ("s0_o1_f1", "s0_o1_f2"), 0.9), Fact("perpendicular", ("s0_o1_f2", "s0_o1_f1"), 0.9),
             Fact("perpendicular", ("s0_o2_f1", "s0_o2_f2"), 0.6)]
    if modality == "rgb":
        facts = []
    depth = np.full((H, W), 1.0, np.float32)
    frame = RGBD(np.zeros((H, W, 3), np.uint8), depth, K)
    return scene, SceneFacts("s0", modality, facts), frame


def _labelled():
    """Labels and masks for :func:`_scene`: box 1, cylinder 2, a bowl 3 where nothing was found, and a partial box 4
    lying on box 1's perceived object."""
    labels = [_lab(1, 10, 10, "box"), _lab(2, 50, 20, "cylinder"), _lab(3, 78, 58, "bowl"),
              _lab(4, 30, 10, "box", partial=True)]
    label = np.zeros((H, W), np.uint16)
    for k, rect in enumerate([(2, 2, 20, 30), (45, 5, 75, 40), (70, 50, 79, 59), (21, 2, 35, 20)], start=1):
        label[_mask(*rect)] = k
    return labels, label


def test_a_frame_counts_each_labelled_object_once_and_the_figures_follow():
    scene, facts, frame = _scene()
    labels, label = _labelled()
    row = bench.evaluate_frame(scene, facts, frame, labels, label)
    assert (row["labelled"], row["found"]) == (4, 3)
    assert row["merged"] == 2          # boxes 1 and 4 share one perceived object
    assert (row["gt"], row["matched"], row["split"]) == (4, 2, 0)  # box 4's mask is a third of its object
    assert row["support"] is True      # every object lies on the plane z = 1 m
    assert (row["boxes"], row["box_over"], row["box_unocc"], row["box_perp"]) == (2, 0, 1, 1)
    assert (row["round"], row["round_prism"]) == (2, 1)
    assert row["pairs_p"] == [0.6] and row["pairs_y"] == [0.0]  # the merged box object is left out

    f = bench.summarise([dict(row, ms=50.0, stages_ms={"objects": 30.0, "grounding": 10.0}),
                         dict(row, ms=150.0, stages_ms={"objects": 50.0})], "depth")
    assert set(f) == set(bench.KEYS) | set(bench.EXTRA_KEYS) | {bench.STAGES}
    assert f[bench.STAGES] == {"objects": 40.0, "grounding": 5.0}  # a stage a frame did not run counts 0 there
    assert f["object_recall"] == 0.5 and f["merged_frac"] == 0.5 and f["split_frac"] == 0.0
    assert f["support_ok_frac"] == 1.0 and f["box_perpendicular_frac"] == 1.0
    assert f["box_overfaced_frac"] == 0.0 and f["cylinder_as_prism_frac"] == 0.5
    assert f["perpendicular_ece"] == pytest.approx(0.6)
    assert f["ms_median"] == 100.0 and f["labelled_found"] == 0.75
    assert f["compile_s"] == 0.0  # rows without JIT work
    assert bench.summarise([dict(row, ms=50.0, compile_ms=300.0), dict(row, ms=150.0, compile_ms=200.0)],
                           "depth")["compile_s"] == 0.5


def test_each_labelled_object_has_a_record_whose_verdicts_sum_to_the_frame_counts(tmp_path):
    scene, facts, frame = _scene()
    scene.objects[1].faces[1].surface = "cylinder"
    facts = SceneFacts("s0", "depth", list(facts.facts) + [Fact("cylindrical", ("s0_o2_f2",), 0.8)])
    labels, label = _labelled()
    row = bench.evaluate_frame(scene, facts, frame, labels, label)
    box, cyl, bowl, part = row["objects"]
    assert [r["object"] for r in row["objects"]] == [1, 2, 3, 4]
    assert box["found"] and box["merged"] and box["merged_with"] == "4" and part["merged_with"] == "1"
    assert box["faces"] == 3 and box["surfaces"] == "plane*3" and box["best_perpendicular"] == 0.9
    assert box["box_perpendicular"] is True and part["box_perpendicular"] is None  # a partial box is not counted
    assert box["box_overfaced"] is False and box["as_prism"] is None and box["box_curved"] is False
    assert box["iou"] == pytest.approx(19 * 29 / (19 * 19 + 15 * 19 + 19 * 10))  # its mask: two of its three faces
    assert cyl["surfaces"] == "plane*1+cylinder*1" and cyl["as_prism"] is True and cyl["cylinder_read"] is True
    assert cyl["cylindrical"] == 0.8 and cyl["box_perpendicular"] is None
    assert not bowl["found"] and bowl["faces"] is None and bowl["iou"] is None and bowl["bowl_curved"] is False
    assert (row["box_perp"], row["box_unocc"], row["round_prism"], row["round"]) == (1, 1, 1, 2)
    assert (row["cyl_read"], row["cyl_unocc"], row["bowl_curved"], row["bowls"]) == (1, 1, 0, 1)

    # a confidence held as a numpy float gives a numpy bool verdict, counted all the same
    np_facts = SceneFacts("s0", "depth", list(facts.facts[:-1]) + [Fact("cylindrical", ("s0_o2_f2",), np.float64(0.8))])
    assert bench.evaluate_frame(scene, np_facts, frame, labels, label)["cyl_read"] == 1

    rgb_scene, rgb_facts, _ = _scene("rgb")
    rgb = bench.evaluate_frame(rgb_scene, rgb_facts, frame, labels, label)["objects"][0]
    assert rgb["found"] and rgb["box_overfaced"] is False
    assert rgb["box_perpendicular"] is None and rgb["best_perpendicular"] is None  # colour alone has no planes
    assert rgb["box_curved"] is None and rgb["box_elliptical"] is False

    out = tmp_path / "sub" / "objects.csv"
    bench.write_objects(out, [{"folder": "f", "modality": "depth", "seed": 0, **r} for r in row["objects"]])
    lines = out.read_text().splitlines()
    assert lines[0] == ",".join(bench.OBJECT_COLUMNS) and len(lines) == 5
    first = dict(zip(bench.OBJECT_COLUMNS, lines[1].split(",")))
    assert (first["found"], first["box_perpendicular"], first["as_prism"], first["best_perpendicular"]) == \
        ("yes", "yes", "", "0.900")


def test_ece_pools_box_and_cylinder_pairs_and_rgb_leaves_plane_figures_null():
    scene, facts, frame = _scene()
    labels = [_lab(1, 10, 10, "box"), _lab(2, 50, 20, "cylinder")]
    row = bench.evaluate_frame(scene, facts, frame, labels, None)  # no masks: pixels decide
    assert row["gt"] is None and row["merged"] == 0
    assert sorted(zip(row["pairs_p"], row["pairs_y"])) == [(0.0, 1.0), (0.6, 0.0), (0.9, 1.0)]
    f = bench.summarise([dict(row, ms=1.0)], "depth")
    # bins: 0.0 (conf 0, truth 1), 0.6 (0.6, 0), 0.9 (0.9, 1): (1 + 0.6 + 0.1) / 3
    assert f["perpendicular_ece"] == pytest.approx(1.7 / 3, abs=1e-4)
    assert f["object_recall"] is None and f["split_frac"] is None

    scene, facts, frame = _scene("rgb")
    row = bench.evaluate_frame(scene, facts, frame, labels, None)
    f = bench.summarise([dict(row, ms=1.0)], "rgb")
    for key in ("support_ok_frac", "box_perpendicular_frac", "cylinder_as_prism_frac", "perpendicular_ece"):
        assert f[key] is None
    assert f["box_overfaced_frac"] == 0.0 and f["labelled_found"] == 1.0


def test_the_table_puts_each_figure_beside_its_target():
    f = {k: None for k in bench.KEYS + bench.EXTRA_KEYS}
    text = bench.table("t", {"depth": dict(f, merged_frac=0.2, object_recall=0.95),
                             "rgbd": dict(f, ms_median=80.0)}, ["depth", "rgbd"])
    lines = {line.split()[0]: line for line in text.splitlines()[2:]}
    assert "0.200 MISS" in lines["merged_frac"] and "<= 0.05" in lines["merged_frac"]
    assert "0.950 ok" in lines["object_recall"]
    assert "80.0 ok" in lines["ms_median"] and lines["split_frac"].rstrip().endswith("-")


@pytest.mark.parametrize("missing", ["objects.csv", "intrinsics.json"])
def test_a_folder_without_its_files_is_one_line_naming_it(tmp_path, capsys, missing):
    (tmp_path / "f0_rgb.png").write_bytes(b"")
    (tmp_path / "f0_depth_mm.png").write_bytes(b"")
    for name in {"objects.csv", "intrinsics.json"} - {missing}:
        (tmp_path / name).write_text("frame,object,u,v,shape,partial,stacked,notes\n" if name.endswith("csv") else "{}")
    assert bench.main([str(tmp_path)]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and str(tmp_path) in err[0] and missing in err[0]


def test_unknown_modality_stops_at_the_command_line(capsys):
    with pytest.raises(SystemExit) as e:
        bench.main(["--modalities", "depth,lidar"])
    assert e.value.code == 2 and "choose among" in capsys.readouterr().err


def _stub_folders(monkeypatch) -> list:
    """bench.main with folders and figures stubbed out: each folder's (seeds, depth settings) is appended to the
    list returned."""
    seen = []

    def run_folder(folder, mods, limit, rows, overlays=None, seeds=(0,), settings=None, profiler=None):
        seen.append((seeds, settings))
        return {m: [] for m in mods}

    monkeypatch.setattr(bench, "run_folder", run_folder)
    monkeypatch.setattr(bench, "labelled_folder", lambda folder: None)
    monkeypatch.setattr(bench, "summarise", lambda rows, m: {k: None for k in bench.KEYS + bench.EXTRA_KEYS})
    return seen


def test_the_seed_reaches_perception_and_a_negative_one_stops_at_the_command_line(tmp_path, capsys, monkeypatch):
    with pytest.raises(SystemExit) as e:
        bench.main(["--seed", "-1"])
    assert e.value.code == 2 and "--seed" in capsys.readouterr().err
    seen = _stub_folders(monkeypatch)
    bench.main([str(tmp_path), "--seed", "5", "--modalities", "depth"])
    assert [s for s, _ in seen] == [(5,)] and "per seed" not in capsys.readouterr().out
    # several seeds: every frame perceived once per seed, the counts pooled (and the tables say so)
    bench.main([str(tmp_path), "--seed", "0,1,2", "--modalities", "depth"])
    assert seen[-1][0] == (0, 1, 2) and "once per seed 0,1,2" in capsys.readouterr().out
    for bad in ("1,1", "0,x"):
        with pytest.raises(SystemExit) as e:
            bench.main(["--seed", bad])
        assert e.value.code == 2 and "--seed" in capsys.readouterr().err


@pytest.mark.parametrize("opt", ["--objects", "--frames"])
def test_a_csv_option_names_a_file_not_a_folder(tmp_path, capsys, monkeypatch, opt):
    _stub_folders(monkeypatch)
    assert bench.main([str(tmp_path), "--modalities", "depth", opt, str(tmp_path)]) == 2
    assert f"{opt} names a file" in capsys.readouterr().err


def test_a_run_of_no_frame_writes_the_headers_alone(tmp_path, monkeypatch):
    _stub_folders(monkeypatch)
    out = tmp_path / "o.csv"
    assert bench.main([str(tmp_path), "--modalities", "depth", "--objects", str(out)]) == 0
    assert out.read_text().splitlines() == [",".join(bench.OBJECT_COLUMNS)]  # no frame, no object
    frames = tmp_path / "f.csv"
    assert bench.main([str(tmp_path), "--modalities", "depth", "--frames", str(frames)]) == 0
    assert frames.read_text().splitlines() == [",".join(bench.FRAME_COLUMNS)]


def test_depth_settings_reach_perception_and_a_wrong_one_is_named(tmp_path, capsys, monkeypatch):
    from lv3d.perception.depth import DEFAULT

    s = bench.depth_settings(["stride=2", "quadrics.fit_cells=400", "unread.max_behind=2"])
    assert (s.stride, s.quadrics.fit_cells, s.unread.max_behind) == (2, 400, 2)
    assert s.curved == DEFAULT.curved and DEFAULT.stride == 1  # the rest, and the default, as they were
    seen = _stub_folders(monkeypatch)
    bench.main([str(tmp_path), "--modalities", "depth", "--set", "stride=2"])
    assert seen[-1][1].stride == 2 and "stride=2" in capsys.readouterr().out
    bench.main([str(tmp_path), "--modalities", "depth"])
    assert seen[-1][1] is None
    assert bench.depth_settings(["curved.misfit_ratio=1"]).curved.misfit_ratio == 1  # a whole number for a float
    for bad, said in (("strid=2", "unknown setting 'strid'"), ("stride=0", "stride must be"),
                      ("nothing.x=1", "no part"), ("stride", "key=value"), ("stride=true", "must be of type int"),
                      ("quadrics.trials=abc", "must be of type int"), ("curved.misfit_ratio=x", "must be of type float")):
        assert bench.main([str(tmp_path), "--set", bad]) == 2
        assert said in capsys.readouterr().err


@pytest.mark.real
def test_one_osd_frame_end_to_end_writes_every_figure(tmp_path, capsys):
    osd = OSD
    if not (osd / "objects.csv").is_file():
        pytest.skip(f"real OSD frames not found at {osd} (../shared/data/real/osd-learn)")
    out, objects, frames = tmp_path / "bench.json", tmp_path / "objects.csv", tmp_path / "frames.csv"
    assert bench.main([str(osd), "--limit", "1", "--modalities", "depth", "--json", str(out),
                       "--objects", str(objects), "--frames", str(frames)]) == 0
    d = json.loads(out.read_text())
    keys = set(bench.KEYS) | set(bench.EXTRA_KEYS) | {bench.STAGES}
    assert set(d) == {"pooled", "folders"} and set(d["folders"]) == {"osd-learn"}
    assert set(d["pooled"]) == {"depth"} and set(d["pooled"]["depth"]) == keys
    fig = d["folders"]["osd-learn"]["depth"]
    assert set(fig) == keys
    assert fig["object_recall"] is not None and fig["ms_median"] > 0 and fig["cylinder_as_prism_frac"] is None
    assert fig[bench.STAGES]["objects"] > 0 and fig[bench.STAGES]["grounding"] > 0
    printed = capsys.readouterr().out
    assert "object_recall" in printed and "median ms by stage, depth: objects" in printed
    # a row per labelled object of the frame, whose verdicts give the figures
    rows = list(csv.DictReader(objects.open()))
    first = FrameFolder(osd).frames[0]
    labelled = [lab for lab in FrameFolder(osd).labels(bench.SHAPES).get(first, [])]
    assert [int(r["object"]) for r in rows] == [lab.object for lab in labelled]
    assert {r["frame"] for r in rows} == {first} and {r["modality"] for r in rows} == {"depth"}
    perp = [r["box_perpendicular"] for r in rows if r["box_perpendicular"]]
    assert fig["box_perpendicular_frac"] == pytest.approx(perp.count("yes") / len(perp))
    assert fig["labelled_found"] == pytest.approx([r["found"] for r in rows].count("yes") / len(rows))
    # one row per frame: its ms, whose median is the figure's, and each stage's
    (row,) = list(csv.DictReader(frames.open()))
    assert (row["folder"], row["frame"], row["modality"], row["seed"]) == ("osd-learn", first, "depth", "0")
    assert int(row["labelled"]) == len(labelled) and int(row["perceived"]) >= 1
    assert float(row["ms"]) == pytest.approx(fig["ms_median"], abs=0.05)
    assert float(row["objects_ms"]) == pytest.approx(fig[bench.STAGES]["objects"], abs=0.05)
    assert "fuse_ms" not in row  # a stage no frame of the run has (depth: no colour fusion) has no column


def test_a_folder_of_labelled_folders_stands_for_those_under_it(tmp_path):
    for name in ("b", "a", "plain"):
        (tmp_path / "parent" / name).mkdir(parents=True)
    for name in ("a", "b"):
        (tmp_path / "parent" / name / "objects.csv").write_text("frame,object,u,v,shape\n")
    (tmp_path / "own").mkdir()
    (tmp_path / "own" / "objects.csv").write_text("frame,object,u,v,shape\n")
    (tmp_path / "own" / "sub").mkdir()
    (tmp_path / "own" / "sub" / "objects.csv").write_text("frame,object,u,v,shape\n")
    parent, own, empty = tmp_path / "parent", tmp_path / "own", tmp_path / "parent" / "plain"
    assert bench.named_folders([parent]) == [parent / "a", parent / "b"]
    assert bench.named_folders([own, parent]) == [own, parent / "a", parent / "b"]  # its own objects.csv: itself
    assert bench.named_folders([empty]) == [empty]  # nothing labelled under it: itself, for its own error
    assert bench.named_folders([]) == bench.default_folders()


def test_objects_csv_naming_a_missing_frame_stops_before_any_work(tmp_path, capsys):
    (tmp_path / "f0_rgb.png").write_bytes(b"")
    (tmp_path / "f0_depth_mm.png").write_bytes(b"")
    (tmp_path / "intrinsics.json").write_text("{}")
    (tmp_path / "objects.csv").write_text("frame,object,u,v,shape,partial,stacked,notes\nf1,1,5,5,box,no,no,\n")
    assert bench.main([str(tmp_path)]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "objects.csv" in err[0] and "f1" in err[0]


def test_an_objects_csv_row_of_an_unknown_shape_or_unusable_is_named(tmp_path, capsys):
    (tmp_path / "f0_rgb.png").write_bytes(b"")
    (tmp_path / "f0_depth_mm.png").write_bytes(b"")
    (tmp_path / "intrinsics.json").write_text(json.dumps({"width": W, "height": H, "frames": {
        "f0": {"fx": 100.0, "fy": 100.0, "cx": 39.5, "cy": 29.5, "depth_scale_m": 0.001}}}))
    csv = tmp_path / "objects.csv"
    csv.write_text("frame,object,u,v,shape,partial,stacked\nf0,1,5,5,box,no,no\nf0,2,6,6,cone,no,no\n")
    with pytest.raises(bench.InputError, match="line 3: shape 'cone'"):
        bench.labelled_folder(tmp_path)
    csv.write_text("frame,object,u,v,shape,partial,stacked\nf0,1,5,5,box,no,no\nf0,2,5,500,box,no,no\n")
    assert len(FrameFolder(tmp_path).objects()[0]) == 1          # a study leaves the row out and counts it ...
    assert bench.main([str(tmp_path)]) == 2                        # ... the benchmark stops, before any work
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "objects.csv: line 3: pixel (5, 500) lies outside" in err[0]


def test_without_masks_the_support_reads_only_the_surface_connected_to_the_labelled_pixel():
    depth = np.full((H, W), 1.0, np.float32)
    depth[:, 40:] = 1.7          # beyond a table's edge: the floor, far below
    depth[10:20, 10:20] = 0.0    # no readings here
    depth[:, 5] = np.linspace(1.0, 1.05, H)  # a gentle slope stays connected
    outline = _mask(0, 0, 59, 59)  # a perceived outline spilling over the edge
    region = bench.connected_region(depth, outline, 30, 30)
    assert region[:, :40].sum() == 40 * H - 100 and not region[:, 40:].any()
    assert bench.connected_region(depth, outline, 11, 11).sum() == region.sum()  # no reading: the nearest seed
    assert not bench.connected_region(depth, outline, 15, 15).any()  # none within 2 % of the diagonal (2 px)
    assert not bench.connected_region(depth, _mask(10, 10, 19, 19), 15, 15).any()


def test_cylinders_read_need_a_cylindrical_fact_of_0_7_and_boxes_count_any_curved_face():
    scene, facts, frame = _scene()
    scene.objects[1].faces[1].surface = "cylinder"
    scene.objects[0].faces[2].surface = "cylinder"   # the box's third face taken for a curved one
    facts = SceneFacts("s0", "depth", list(facts.facts) + [Fact("cylindrical", ("s0_o2_f2",), 0.8)])
    labels = [_lab(1, 10, 10, "box"), _lab(2, 50, 20, "cylinder"), _lab(3, 70, 30, "cylinder", partial=True)]
    row = bench.evaluate_frame(scene, facts, frame, labels, None)
    assert (row["cyl_unocc"], row["cyl_read"], row["box_curved"]) == (1, 1, 1)  # the partial cylinder is left out
    f = bench.summarise([dict(row, ms=1.0)], "depth")
    assert f["cylinder_read_frac"] == 1.0 and f["box_curved_frac"] == 1.0
    weak = SceneFacts("s0", "depth", [Fact("cylindrical", ("s0_o2_f2",), 0.6)])
    assert bench.evaluate_frame(scene, weak, frame, labels, None)["cyl_read"] == 0
    assert bench.summarise([dict(row, ms=1.0)], "rgb")["cylinder_read_frac"] is None


def test_bowls_read_as_curved_count_any_curved_face_of_the_object_under_the_pixel():
    scene, facts, frame = _scene()
    labels = [_lab(1, 10, 10, "bowl"), _lab(2, 50, 20, "bowl")]
    row = bench.evaluate_frame(scene, facts, frame, labels, None)
    assert (row["bowls"], row["bowl_curved"]) == (2, 0)
    scene.objects[1].faces[0].surface = "sphere"   # a bowl's inside read as a sphere's
    row = bench.evaluate_frame(scene, facts, frame, labels, None)
    assert (row["bowls"], row["bowl_curved"]) == (2, 1)
    assert bench.summarise([dict(row, ms=1.0)], "depth")["bowl_curved_frac"] == 0.5
    assert bench.summarise([dict(row, ms=1.0)], "rgb")["bowl_curved_frac"] is None


def test_the_compile_clock_hears_jit_work_and_starts_again_at_zero():
    import jax
    import jax.numpy as jnp

    clock = bench.compile_clock()
    assert bench.compile_clock() is clock  # one listener for the process
    clock.start()
    scale = float(np.random.default_rng().uniform(2.0, 3.0))  # a program no earlier test compiled
    jax.jit(lambda x: jnp.sin(x) * scale)(jnp.ones(7)).block_until_ready()
    assert clock.spent > 0.0
    clock.start()
    assert clock.spent == 0.0


def test_the_compile_clock_counts_a_persistent_cache_read_once():
    # JAX times compile_or_get_cached (a compile, or a read of the persistent cache) as one backend-compile event
    # and reports the read again on its own: a frame would lose the read twice (and could fall below zero ms)
    from jax import monitoring

    clock = bench.compile_clock()
    clock.start()
    monitoring.record_event_duration_secs("/jax/core/compile/backend_compile_duration", 0.5)
    monitoring.record_event_duration_secs("/jax/compilation_cache/cache_retrieval_time_sec", 0.4)
    monitoring.record_event_duration_secs("/jax/core/compile/jaxpr_trace_duration", 0.25)
    assert clock.spent == 0.75
    clock.start()


def test_the_profile_lists_lv3d_functions_per_frame_and_names_a_file_not_a_folder(tmp_path, capsys, monkeypatch):
    import cProfile
    import pstats

    from lv3d.perception.depth import creases

    _stub_folders(monkeypatch)
    assert bench.main([str(tmp_path), "--modalities", "depth", "--profile", str(tmp_path)]) == 2
    assert "--profile names a file" in capsys.readouterr().err
    # two frames' worth of one lv3d function, and a call outside lv3d that the table leaves out
    prof = cProfile.Profile()
    prof.enable()
    for _ in range(2):
        creases.h_maxima(np.arange(100, dtype=np.float32).reshape(10, 10), 2.0)
    sorted(range(10))
    prof.disable()
    text = bench.profile_table(pstats.Stats(prof), frames=2)
    lines = text.strip().splitlines()
    assert lines[0].startswith("== profile: per timed frame (2)") and lines[1].split()[-1] == "function"
    rows = lines[2:]
    assert rows and all(any(p.strip("/") in r for p in bench.PROFILED) for r in rows)
    top = next(r for r in rows if "h_maxima" in r)
    assert top.split()[2] == "1.0" and "lv3d/perception/depth/creases.py" in top  # calls per frame, path from the root


def test_several_seeds_also_give_each_seed_s_figures_and_their_spread(monkeypatch):
    none = {k: None for k in bench.KEYS + bench.EXTRA_KEYS}
    figures = {"0": {"depth": {**none, "box_perpendicular_frac": 0.9}, "rgbd": {**none, "box_perpendicular_frac": 0.85}},
               "1": {"depth": {**none, "box_perpendicular_frac": 0.8}, "rgbd": {**none, "box_perpendicular_frac": None}}}
    text = bench.seed_table(figures, ["depth", "rgbd"])
    lines = text.splitlines()
    assert "seed 0" in lines[0] and "seed 1" in lines[0] and "spread" in lines[0]
    assert [ln.split() for ln in lines[1:]] == [["box_perpendicular_frac", "depth", "0.900", "0.800", "0.100"],
                                                ["box_perpendicular_frac", "rgbd", "0.850", "null", "0.000"]]
    assert "ms_median" not in text  # time is not perception's chance
    rows = {"depth": [{"seed": 0, "x": 1}, {"seed": 1, "x": 2}, {"seed": 1, "x": 3}]}
    seen = []
    monkeypatch.setattr(bench, "summarise", lambda rs, m: seen.append([r["x"] for r in rs]) or none)
    assert set(bench.by_seed(rows, (0, 1), ["depth"])) == {"0", "1"} and seen == [[1], [2, 3]]
