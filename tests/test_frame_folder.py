"""Folders of labelled frames (the layout of ../shared/data/real): reading objects.csv, one example per labelled
object, learning from such a folder on the command line and in a study."""

import json

import pytest

from lv3d.cli.app import main
from lv3d.frame_folder import FrameFolder, scene_atom
from lv3d.object_facts import FrameFacts, example_facts, example_id, frame_facts, labelled_facts
from tests.conftest import FOLDER_CLASSES, write_frame_folder

def _with_rows(frames, folder, rows):
    """A copy of the folder ``frames`` at ``folder`` with ``rows`` (objects.csv lines) added to its objects.csv."""
    import shutil

    shutil.copytree(frames, folder)
    with (folder / "objects.csv").open("a") as f:
        f.writelines(f"{row}\n" for row in rows)
    return folder


def test_rows_that_cannot_be_used_are_named_by_file_and_line_and_the_rest_are_read(tmp_path, frames):
    folder = _with_rows(frames, tmp_path / "copy", [
        "frame-000,x,5,5,box,no,no,",       # line 8: not a number
        "nowhere,1,5,5,box,no,no,",          # line 9: no such frame
        "frame-000,2,900,5,box,no,no,",      # line 10: outside the image
        "frame-000,3,5,5,Big Box,no,no,",    # line 11: not a class name
        "frame-000,1,5,5,box,no,no,",        # line 12: labelled twice
    ])
    objects, problems = FrameFolder(folder).objects()
    assert len(objects) == 6
    assert [p.line for p in problems] == [8, 9, 10, 11, 12]
    assert all(str(p).startswith(f"{folder / 'objects.csv'}: line ") for p in problems)
    assert "outside the 320x240 frame" in str(problems[2]) and "twice" in str(problems[4])
    # read strictly (what the real-frame measurements need), the first such row is the error
    from lv3d.errors import InputError

    with pytest.raises(InputError, match=r"objects.csv: line 8: object: expected a whole number"):
        FrameFolder(folder).labels()
    by_frame = FrameFolder(frames).labels(("box", "prism"))
    assert sorted(by_frame) == FrameFolder(frames).frames and all(len(v) == 1 for v in by_frame.values())
    with pytest.raises(InputError, match=r"line 3: shape 'prism' is not one of box"):
        FrameFolder(frames).labels(("box",))


def test_a_folder_not_in_the_layout_is_one_clear_error(tmp_path):
    from lv3d.errors import InputError

    with pytest.raises(InputError, match="no objects.csv"):
        FrameFolder(tmp_path)
    (tmp_path / "objects.csv").write_text("frame,u,v\n")
    (tmp_path / "intrinsics.json").write_text("{}")
    (tmp_path / "a_rgb.png").write_bytes(b"")
    (tmp_path / "a_depth_mm.png").write_bytes(b"")
    with pytest.raises(InputError, match="missing object, shape"):
        FrameFolder(tmp_path).objects()


def test_a_folder_is_known_by_its_content_wherever_it_lies(frames, tmp_path):
    import os
    import shutil

    from lv3d.experiment.real_data import real_data

    copy = tmp_path / "elsewhere" / frames.name
    shutil.copytree(frames, copy)
    for p in copy.iterdir():  # written anew: other times, the same bytes
        os.utime(p, ns=(0, 0))
    key = real_data([frames]).key
    assert real_data([copy]).key == key  # so its cached facts and study results are kept
    depth = sorted(copy.glob("*_depth_mm.png"))[0]
    depth.write_bytes(depth.read_bytes() + b"\0")  # one byte more in one frame: another folder
    assert real_data([copy]).key != key


def test_frame_names_become_distinct_prolog_atoms():
    names = ["learn0", "frame-000000", "frame_000000", "0001", "Frame-000000", "ä"]
    atoms = [scene_atom(n) for n in names]
    assert atoms[0] == "learn0" and len(set(atoms)) == len(atoms)
    assert all(a[0].islower() and a.replace("_", "").isalnum() and a.isascii() for a in atoms)


@pytest.mark.parametrize("modality", ["rgb", "depth", "rgbd"])
def test_each_labelled_object_is_an_example_of_its_own(frames, modality):
    folder = FrameFolder(frames)
    objects, _ = folder.objects()
    lab = objects[0]
    atom = scene_atom(lab.frame)
    ff = frame_facts(folder.load(lab.frame), atom, modality, [(lab.object, lab.u, lab.v), (9, 2, 2)])
    ex = example_facts(ff, lab.object, example_id(atom, lab.object))
    assert ex.target == f"{atom}_x1_o" and ex.scene == f"{atom}_x1"
    assert {f.args[0] for f in ex.facts if f.pred == "face_of"} == {ex.target}
    assert all(a.startswith(ex.target) for f in ex.facts for a in f.args)
    # a label in the image's corner, on no object: an example with no target
    assert ff.under[9] is None and example_facts(ff, 9, example_id(atom, 9)).target is None
    assert json.loads(json.dumps(ff.to_json())) == type(ff).from_json(ff.to_json()).to_json()


@pytest.mark.parametrize("modality", ["depth", "rgbd"])
def test_facts_of_a_frame_already_perceived_are_those_of_perceiving_it(frames, modality):
    from lv3d.perception import perceive

    folder = FrameFolder(frames)
    labs = folder.objects()[0][:2]
    frame, atom = folder.load(labs[0].frame), scene_atom(labs[0].frame)
    labels = [(lab.object, lab.u, lab.v) for lab in labs if lab.frame == labs[0].frame] + [(9, 2, 2)]
    scene = perceive(frame, modality, scene_id=atom)
    before = [o.id for o in scene.objects]
    assert labelled_facts(scene, frame, labels).to_json() == frame_facts(frame, atom, modality, labels).to_json()
    assert [o.id for o in scene.objects] == before  # the scene is left as it was


def test_the_facts_of_real_frames_follow_the_study_depth_settings(frames, tmp_path, monkeypatch):
    """A study's ``lv3d.depth`` reaches perception of each frame, and its facts are cached apart."""
    import lv3d.object_facts as object_facts
    from lv3d.experiment.data import facts_variant
    from lv3d.experiment.real_data import ensure_frame_facts, real_data

    rd = real_data([frames])
    depth = {"max_objects": 1, "sensor.base_m": 0.005}
    given = []
    real = object_facts.frame_facts

    def recording(frame, atom, modality, labels, *, refine=True, seed=0, depth=None):
        given.append(depth)
        return real(frame, atom, modality, labels, refine=refine, seed=seed, depth=depth)

    monkeypatch.setattr(object_facts, "frame_facts", recording)
    got = ensure_frame_facts(rd, tmp_path, "v", "depth", False, depth=depth)
    assert set(got) == set(rd.frames) and given == [depth] * len(rd.frames)
    assert [p.name for p in (tmp_path / rd.key / "v").iterdir()] == [facts_variant("depth", False, 0, depth)]
    assert all(len(ff.facts.objects()) <= 1 for ff in got.values())


def test_learn_fit_predict_and_explain_on_a_folder_of_frames(frames, tmp_path, capsys):
    cache, model = tmp_path / "cache", tmp_path / "model"
    args = ["--data", str(frames), "--modality", "depth", "--cache", str(cache)]
    assert main(["learn", "fit", *args, "--out", str(model), "--time-limit", "20"]) == 0
    out = capsys.readouterr().out
    assert "learned from 6 examples (box 3, prism 3)" in out and "box(A) :-" in out
    assert list(cache.rglob("*.json"))  # the frames' facts are cached: a second command reads them
    assert main(["learn", "predict", *args, "--model", str(model)]) == 0
    out = capsys.readouterr().out
    rows = [line.split("\t") for line in out.splitlines() if "\t" in line]
    assert len(rows) == 6 and out.splitlines()[-1].startswith("accuracy ")
    assert out.splitlines()[-2].startswith("per class: box ")
    per = {c: tuple(map(int, k.split("/"))) for c, k in (p.split() for p in out.splitlines()[-2][len("per class: "):].split(", "))}
    assert f"balanced {sum(r / n for r, n in per.values()) / len(per):.3f}" in out.splitlines()[-1]
    # a model of some of the folder's classes: the others' examples are answered, and left out of its accuracy
    assert main(["learn", "fit", *args, "--classes", "box", "--out", str(tmp_path / "box_only")]) == 0
    capsys.readouterr()
    assert main(["learn", "predict", *args, "--model", str(tmp_path / "box_only")]) == 0
    lines = capsys.readouterr().out.splitlines()
    assert "left out of the accuracy, of classes the model holds no program for: prism 3 (its classes: box)" in lines
    assert lines[-1].startswith("accuracy ") and lines[-1].split()[1].endswith("/3")
    assert all(r[2] == "box" for r in rows if r[1] == "box")  # every box is proved a box
    ex = f"{scene_atom('frame-002')}_x1"
    assert main(["learn", "explain", *args, "--model", str(model), "--example", ex]) == 0
    out = capsys.readouterr().out
    assert out.startswith(f"{ex} (box): {ex}_o is a box") and "because" in out
    # the same example by its frame's file name
    assert main(["learn", "explain", *args, "--model", str(model), "--example", "frame-002_x1"]) == 0
    assert capsys.readouterr().out.startswith(f"{ex} (box): {ex}_o is a box")
    assert main(["learn", "fit", *args, "--facts", "truth", "--out", str(tmp_path / "m2")]) == 2
    assert "no ground-truth facts" in capsys.readouterr().err


def test_learn_takes_depth_settings_keeps_their_facts_apart_and_the_model_remembers_them(frames, tmp_path, capsys):
    """--depth-set reaches perception of every frame (max_objects=1 leaves one object a frame), its facts are
    cached apart from the defaults', the model records them, and predict says when its examples' differ."""
    from lv3d.experiment.data import facts_variant

    cache, model = tmp_path / "cache", tmp_path / "model"
    args = ["--data", str(frames), "--modality", "depth", "--cache", str(cache)]
    depth = {"max_objects": 1, "sensor.base_m": 0.005}
    sets = ["--depth-set", "sensor.base_m=0.005", "--depth-set", "max_objects=1"]
    assert main(["learn", "fit", *args, *sets, "--out", str(model), "--time-limit", "20"]) == 0
    assert "learned from 6 examples" in capsys.readouterr().out
    assert json.loads((model / "depth_settings.json").read_text()) == depth
    variants = {p.name for p in cache.glob("facts/*/*/*")}
    assert variants == {facts_variant("depth", True, 0, depth)} and "-depth" in variants.pop()
    frames_facts = [FrameFacts.from_json(json.loads(p.read_text())) for p in cache.glob("facts/*/*/*/*.json")]
    assert len(frames_facts) == 6 and all(sum(f.pred == "object" for f in ff.facts.facts) == 1 for ff in frames_facts)
    assert main(["learn", "predict", *args, *sets, "--model", str(model)]) == 0
    out = capsys.readouterr()
    assert out.out.splitlines()[-1].startswith("accuracy ") and "note" not in out.err
    assert main(["learn", "predict", *args, "--model", str(model)]) == 0  # the defaults: facts made anew, and said
    err = capsys.readouterr().err
    assert "learned from facts made with the depth settings max_objects=1 sensor.base_m=0.005; these examples' " \
           "are made with the defaults" in err
    assert main(["learn", "explain", *args, "--depth-set", "sensor.nope=1", "--model", str(model)]) == 2
    assert "--depth-set: sensor.nope: unknown setting 'nope'" in capsys.readouterr().err


def test_a_script_reads_the_examples_of_a_folder_learns_and_explains(frames, tmp_path):
    # what lv3d/examples.py's docstring shows a script doing, on a folder with a row on no object and a bad row
    from lv3d.examples import read_examples
    from lv3d.learn import Model

    folder = _with_rows(frames, tmp_path / "copy", ["frame-000,2,2,2,box,no,no,", "frame-000,x,5,5,box,no,no,"])
    ex = read_examples(folder, "depth", cache=tmp_path / "cache")
    lost = f"{scene_atom('frame-000')}_x2"
    assert ex.labels == ["box", "box", "prism", "box", "prism", "box", "prism"] and ex.without_object == 1
    assert [w.example for w in ex.warnings] == [None, lost] and "line 9" in str(ex.warnings[0])
    train = ex.learnable()
    assert len(train.scenes) == 6 and lost not in {s.scene for s in train.scenes}
    model = Model.fit(train.scenes, train.labels, classes=["box"], seed=0)
    scene = train.scenes[0]
    assert model.predict(scene)[0] == "box" and "box" in str(model.explain(scene))
    assert read_examples(folder, "depth", cache=tmp_path / "cache").labels == ex.labels  # from the cache
    from lv3d.errors import InputError

    with pytest.raises(InputError, match="--modality: must be one of rgb, depth, rgbd, got 'rgb-d'"):
        read_examples(folder, "rgb-d")
    with pytest.raises(InputError, match="no ground-truth facts"):
        read_examples(folder, "depth", facts="truth")
    with pytest.raises(InputError, match="not a data set"):
        read_examples(tmp_path, "depth")


def test_explain_warns_of_the_examples_it_is_asked_about_only(frames, tmp_path, capsys):
    # a corner pixel: on no object, an example without one
    folder = _with_rows(frames, tmp_path / "copy", ["frame-000,2,2,2,box,no,no,"])
    args = ["--data", str(folder), "--modality", "depth", "--cache", str(tmp_path / "cache")]
    assert main(["learn", "fit", *args, "--out", str(tmp_path / "model"), "--time-limit", "20"]) == 0
    lost = f"{scene_atom('frame-000')}_x2"
    assert f"example {lost} has no object" in capsys.readouterr().err  # fit names it (and leaves it out)
    asked = f"{scene_atom('frame-002')}_x1"
    assert main(["learn", "explain", *args, "--model", str(tmp_path / "model"), "--example", asked]) == 0
    out, err = capsys.readouterr()
    assert out.startswith(f"{asked} (box): ") and "has no object" not in err
    assert main(["learn", "explain", *args, "--model", str(tmp_path / "model"), "--example", lost]) == 0
    out, err = capsys.readouterr()
    assert f"example {lost} has no object" in err and "perception found no object under its labelled pixel" in out


def test_fit_learns_every_class_but_the_catch_all_other_unless_named(frames, tmp_path, capsys):
    first = (frames / "objects.csv").read_text().splitlines()[1].split(",")
    # frame-000's object, labelled a second time as an object of no named shape
    folder = _with_rows(frames, tmp_path / "copy", [",".join([first[0], "2", *first[2:4], "other", "no", "no", ""])])
    args = ["--data", str(folder), "--modality", "depth", "--cache", str(tmp_path / "cache"), "--time-limit", "20"]
    assert main(["learn", "fit", *args, "--out", str(tmp_path / "m")]) == 0
    out = capsys.readouterr().out
    assert "learned from 7 examples (box 3, other 1, prism 3)" in out and "% other:" not in out and "% box:" in out
    assert main(["learn", "fit", *args, "--classes", "box,other", "--out", str(tmp_path / "m2")]) == 0
    assert "% other:" in capsys.readouterr().out


def test_a_study_on_folders_keeps_each_frame_in_one_fold(frames, tmp_path, capsys, monkeypatch, load_script):
    from lv3d.experiment.config import load_study
    from lv3d.experiment.runner import run_study, study_inputs

    # one ball among them: too few to test in each of 3 folds, so the study learns box and prism and says so
    folder = _with_rows(frames, tmp_path / "frames", ["frame-000,2,5,5,ball,no,no,"])
    config = tmp_path / "real.yaml"
    config.write_text(f"""
name: real_tiny
folds: 3
data: {{folders: [{folder}], classes: [box, prism, ball], cache: {tmp_path / 'cache'}}}
train: {{positives: 1, negatives_per_positive: 1, multiclass: true}}
systems: [lv3d-depth, tree-rgbd]
lv3d: {{settings: {{time_limit: 10}}}}
baselines: {{image_size: 16, tree_cells: 4}}
""")
    out = tmp_path / "run"
    summary = run_study(config, out, progress=False)
    assert summary["ran"] == 6
    tests = [set(json.loads((out / "folds" / "base" / "lv3d-depth" / f"fold{k}.json").read_text())["test_ids"])
             for k in range(3)]
    assert sorted(i for t in tests for i in t) == sorted(f"{scene_atom(f'frame-{i:03d}')}_x1" for i in range(6))
    rec = json.loads((out / "folds" / "base" / "tree-rgbd" / "fold0.json").read_text())
    assert rec["left_out"] == {"unusable_rows": [], "other_classes": {"ball": 1}}
    assert "ball" not in rec["tasks"] and {"box", "prism"} <= set(rec["tasks"])
    assert "objects of ball, a class not labelled in at least folds (3) frames of data.folders: 1." in \
        (out / "results.md").read_text()
    again = run_study(config, out, progress=False)  # resumes: nothing to recompute
    assert again["ran"] == 0 and again["skipped"] == 6
    # perception's code changed and found the same facts and boxes: its facts are computed anew, and both the lv3d
    # results (the same facts) and the baseline's (its crops where they were) are kept
    import lv3d.experiment.code_version as cv

    monkeypatch.setattr(cv, "facts_version", lambda: "refactored")
    again = run_study(config, out, progress=False)
    assert again["ran"] == 0 and list((tmp_path / "cache" / "facts").glob("*/refactored/depth-refine1/*"))
    # the baselines restored from the report (scripts/restore_baselines.py) carry the key the run computes
    restore = load_script("restore_baselines")
    assert restore.restore(config, out / "results.csv", tmp_path / "rerun") == 3
    assert run_study(config, tmp_path / "rerun", progress=False)["ran"] == 3  # the lv3d folds only
    # the warning about the ball, once for the conditions of one study (they share ``warned``)
    warned: set = set()
    for _ in range(2):
        study_inputs(load_study(config).base, out, progress=True, warned=warned)
    assert capsys.readouterr().err.count("'ball' is not labelled in at least folds (3) frames of data.folders: its 1 "
                                         "object (left out)") == 1


def test_a_study_on_folders_needs_two_classes_it_can_test_in_every_fold(frames, tmp_path):
    from lv3d.errors import InputError
    from lv3d.experiment.config import load_study

    config = tmp_path / "real.yaml"
    config.write_text(f"name: real_tiny\nfolds: 3\ndata: {{folders: [{frames}], classes: [box, prism]}}\n")
    study = load_study(config)
    assert study.base.data.classes == ("box", "prism") and study.base.left_out_classes == ()
    assert "left_out_classes" not in study.base.to_dict()  # derived: no key of the YAML form nor of a cache key
    with pytest.raises(InputError, match=r"real.yaml: data.classes: fewer than two of box, ball are labelled in at "
                                         r"least folds \(3\) frames.*the folders hold: box 3 in 3 frame\(s\), prism 3"):
        load_study(config, ["data.classes=[box, ball]"])
    with pytest.raises(InputError, match="fewer than two of box, prism are labelled in at least folds \\(4\\)"):
        load_study(config, ["folds=4"])
    # no classes named: every shape of the folder, the most labelled objects first, but the catch-all "other"
    shapes = ["other"] * 4 + ["cone"] * 4 + ["ball"] * 2
    more = _with_rows(frames, tmp_path / "more", [f"frame-00{i % 6},{10 + i},{10 + i},2,{c},no,no,"
                                                  for i, c in enumerate(shapes)]
                      + [f"frame-005,{30 + i},{30 + i},2,mug,no,no," for i in range(4)])
    # four mugs, all in one frame: a fold grouped by frame would hold them all, so no fold could test them
    study = load_study(config, ["data.classes=null", f"data.folders=[{more}]"])
    assert study.base.data.classes == ("cone", "box", "prism")
    assert study.base.left_out_classes == (("mug", 4), ("ball", 2))
    with pytest.raises(InputError, match="data.classes: give the classes to render"):
        load_study(config, ["data.classes=null", "data.folders=null"])


def test_the_demo_learns_from_labelled_frames_and_explains_a_real_object(tmp_path, monkeypatch, capsys):
    from lv3d.cli import demo

    monkeypatch.setitem(FOLDER_CLASSES, "triangular_prism", "cylinder")  # the demo learns box and cylinder
    folder = write_frame_folder(tmp_path / "frames", [(f"f{i}", cls, 21 + i)
                                                 for i, cls in enumerate(["cube", "triangular_prism"] * 4)])
    got = demo.real_step(folder, tmp_path / "out", seed=0)
    out = capsys.readouterr().out
    assert set(got["answers"]) and all(a[0] in ("box", "cylinder") for a in got["answers"].values())
    assert (tmp_path / "out" / "overlays").is_dir() and got["overlay"].endswith(".png")
    assert "learning box, cylinder (lv3d-rgbd)" in out and "perception found" in out
    assert "Why lv3d-rgbd says the real object" in out


def test_a_study_split_by_folder_learns_from_one_folder_and_tests_on_the_other(frames, tmp_path):
    from lv3d.errors import InputError
    from lv3d.experiment.config import load_study
    from lv3d.experiment.runner import run_study

    other = write_frame_folder(tmp_path / "other", [(f"g{i}", cls, 41 + i) for i, cls in enumerate(["cube", "triangular_prism"] * 2)])
    # a ball in one folder only: no fold could both learn and test it
    other = _with_rows(other, tmp_path / "sensor2", ["g0,2,5,5,ball,no,no,"])
    config = tmp_path / "across.yaml"
    config.write_text(f"""
name: across
data: {{folders: [{frames}, {other}], split: folders, classes: null, cache: {tmp_path / 'cache'}}}
train: {{positives: 2, negatives_per_positive: 1, multiclass: true}}
systems: [lv3d-depth, tree-rgbd]
lv3d: {{settings: {{time_limit: 10}}}}
baselines: {{image_size: 16, tree_cells: 4}}
""")
    study = load_study(config)
    assert study.base.folds == 2 and study.base.data.classes == ("box", "prism")
    assert study.base.left_out_classes == (("ball", 1),)
    out = tmp_path / "run"
    assert run_study(config, out, progress=False)["ran"] == 4
    tests = [json.loads((out / "folds" / "base" / "lv3d-depth" / f"fold{k}.json").read_text())["test_ids"]
             for k in range(2)]
    assert sorted(tests[0]) == sorted(f"{scene_atom(f'frame-{i:03d}')}_x1" for i in range(6))
    assert sorted(tests[1]) == sorted(f"{scene_atom(f'g{i}')}_x1" for i in range(4))
    report = (out / "results.md").read_text()
    assert "Each folder a test fold" in report and "| system | frames | sensor2 |" in report
    assert "objects of ball, a class not labelled in every folder of data.folders: 1." in report
    # the same folders split by frame are another study: its fold results are not these
    from lv3d.experiment.runner import result_key

    by_frames = load_study(config, ["data.split=frames", "folds=2"]).base
    assert result_key(study.base, "lv3d-depth", 0, "f") != result_key(by_frames, "lv3d-depth", 0, "f")
    with pytest.raises(InputError, match="data.split: folders .* needs data.folders of two folders or more, got 1"):
        load_study(config, [f"data.folders=[{frames}]"])
    with pytest.raises(InputError, match="data.split: folders .* got 0"):
        load_study(config, ["data.folders=null", "data.classes=[cube, triangular_prism]"])


def test_fit_reads_several_folders_together_and_tells_their_frames_apart(frames, tmp_path, capsys):
    # the same frames again in a folder of another name: two frames of one name, told apart by their folders
    import shutil

    again = shutil.copytree(frames, tmp_path / "session2")
    args = ["--data", str(frames), "--data", str(again), "--modality", "depth", "--cache", str(tmp_path / "cache")]
    assert main(["learn", "fit", *args, "--out", str(tmp_path / "model"), "--time-limit", "20"]) == 0
    assert "learned from 12 examples (box 6, prism 6)" in capsys.readouterr().out
    assert main(["learn", "explain", *args, "--model", str(tmp_path / "model"), "--example", "session2_frame-002_x1"]) == 0
    assert " is a box" in capsys.readouterr().out
    assert main(["learn", "fit", "--data", str(frames), "--data", str(tmp_path), "--out", str(tmp_path / "m2")]) == 2
    assert "several --data must all be such folders" in capsys.readouterr().err
