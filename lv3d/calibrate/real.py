"""Labelled ``perpendicular`` candidates of real RGB-D frames: fit and check data for the confidence calibration
(lv3d.calibrate.fit), with what benchmarks/bench_real.py's box and calibration figures need to be recomputed
for any set of calibration maps without perceiving the frames again.

    lv3d calibrate real ../shared/data/real/osd-learn --out out/calib/real_osd-learn.pkl
    lv3d calibrate real ../shared/data/real/ycb-realsense --out out/calib/real_ycb-realsense.pkl

Each folder is in the real layout (docs/real_frames.md) with every row of objects.csv usable and of a shape in
``SHAPES`` (lv3d.frame_folder.FrameFolder.labels). Every frame is perceived (lv3d.perception.perceive) and
grounded (lv3d.describe.ground, raw probabilities) once per modality, as bench_real does, and each labelled
object is matched to the perceived object holding its pixel as bench_real matches it (lv3d.object_facts:
face_cover, held_object, merged_flags). Truth, as bench_real's ``perpendicular_ece`` defines it
(:func:`perpendicular_truth`): a pair of adjacent faces of the perceived object of a labelled box is
perpendicular, one of a labelled cylinder or bowl (``ROUND``) is not; a perceived object that holds another
labelled object (merged) or no box, cylinder or bowl has no truth. Each candidate (both argument orders, as facts
are emitted) of a pair with truth is one fit row: the fields lv3d.calibrate.rows gives rendered rows
(``modality``, ``pred``, ``p``, ``y``, ``value`` and the measurements of lv3d.describe.calibration_features) plus
``scene`` (folder/frame: the unit that cross-validation keeps together) and ``source`` ("real:<folder>").

The pickle: ``{"rows": [...], "frames": [...], "folders": [...], "made_by": command line}``; a frame entry holds,
per modality, the ``perpendicular`` candidates of every adjacent pair of the perceived objects that bench_real's
figures read and which labelled boxes (unoccluded), cylinders and bowls each object is, so that :func:`figures`
gives ``box_perpendicular_frac``, ``cylinder_as_prism_frac`` and ``perpendicular_ece`` for any calibration.
"""

from __future__ import annotations

import pickle
import time
from pathlib import Path

import numpy as np

from ..errors import InputError, read_pickle
from ..frame_folder import FrameFolder
from ..object_facts import face_cover, held_object, merged_flags, region_pixels
from ..output import write_atomic
from .measures import ece

MODALITIES = ("depth", "rgbd")  # the modalities that see planes, so that say `perpendicular` at all
PRED = "perpendicular"
SHAPES = ("box", "cylinder", "bowl", "sphere", "other")  # the shapes objects.csv may name (../shared/data/real)
ROUND = ("cylinder", "bowl")  # labelled shapes whose adjacent faces are not perpendicular
BOX_PERP = 0.7    # box_perpendicular: an adjacent pair at perpendicular confidence >= this
PRISM_PERP = 0.5  # cylinder_as_prism: an adjacent pair at perpendicular confidence >= this


def perpendicular_truth(labels: list, held: list[int | None], merged: list[bool]) -> dict[int, bool]:
    """{perceived object: whether its adjacent faces are perpendicular} from the labelled objects it holds
    (``held``, ``merged`` per label, lv3d.object_facts): True for a box, False for a cylinder or bowl; an object
    that is merged, or holds labels of both kinds, has no truth."""
    truth: dict[int, set[bool]] = {}
    for lab, k, mg in zip(labels, held, merged):
        if k is not None and not mg and (lab.shape == "box" or lab.shape in ROUND):
            truth.setdefault(k, set()).add(lab.shape == "box")
    return {k: next(iter(ys)) for k, ys in truth.items() if len(ys) == 1}


def frame_entry(scene, frame, labels: list, label_img, folder: str, name: str) -> dict:
    """What one perceived frame of one modality gives: its labelled ``perpendicular`` candidates and the
    structure :func:`figures` reads (see the module's docstring)."""
    from ..describe import calibration_features, calibration_keys, ground

    cands, results = ground(scene, frame, refine=True, calibrate=False)
    shape = frame.depth.shape
    covers = [face_cover(o, shape) for o in scene.objects]
    masks = [c > 0 for c in covers]
    held = [held_object(covers, lab.u, lab.v) for lab in labels]
    regions = [region_pixels(lab, label_img) for lab in labels]
    truth_of = perpendicular_truth(labels, held, merged_flags(held, masks, regions))
    boxes = [k for lab, k in zip(labels, held) if lab.shape == "box" and not lab.partial]
    rounds = [k for lab, k in zip(labels, held) if lab.shape in ROUND]
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


def collect(folder: Path, modalities: list[str], limit: int | None = None, seeds: tuple[int, ...] = (0,)
            ) -> list[dict]:
    """:func:`frame_entry` of every frame (the first ``limit``) of a real-layout folder, per modality and per
    perception seed of ``seeds`` (perceive's; each entry records its ``seed``). A frame's entries of every seed
    name the same frame, so that frame-grouped folds keep them together."""
    from ..perception import perceive

    ff = FrameFolder(folder)
    labels = ff.labels(SHAPES)
    frames = ff.frames
    out = []
    for i, name in enumerate(frames[:limit] if limit else frames):
        frame = ff.load(name)
        label_img = ff.label_image(name, frame.shape)
        for seed in seeds:
            for m in modalities:
                scene = perceive(frame, m, scene_id=f"s{i:06d}", seed=seed)  # the scene id bench_real gives it
                entry = frame_entry(scene, frame, labels.get(name, []), label_img, ff.name, name)
                out.append({**entry, "seed": seed})
    return out


def rows_of(frames: list[dict]) -> list[dict]:
    """The fit rows of frame entries: the candidates with a truth."""
    return [r for f in frames for r in f["cands"] if "y" in r]


def figures(frames: list[dict], conf) -> dict[str, dict]:
    """bench_real's ``box_perpendicular_frac``, ``cylinder_as_prism_frac`` and ``perpendicular_ece`` (and the
    number of calibration pairs, ``pairs``) per modality of frame entries, with each candidate's confidence
    ``conf(row)`` (a calibrated probability; facts below lv3d.describe.MIN_CONF are absent, as describe drops
    them)."""
    from ..describe import MIN_CONF

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
            box_ok += sum(k is not None and any(c >= BOX_PERP for c in pair_conf[k]) for k in f["boxes"])
            rounds += len(f["rounds"])
            round_prism += sum(k is not None and any(c >= PRISM_PERP for c in pair_conf[k]) for k in f["rounds"])
            for k, y in sorted(f["truth"].items()):
                ps += pair_conf[k]
                ys += [float(y)] * len(pair_conf[k])
        out[m] = {"box_perpendicular_frac": box_ok / boxes if boxes else None,
                  "cylinder_as_prism_frac": round_prism / rounds if rounds else None,
                  "perpendicular_ece": ece(np.array(ps), np.array(ys)) if ps else None, "pairs": len(ps)}
    return out


def checked_seeds(seeds) -> tuple[int, ...]:
    """Perception seeds (perceive's) as a tuple: at least one, each 0 or more, none twice; else an InputError
    naming ``--seed``."""
    seeds = tuple(seeds)
    if not seeds or any(x < 0 for x in seeds) or len(set(seeds)) != len(seeds):
        raise InputError("--seed", f"seeds are distinct and 0 or more, not {','.join(map(str, seeds))!r}")
    return seeds


def seed_list(text: str) -> tuple[int, ...]:
    """The perception seeds of an option's text, ``0`` or ``0,1,2`` (:func:`checked_seeds`); an InputError naming
    ``--seed`` otherwise."""
    try:
        seeds = tuple(int(x) for x in text.split(","))
    except ValueError:
        raise InputError("--seed", f"seeds are whole numbers, comma-separated (0 or 0,1,2), not {text!r}") from None
    return checked_seeds(seeds)


def read(path: Path) -> dict:
    """A pickle of :func:`make`, or a one-line InputError naming the file."""
    return read_pickle(path, "lv3d calibrate real", ("rows", "frames"))


def make(folders: list[Path], out: Path, modalities: tuple[str, ...] = MODALITIES, limit: int | None = None,
         command: str = "", log=print, seeds: tuple[int, ...] = (0,)) -> dict:
    """The frame entries of every frame (the first ``limit`` of each folder) of ``folders``, once per perception
    seed of ``seeds``, written to the pickle ``out`` once all are done (``out`` must be absent or a pickle of
    this function). Every folder is checked before any work."""
    bad = [m for m in modalities if m not in MODALITIES]
    if bad or not modalities:
        raise InputError("--modalities", f"choose among {', '.join(MODALITIES)}, not {','.join(modalities)!r}")
    if limit is not None and limit < 1:
        raise InputError("--limit", f"must be at least 1, not {limit}")
    seeds = checked_seeds(seeds)
    out = Path(out)
    if out.is_dir():
        raise InputError(out, "is a folder; --out names a file")
    if out.exists():
        read(out)  # a file this command did not write is refused, never replaced
    for folder in folders:
        FrameFolder(folder).labels(SHAPES)
    t0 = time.time()
    frames: list[dict] = []
    for folder in folders:
        frames += collect(Path(folder), list(modalities), limit, seeds)
        log(f"{Path(folder).name}: {len(frames)} frame entries, {len(rows_of(frames))} rows, {time.time() - t0:.0f} s")
    data = {"rows": rows_of(frames), "frames": frames, "folders": [Path(f).name for f in folders], "made_by": command}
    write_atomic(out, pickle.dumps(data))
    return data
