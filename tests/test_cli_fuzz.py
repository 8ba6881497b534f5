"""Every command of the CLI, driven with bad input: each answer is exit code 2 and one line on stderr, no
traceback, and nothing in the folder around it is made, changed or removed (--out included)."""

import json
import struct
import zlib

import cv2
import numpy as np
import pytest

from lv3d.cli import main


def _png_header(width: int, height: int) -> bytes:
    """A PNG that declares width x height pixels and holds none: only a reader that decodes would notice."""
    ihdr = struct.pack(">IIBBBBB", width, height, 8, 2, 0, 0, 0)
    chunk = lambda kind, data: (struct.pack(">I", len(data)) + kind + data  # noqa: E731
                                + struct.pack(">I", zlib.crc32(kind + data) & 0xFFFFFFFF))
    return b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", ihdr) + chunk(b"IEND", b"")


K = {"fx": 60, "fy": 60, "cx": 32, "cy": 24, "width": 64, "height": 48}


@pytest.fixture(scope="module")
def box(tmp_path_factory):
    """A sandbox: a frame, intrinsics (good and bad), a tiny data set with truth, a model, configs."""
    root = tmp_path_factory.mktemp("fuzz")
    cv2.imwrite(str(root / "c.png"), np.full((48, 64, 3), 128, np.uint8))
    cv2.imwrite(str(root / "d.png"), np.full((48, 64), 900, np.uint16))
    (root / "huge.png").write_bytes(_png_header(8000, 8000))
    (root / "junk.png").write_bytes(b"not an image")
    (root / "k.json").write_text(json.dumps(K))
    for name, k in {"k_scale.json": {**K, "depth_scale_m": "x"}, "k_frames.json": {"width": 64, "height": 48,
                    "frames": [K]}, "k_width.json": {**K, "width": 640.7}, "k_nan.json": {**K, "fx": "60"}}.items():
        (root / name).write_text(json.dumps(k))
    (root / "k_bad.json").write_text("{not json")
    (root / "frames").mkdir()  # a folder of frames in the real layout
    cv2.imwrite(str(root / "frames" / "f1_rgb.png"), np.full((48, 64, 3), 128, np.uint8))
    cv2.imwrite(str(root / "frames" / "f1_depth_mm.png"), np.full((48, 64), 900, np.uint16))
    (root / "frames" / "intrinsics.json").write_text(json.dumps(K))
    (root / "file.txt").write_text("a file of the user's")
    data = root / "data"
    from lv3d.render.dataset import make_dataset

    make_dataset(data, ["cube", "square_pyramid"], 2, "clean", 0, workers=1, width=64, height=48, progress=False)
    for name, manifest in {"m_junk": "{oops", "m_items": '{"items": 3}', "m_item": '{"items": [{"id": "s0"}]}',
                           "m_escape": '{"items": [{"id": "s0", "class": "cube", "dir": "../../etc"}]}'}.items():
        (root / name).mkdir()
        (root / name / "manifest.json").write_text(manifest)
    from lv3d.learn.program import Program

    model = root / "model_rgbd"
    model.mkdir()
    Program("cube", ("cube(A) :- face_of(A, B), square(B).",), {}, "rgbd").save(model / "cube.pl")
    (model / "model.json").write_text(json.dumps({"classes": ["cube"], "settings": {}, "scores": {}}))
    (root / "task.pl").write_text("this is not prolog (\n")
    good = "data: {classes: [cube, square_pyramid], per_class: 6}\nfolds: 2\n"
    (root / "study.yaml").write_text(good)
    for i, bad in enumerate(BAD_CONFIGS):
        (root / f"bad{i}.yaml").write_text(good + bad + "\n")
    (root / "syntax.yaml").write_text("data: [unclosed\n")
    (root / "list.yaml").write_text("- a\n- b\n")
    return root


BAD_CONFIGS = [
    "lv3d: {settings: {time_limit: -5}}", "lv3d: {settings: {metarules: [part, no_such_rule]}}",
    "lv3d: {settings: {label_noise: false}}", "train: {multiclass: 'no'}",
    "data: {classes: [cube, square_pyramid], per_class: 6, noise_overrides: {depth_sigma_k: -1}}",
    "baselines: {epochs: -1}", "baselines: {threads: -4}", "baselines: {tree_cells: 0}", "baselines: {batch_size: 0}",
    "baselines: {image_size: 0}", "lv3d: {refine: maybe}", "baselines: {lr: fast}", "seed: -3", "systems: [svm]",
    "stats: {pairs: [[lv3d-rgb]]}", "sweep: {param: train.positives, values: [1, -1]}",
    "conditions: {'../up': {}}", "lv3d: {workers: 0}", "train: {draws: 0}", "name: 5",
]
BAD_CONFIGS[4] = "data: {noise_overrides: {depth_sigma_k: -1}}"

# each case: the arguments, with {box} for the sandbox; "{out}" names a folder that must not appear
CASES = [
    # extract: --out that is not lv3d's, inputs that are not images, sizes, intrinsics, options
    "extract {box}/c.png --depth {box}/d.png --intrinsics {box}/k.json --out .",
    "extract {box}/c.png --depth {box}/d.png --intrinsics {box}/k.json --out ..",
    "extract {box}/c.png --depth {box}/d.png --intrinsics {box}/k.json --out {box}",
    "extract {box}/c.png --depth {box}/d.png --intrinsics {box}/k.json --out {box}/file.txt",
    "extract {box}/nope.png --modality rgb --out {out}",
    "extract {box}/junk.png --modality rgb --out {out}",
    "extract {box}/huge.png --modality rgb --out {out}",
    "extract {box}/c.png --depth {box}/huge.png --intrinsics {box}/k.json --out {out}",
    "extract {box}/c.png --depth {box}/d.png --intrinsics {box}/k_scale.json --out {out}",
    "extract {box}/c.png --depth {box}/d.png --intrinsics {box}/k_frames.json --out {out}",
    "extract {box}/c.png --depth {box}/d.png --intrinsics {box}/k_width.json --out {out}",
    "extract {box}/c.png --depth {box}/d.png --intrinsics {box}/k_nan.json --out {out}",
    "extract {box}/c.png --depth {box}/d.png --intrinsics {box}/k_bad.json --out {out}",
    "extract {box}/c.png --depth {box}/d.png --intrinsics {box}/k.json --depth-scale -1 --out {out}",
    "extract {box}/c.png --depth {box}/d.png --intrinsics {box}/k.json --depth-scale 5 --out {out}",
    "extract {box}/c.png --depth {box}/d.png --intrinsics {box}/k.json --scene-id Bad-Id --out {out}",
    "extract {box}/c.png --depth {box}/d.png --intrinsics {box}/k.json --max-objects 0 --out {out}",
    "extract {box}/c.png --modality infrared --out {out}",
    "extract {box}/c.png --out {out}",
    "extract --out {out}",
    # dataset make and show
    "dataset make --classes cube --per-class 1 --width 16384 --height 16384 --out {out}",
    "dataset make --classes cube --per-class 0 --out {out}",
    "dataset make --classes cube --per-class 100000000 --out {out}",
    "dataset make --classes cube,cuboid,square_pyramid --per-class 9000 --out {out}",
    "dataset make --classes cube,blob --per-class 1 --out {out}",
    "dataset make --classes , --per-class 1 --out {out}",
    "dataset make --classes cube --per-class 1 --noise fog --out {out}",
    "dataset make --classes cube --per-class 1 --workers 0 --out {out}",
    "dataset make --classes cube --per-class 1 --seed -1 --out {out}",
    "dataset make --classes cube --per-class 1 --width 0 --out {out}",
    "dataset make --classes cube --per-class 1 --out {box}/file.txt",
    "dataset make --classes cube --per-class x --out {out}",
    "dataset show {box}/data --max-items 0",
    "dataset show {box}/data --max-items -3",
    "dataset show {box}/data --out {box}",
    "dataset show {box}/m_junk",
    "dataset show {box}/m_items",
    "dataset show {box}/m_item",
    "dataset show {box}/m_escape",
    "dataset show {box}/nope",
    "dataset show {box}/file.txt",
    # mil and learn
    "mil {box}/nope.pl",
    "mil {box}/task.pl",
    "mil {box}/file.txt",
    "mil {box}/task.pl --time-limit -1",
    "learn fit --data {box}/data --out {out} --time-limit -1",
    "learn fit --data {box}/data --out {out} --time-limit 0",
    "learn fit --data {box}/data --out {out} --seed -1",
    "learn fit --data {box}/data --out {out} --classes dodecahedron",
    "learn fit --data {box}/data --out {out} --classes ,",
    "learn fit --data {box}/data --out {out} --modality sonar",
    "learn fit --data {box}/data --out {out} --facts guess",
    "learn fit --data {box}/nope --out {out}",
    "learn fit --data {box}/m_junk --out {out}",
    "learn fit --data {box}/m_item --out {out}",
    "learn fit --data {box}/data --out {box}/data",
    "learn fit --data {box}/data --out .",
    "learn fit --data {box}/data --out {box}/file.txt",
    "learn predict --data {box}/data --model {box}/nope",
    "learn predict --data {box}/data --model {box}/data",
    "learn predict --data {box}/data --model {box}/model_rgbd --modality rgb",
    "learn predict --data {box}/m_items --model {box}/model_rgbd",
    # experiment run
    *[f"experiment run {{box}}/bad{i}.yaml --out {{out}}" for i in range(len(BAD_CONFIGS))],
    "experiment run {box}/nope.yaml --out {out}",
    # experiment report
    "experiment report {box}/nope.yaml --out {out}",
    "experiment report {box}/syntax.yaml --out {out}",
    "experiment report {box}/study.yaml --out {out}",
    "experiment report {box}/study.yaml --out {box} --set nonsense",
    "experiment run {box}/syntax.yaml --out {out}",
    "experiment run {box}/list.yaml --out {out}",
    "experiment run {box}/study.yaml --out {out} --set nonsense",
    "experiment run {box}/study.yaml --out {out} --set train.nope=1",
    "experiment run {box}/study.yaml --out {out} --set train.positives=[1",
    "experiment run {box}/study.yaml --out {out} --set lv3d.settings.time_limit=-1",
    "experiment run {box}/study.yaml --out {out} --set data.per_class=1e8",
    "experiment run {box}/study.yaml --out {out} --executor spark",
    "experiment run {box}/study.yaml --out {out} --address tcp://127.0.0.1:1",
    "experiment run {box}/study.yaml --out {out} --workers 0",
    "experiment run {box}/study.yaml --out {box}/file.txt",
    "experiment run {box}/study.yaml --out {box}",
    "experiment run {box}/study.yaml",
    # calibrate: pickles that are missing or not lv3d's, files it did not write, options
    "calibrate rows --per-class 1 --out {box}/file.txt",
    "calibrate rows --per-class 1 --fresh --out {box}/file.txt",
    "calibrate rows --per-class 1 --out {box}",
    "calibrate rows --per-class 0 --out {out}",
    "calibrate rows --seed 0 --out {out}",
    "calibrate rows --per-class 1 --preset fog --out {out}",
    "calibrate rows --per-class 1 --modalities sonar --out {out}",
    "calibrate rows --per-class 1",
    "calibrate real {box}/nope --out {out}",
    "calibrate real {box}/data --out {out}",
    "calibrate real {box}/data --limit 0 --out {out}",
    "calibrate real {box}/data --modalities rgb --out {out}",
    "calibrate fit {box}/nope.pkl --out {out}",
    "calibrate fit {box}/file.txt --out {out}",
    "calibrate fit {box}/file.txt --dry-run",
    "calibrate fit {box}/nope.pkl --real-share 2 --out {out}",
    "calibrate fit {box}/nope.pkl --modalities rgb --out {out}",
    "calibrate check {box}/nope.pkl",
    "calibrate check {box}/file.txt",
    "calibrate check {box}/file.txt --draws 0",
    "calibrate check {box}/file.txt --modality rgb",
    "calibrate check",
    # label: a folder not in the layout, an --out it must not write, options
    "label {box}/nope --out {out}",
    "label {box}/data --out {out}",
    "label {box}/file.txt --out {out}",
    "label {box}/frames --out {box}/frames",
    "label {box}/frames --out {box}/file.txt",
    "label {box}/frames --out {box}",
    "label {box}/frames --seed -1 --out {out}",
    "label {box}/frames --max-objects 0 --out {out}",
    "label {box}/frames",
    # demo and the top level
    "demo --out {out} --per-class 0",
    "demo --out {out} --train 0",
    "demo --out {out} --train 9",
    "demo --out {out} --systems lv3d-rgb,svm",
    "demo --out {out} --noise fog",
    "demo --out {out} --threads 0",
    "demo --out {out} --seed -1",
    "demo --out {box}/file.txt",
    "no-such-command",
    "dataset make --no-such-option",
]


def _snapshot(folder):
    return {p.relative_to(folder).as_posix(): (p.stat().st_mtime_ns, p.read_bytes() if p.is_file() else None)
            for p in sorted(folder.rglob("*"))}


@pytest.mark.parametrize("case", CASES)
def test_bad_input_is_exit_2_one_line_and_touches_nothing(box, case, capsys, monkeypatch):
    monkeypatch.chdir(box / "data")
    before = _snapshot(box.parent)
    args = [a.format(box=box, out=box / "new_out") for a in case.split()]
    rc = main(args)
    err = capsys.readouterr().err.strip()
    assert rc == 2, (case, rc, err)
    assert len(err.splitlines()) == 1 and err.startswith("lv3d: error: ") and "Traceback" not in err, (case, err)
    assert _snapshot(box.parent) == before, case
    assert not (box / "new_out").exists()
