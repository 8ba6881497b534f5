"""Labelled ``perpendicular`` candidates of real RGB-D frames: fit and check data for the confidence calibration
(benchmarks/fit_calibration.py), with what bench_real.py's box and calibration figures need to be recomputed
for any set of calibration maps without perceiving the frames again.

    .venv/bin/python -m benchmarks.calibration_real ../shared/data/real/osd-learn --out out/calib/real_osd-learn.pkl
    .venv/bin/python -m benchmarks.calibration_real ../shared/data/real/ycb-realsense --out out/calib/real_ycb-realsense.pkl

Each folder is in the layout of ../shared/data/real/README.md. Every frame is perceived
(lv3d.perception.perceive) and grounded (lv3d.describe.ground, raw probabilities) once per modality, as
bench_real.py does, and the labelled objects are matched to perceived objects by bench_real's own functions.
Truth, as bench_real.py's ``perpendicular_ece`` defines it: a pair of adjacent faces of the perceived object of a
labelled box is perpendicular, one of a labelled cylinder or bowl is not; a perceived object that holds another
labelled object (merged) or no box, cylinder or bowl has no truth. Each candidate (both argument orders, as
facts are emitted) of a pair with truth is one fit row: the fields benchmarks/calibration_data.py gives rendered
rows (``modality``, ``pred``, ``p``, ``y``, ``value`` and the measurements of lv3d.describe.calibration_features)
plus ``scene`` (folder/frame: the unit that cross-validation keeps together) and ``source`` ("real:<folder>").

The pickle: ``{"rows": [...], "frames": [...], "folders": [...], "made_by": command line}``; a frame entry holds,
per modality, the ``perpendicular`` candidates of every adjacent pair of the perceived objects that bench_real's
figures read and which labelled boxes (unoccluded), cylinders and bowls each object is, so that :func:`figures`
gives ``box_perpendicular_frac``, ``cylinder_as_prism_frac`` and ``perpendicular_ece`` for any calibration.
"""

from __future__ import annotations

import argparse
import pickle
import sys
import time
from pathlib import Path

import numpy as np

from benchmarks import bench_real as br
from benchmarks.calibration_error import ece

MODALITIES = ("depth", "rgbd")  # the modalities that see planes, so that say `perpendicular` at all
PRED = "perpendicular"


def frame_entry(scene, frame, labels: list, label_img, folder: str, name: str) -> dict:
    """What one perceived frame of one modality gives: its labelled ``perpendicular`` candidates and the
    structure :func:`figures` reads (see the module's docstring)."""
    from lv3d.describe import calibration_features, calibration_keys, ground

    cands, results = ground(scene, frame, refine=True, calibrate=False)
    shape = frame.depth.shape
    covers = [br.face_cover(o, shape) for o in scene.objects]
    masks = [c > 0 for c in covers]
    held = [br.held_object(covers, lab.u, lab.v) for lab in labels]
    regions = [br.region_pixels(lab, label_img) for lab in labels]
    merged = br.merged_flags(held, masks, regions)
    # truth per perceived object, as bench_real.evaluate_frame gives it
    truth: dict[int, set[bool]] = {}
    for lab, k, mg in zip(labels, held, merged):
        if k is not None and not mg and (lab.shape == "box" or lab.shape in br.ROUND):
            truth.setdefault(k, set()).add(lab.shape == "box")
    truth_of = {k: next(iter(ys)) for k, ys in truth.items() if len(ys) == 1}
    boxes = [k for lab, k in zip(labels, held) if lab.shape == "box" and not lab.partial]
    rounds = [k for lab, k in zip(labels, held) if lab.shape in br.ROUND]
    wanted = {k for k in (*boxes, *rounds, *truth_of) if k is not None}
    # each wanted object's adjacent pairs, each once (bench_real.pair_confidences' order)
    pairs: dict[int, list[tuple[str, str]]] = {}
    for k in sorted(wanted):
        seen: set[frozenset] = set()
        pairs[k] = []
        for a, b in scene.objects[k].adjacency:
            if a != b and frozenset((a, b)) not in seen:
                seen.add(frozenset((a, b)))
                pairs[k].append((a, b))
    face_obj = {f.id: k for k in wanted for f in scene.objects[k].faces}
    perp = [c for c in cands if c[0] == PRED and c[2] > 0 and face_obj.get(c[1][0]) is not None
            and face_obj.get(c[1][0]) == face_obj.get(c[1][1])]
    adjacent = {k: {frozenset(p) for p in ps} for k, ps in pairs.items()}
    perp = [c for c in perp if frozenset(c[1]) in adjacent[face_obj[c[1][0]]]]
    keys = calibration_keys(perp, results)
    feats = calibration_features(perp, results)
    cand_rows = []
    for (pred, args, p, value), key, f in zip(perp, keys, feats):
        k = face_obj[args[0]]
        row = {"modality": scene.modality, "pred": pred, "key": key, "p": float(p), "args": tuple(args), "obj": k,
               "scene": f"{folder}/{name}", "source": f"real:{folder}", **f, "value": value}
        if k in truth_of:
            row["y"] = bool(truth_of[k])
        cand_rows.append(row)
    return {"folder": folder, "frame": name, "modality": scene.modality, "cands": cand_rows,
            "pairs": {k: [tuple(p) for p in ps] for k, ps in pairs.items()}, "truth": truth_of,
            "boxes": boxes, "rounds": rounds}


def collect(folder: Path, modalities: list[str], limit: int | None = None) -> list[dict]:
    """:func:`frame_entry` of every frame (the first ``limit``) of a real-layout folder, per modality."""
    from lv3d.perception import perceive
    from lv3d.rgbd import load_real

    br.check_folder(folder)
    labels = br.read_labels(folder / "objects.csv")
    frames = br.folder_frames(folder)
    out = []
    for i, name in enumerate(frames[:limit] if limit else frames):
        frame = load_real(folder, name)
        label_img = br.read_label_image(folder / f"{name}_label.png", frame.shape)
        for m in modalities:
            scene = perceive(frame, m, scene_id=f"s{i:06d}")  # the scene id bench_real gives the frame
            out.append(frame_entry(scene, frame, labels.get(name, []), label_img, folder.name, name))
    return out


def rows_of(frames: list[dict]) -> list[dict]:
    """The fit rows of frame entries: the candidates with a truth."""
    return [r for f in frames for r in f["cands"] if "y" in r]


def figures(frames: list[dict], conf) -> dict[str, dict]:
    """bench_real.py's ``box_perpendicular_frac``, ``cylinder_as_prism_frac`` and ``perpendicular_ece`` (and the
    number of calibration pairs, ``pairs``) per modality of frame entries, with each candidate's confidence
    ``conf(row)`` (a calibrated probability; facts below lv3d.describe.MIN_CONF are absent, as describe drops
    them)."""
    from lv3d.describe import MIN_CONF

    out: dict[str, dict] = {}
    by_mod: dict[str, list[dict]] = {}
    for f in frames:
        by_mod.setdefault(f["modality"], []).append(f)
    for m, fs in sorted(by_mod.items()):
        box_ok = boxes = round_prism = rounds = 0
        ps, ys = [], []
        for f in fs:
            perp = {}
            for r in f["cands"]:
                c = min(float(conf(r)), 1.0)
                if c >= MIN_CONF:
                    perp[r["args"]] = c
            pair_conf = {k: [max(perp.get((a, b), 0.0), perp.get((b, a), 0.0)) for a, b in ps_k]
                         for k, ps_k in f["pairs"].items()}
            boxes += len(f["boxes"])
            box_ok += sum(k is not None and any(c >= br.BOX_PERP for c in pair_conf[k]) for k in f["boxes"])
            rounds += len(f["rounds"])
            round_prism += sum(k is not None and any(c >= br.PRISM_PERP for c in pair_conf[k]) for k in f["rounds"])
            for k, y in sorted(f["truth"].items()):
                ps += pair_conf[k]
                ys += [float(y)] * len(pair_conf[k])
        out[m] = {"box_perpendicular_frac": box_ok / boxes if boxes else None,
                  "cylinder_as_prism_frac": round_prism / rounds if rounds else None,
                  "perpendicular_ece": ece(np.array(ps), np.array(ys)) if ps else None, "pairs": len(ps)}
    return out


def load(path: Path) -> dict:
    """A pickle of this script, or a one-line error naming the file."""
    try:
        data = pickle.loads(Path(path).read_bytes())
        if not isinstance(data, dict) or "frames" not in data:
            raise KeyError("frames")
    except (OSError, pickle.UnpicklingError, KeyError, EOFError) as e:
        raise SystemExit(f"{path}: not a calibration_real.py pickle ({e!r})") from None
    return data


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("folders", nargs="+", type=Path, help="folders in the real layout (with objects.csv)")
    ap.add_argument("--modalities", default=",".join(MODALITIES))
    ap.add_argument("--limit", type=int, metavar="N", help="only the first N frames of each folder")
    ap.add_argument("--out", type=Path, required=True)
    a = ap.parse_args(argv)
    mods = a.modalities.split(",")
    if not set(mods) <= set(MODALITIES):
        ap.error(f"--modalities: choose from {', '.join(MODALITIES)}")
    import grounding

    grounding.enable_cache()
    t0 = time.time()
    frames = []
    for folder in a.folders:
        try:
            frames += collect(folder, mods, a.limit)
        except br.InputError as e:
            print(f"calibration_real.py: error: {e}", file=sys.stderr)
            return 2
        print(f"{folder.name}: {len(frames)} frame entries, {len(rows_of(frames))} rows, {time.time() - t0:.0f} s",
              flush=True)
    a.out.parent.mkdir(parents=True, exist_ok=True)
    a.out.write_bytes(pickle.dumps({"rows": rows_of(frames), "frames": frames,
                                    "folders": [f.name for f in a.folders],
                                    "made_by": " ".join(["python -m benchmarks.calibration_real", *(argv or sys.argv[1:])])}))
    return 0


if __name__ == "__main__":
    sys.exit(main())
