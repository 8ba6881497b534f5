"""Grounding accuracy, calibration and speed on rendered scenes with exact ground truth.

    .venv/bin/python -m benchmarks.bench_grounding            # 6 scenes per class, realsense and hard
    .venv/bin/python -m benchmarks.bench_grounding --quick    # 2 per class
    .venv/bin/python -m benchmarks.bench_grounding --no-speed --out out/bench_grounding
    .venv/bin/python -m benchmarks.bench_grounding --presets realsense --sources perceived --no-speed --bins acute,parallel

Per preset (rgbd perception of the target object): median vertex error (px) of faces whose side count is
right and median interior-dihedral error (deg) of truly adjacent faces, without and with refinement;
expected calibration error (ECE, 10 bins) of every emitted fact type against the predicate evaluated on
the ground truth (a fact on a face that matches no true face is false), beside the ECE a perfectly calibrated
type shows by chance (facts drawn one by one) and a 95% interval of the ECE over scenes drawn with replacement
(a scene's facts are not independent), each type's log loss over every labelled candidate (dropped ones included:
a proper score, steadier than a rare type's ECE), and a reliability diagram (PNG under --out); the model-error floor each
quantity would need (docs/grounding.md). Then speed:
refinement + facts per 640x480 frame on one core after warm-up (median over --speed-runs processes, each
timing --speed-frames - 1 frames twice), and the first call in each new process with a warm compilation
cache. Targets from the issue are printed beside the figures.
"""

from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
import time
from collections import defaultdict
from pathlib import Path

import numpy as np

from lv3d import compile_cache
from lv3d.calibrate.measures import chance_ece, ece, ece_verdict, log_loss, reliability_bins, scene_interval
from lv3d.calibrate.truth import match_faces, truth_labels, truth_quantities, truth_scene
from lv3d.describe import MIN_CONF, ground
from lv3d.perception import perceive
from lv3d.render import render_scene
from benchmarks.targets import beside

ROOT = Path(__file__).resolve().parent.parent

CLASSES = ["cube", "cuboid", "square_pyramid", "triangular_prism", "pentagonal_prism", "hexagonal_prism",
           "tetrahedron"]
CUT_TARGET = 0.30      # refinement cuts vertex and dihedral error by at least this at realsense
FRAME_MS_TARGET = 20.0
FIRST_CALL_S_TARGET = 2.0
DEBUG = bool(os.environ.get("BENCH_DEBUG"))


def _med(xs):
    return float(np.median(xs)) if len(xs) else float("nan")


def run_preset(preset: str, per_class: int, seed0: int, source: str = "perceived") -> dict:
    """Accuracy and calibration figures of one preset. ``source``: 'perceived' scenes come from
    lv3d.perception (end to end: perception's gross errors count against the facts); 'truth' scenes are
    true polygons with 1.5 px vertex noise and planes fitted to the noisy depth (grounding alone)."""
    stats = {"vertex": {False: [], True: []}, "dihedral": {False: [], True: []}, "facts": defaultdict(list),
             "candidates": defaultdict(list), "z": defaultdict(list), "frames": 0}
    rgbd_preds = _modal_preds("rgbd")
    for ci, cls in enumerate(CLASSES):
        for s in range(per_class):
            seed = seed0 + 1000 * ci + s
            frame, faces_mask = render_scene(cls, seed, preset)
            if source == "truth":
                scene = truth_scene(frame, faces_mask, f"s{seed:06d}", np.random.default_rng(seed))
            else:
                scene = perceive(frame, "rgbd", scene_id=f"s{seed:06d}")
            stats["frames"] += 1
            truth = frame.meta["truth"]
            for refine in (False, True):
                cands, results = ground(scene, frame, refine=refine)
                for res in results:
                    match = match_faces(res, faces_mask, truth)
                    if not match:
                        continue
                    for fr in res.faces:
                        g = match.get(fr.face.id)
                        if g is None or len(fr.polygon) != g["sides"] or g.get("visible_fraction", 1.0) < 0.9:
                            continue
                        tp = np.asarray(g["polygon"], float)
                        d = np.linalg.norm(tp[:, None] - fr.polygon[None], axis=2)
                        stats["vertex"][refine] += d.min(axis=1).tolist()
                    for adj in truth.get("adjacency", []):
                        a, b = adj["faces"]
                        for (fa, fb), dih in res.dihedral_deg.items():
                            ga, gb = match.get(fa), match.get(fb)
                            if ga is not None and gb is not None and fa < fb and {ga["id"], gb["id"]} == {a, b}:
                                stats["dihedral"][refine].append(abs(dih - adj["dihedral_deg"]))
                    if refine:
                        for (pred, z) in truth_quantities(res, match, truth, frame.intrinsics):
                            stats["z"][pred].append(z)
                if refine:
                    labels = truth_labels(cands, results, faces_mask, truth, frame.intrinsics)
                    for (pred, args, p, value), y in zip(cands, labels):
                        if y is None or pred not in rgbd_preds:
                            continue
                        stats["candidates"][pred].append((min(p, 1.0), float(y)))
                        if p >= MIN_CONF:
                            stats["facts"][pred].append((min(p, 1.0), float(y), seed))
                            if DEBUG and abs(p - y) > 0.7:
                                print(f"    miss {cls} {seed} {pred}{args} p={p:.2f} value={value} truth={y}")
    return stats


def _modal_preds(modality):
    from lv3d.facts import PREDICATES

    return {p for p, (_, mods) in PREDICATES.items() if modality in mods}


def candidates_log_loss(rows: list[tuple[float, float]]) -> float:
    """Log loss of (confidence, truth) pairs: over every candidate with a truth label, dropped ones (below the
    emission threshold) included, a proper score of the confidences, steadier than a rare type's ECE, which sees
    only the few facts emitted."""
    return log_loss(*np.array(rows, float).reshape(-1, 2).T) if rows else float("nan")


def suggested_floor(z: list[tuple[float, float]]) -> float:
    """Floor f such that errors / sqrt(std^2 + f^2) have median |.| 0.674 (that of a unit Gaussian)."""
    if len(z) < 5:
        return float("nan")
    err = np.abs(np.array([e for e, _ in z]))
    std = np.array([s for _, s in z])
    lo, hi = 0.0, 50.0
    for _ in range(60):
        f = 0.5 * (lo + hi)
        if np.median(err / np.sqrt(std ** 2 + f ** 2)) > 0.674:
            lo = f
        else:
            hi = f
    return 0.5 * (lo + hi)


def reliability_png(facts: dict, path: Path, title: str) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(6, 6))
    ax.plot([0, 1], [0, 1], "k--", lw=1)
    for pred, rows in sorted(facts.items()):
        if len(rows) < 5:
            continue
        p, y, _ = np.array(rows).T
        edges = np.linspace(0, 1, 11)
        idx = np.minimum((p * 10).astype(int), 9)
        xs = [p[idx == b].mean() for b in range(10) if np.any(idx == b)]
        ys = [y[idx == b].mean() for b in range(10) if np.any(idx == b)]
        ax.plot(xs, ys, "o-", ms=3, label=f"{pred} (n={len(p)})")
        del edges
    ax.set_xlabel("confidence")
    ax.set_ylabel("fraction true on ground truth")
    ax.set_title(title)
    ax.legend(fontsize=7)
    fig.tight_layout()
    path.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(path, dpi=110)
    plt.close(fig)


def speed(frames: int, runs: int) -> tuple[float, float, list[float]]:
    """(median ms per frame for refinement + facts on one core, the same in CPU time of the process, the
    first call in each new process in s, which includes importing JAX and grounding and loading the compiled
    programs from the cache), over ``runs`` processes after one that warms the cache. Each process times
    ``frames`` - 1 frames twice. On a shared machine the CPU time is the steadier figure: it leaves out the
    time the process waits for the core."""
    code = r"""
import os, sys, time, json
os.sched_setaffinity(0, {sorted(os.sched_getaffinity(0))[0]})
from lv3d.describe import describe
from lv3d.render import render_scene
from lv3d.perception import perceive
items = []
for i in range(%d):
    fr, _ = render_scene(["cube", "triangular_prism", "pentagonal_prism"][i %% 3], 500 + i, "realsense")
    items.append((fr, perceive(fr, "rgbd", scene_id="s%%06d" %% i)))
t1 = time.perf_counter()
describe(items[0][1], items[0][0])
first = time.perf_counter() - t1
ts, cs = [], []
for fr, sc in items[1:] + items[1:]:
    t, c = time.perf_counter(), time.process_time(); describe(sc, fr)
    ts.append(time.perf_counter() - t); cs.append(time.process_time() - c)
import numpy as np
print(json.dumps({"first": first, "ts": ts, "cs": cs}))
""" % frames
    env = dict(os.environ, XLA_FLAGS="--xla_cpu_multi_thread_eigen=false intra_op_parallelism_threads=1")
    out = []
    for _ in range(1 + runs):  # the first run warms the cache if it is cold; the others are measured
        r = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, env=env, cwd=ROOT)
        if r.returncode != 0:
            raise RuntimeError(r.stderr[-2000:])
        out.append(json.loads(r.stdout.strip().splitlines()[-1]))
    ts = [t for o in out[1:] for t in o["ts"]]
    cs = [c for o in out[1:] for c in o["cs"]]
    return 1e3 * float(np.median(ts)), 1e3 * float(np.median(cs)), [o["first"] for o in out[1:]]


def main(argv=None) -> int:
    compile_cache.enable()  # an entry point: grounding's compiled programs are kept on disk
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--quick", action="store_true", help="2 scenes per class")
    ap.add_argument("--per-class", type=int, default=6)
    ap.add_argument("--presets", default="realsense,hard")
    ap.add_argument("--seed", type=int, default=7000)
    ap.add_argument("--out", type=Path, default=ROOT / "out" / "bench_grounding")
    ap.add_argument("--no-speed", action="store_true")
    ap.add_argument("--speed-frames", type=int, default=16, help="frames a speed process renders (the first is the first call)")
    ap.add_argument("--speed-runs", type=int, default=3, help="measured speed processes (after one that warms the cache)")
    ap.add_argument("--sources", default="truth,perceived",
                    help="scenes from 'truth' (grounding alone) and/or 'perceived' (end to end)")
    ap.add_argument("--bins", default="", help="fact types (comma-separated) whose reliability bins to print: "
                    "facts, mean confidence and share true per tenth of confidence")
    a = ap.parse_args(argv)
    per_class = 2 if a.quick else a.per_class
    for preset, source in [(p, s) for s in a.sources.split(",") for p in a.presets.split(",")]:
        t = time.perf_counter()
        st = run_preset(preset, per_class, a.seed, source)
        print(f"== {preset}, {source} scenes: {st['frames']} frames, rgbd, {time.perf_counter() - t:.0f} s")
        for key, unit in (("vertex", "px"), ("dihedral", "deg")):
            raw, ref = _med(st[key][False]), _med(st[key][True])
            cut = 1 - ref / raw if raw > 0 else float("nan")
            tgt = f"  (cut {beside('>=', CUT_TARGET, cut, '.0%')})" if preset == "realsense" else ""
            print(f"  median {key} error: unrefined {raw:.3f} {unit}, refined {ref:.3f} {unit} "
                  f"(n={len(st[key][True])}), cut {cut:.1%}{tgt}")
        allp = [r for rows in st["facts"].values() for r in rows]
        for pred, rows in sorted(st["facts"].items()):
            p, y, scenes = np.array(rows).T
            e = ece(p, y)
            lo, hi = scene_interval(p, y, scenes)
            tgt = f"  {ece_verdict(e)}" if preset == "realsense" else ""
            print(f"  ECE {pred:14s} {e:.3f}  n={len(p):4d}  chance {chance_ece(p):.3f}  scenes 95% {lo:.3f}-{hi:.3f}  "
                  f"mean conf {p.mean():.2f}  true {y.mean():.2f}  log loss {candidates_log_loss(st['candidates'][pred]):.4f}{tgt}")
            if pred in a.bins.split(","):
                for lo, n, conf, true in reliability_bins(p, y):
                    print(f"      [{lo:.1f}, {lo + 0.1:.1f})  n={n:4d}  conf {conf:.2f}  true {true:.2f}")
        if allp:
            p, y, _ = np.array(allp).T
            every = [r for rows in st["candidates"].values() for r in rows]
            print(f"  ECE all facts      {ece(p, y):.3f}  n={len(p)}  log loss {candidates_log_loss(every):.4f} (n={len(every)})")
        png = a.out / f"reliability_{preset}_{source}.png"
        reliability_png(st["facts"], png, f"grounding calibration, {preset}, {source} scenes, rgbd")
        print(f"  reliability diagram: {png}")
        for q, z in sorted(st["z"].items()):
            print(f"  floor that {q:14s} would need: {suggested_floor(z):.3f}  (n={len(z)})")
    if not a.no_speed:
        ms, cpu_ms, firsts = speed(a.speed_frames, a.speed_runs)
        first = float(np.median(firsts))
        print("== speed (one core; this machine is shared, so figures are pessimistic)")
        print(f"  refinement + facts per 640x480 frame, median after warm-up: {ms:.1f} ms "
              f"({beside('<=', FRAME_MS_TARGET, ms, '.0f', ' ms')}); "
              f"CPU time {cpu_ms:.1f} ms")
        print(f"  first call in a new process, warm cache: median {first:.2f} s of "
              f"{', '.join(f'{x:.2f}' for x in firsts)} "
              f"({beside('<=', FIRST_CALL_S_TARGET, first, '.0f', ' s')}; "
              f"includes importing JAX)")
    return 0


if __name__ == "__main__":
    sys.exit(main())
