"""The learner's accuracy under noise and its speed; prints each figure beside its target (issue 5).

    .venv/bin/python benchmarks/bench_learner.py [--per-class 10] [--heldout 25] [--seed 0]

Figures (rgbd facts, the four classes of the learner's tests, four-way accuracy on held-out clean
renders, 'unknown' counted wrong):
  clean          programs learned from clean ground-truth facts
  labels-20%     the same with 20 % of the training labels flipped to another class (seeded)
  facts-p        ground-truth facts perturbed with strength p for training and test (lv3d.truth_facts)
  realsense      facts through perception + grounding from the realsense preset, when lv3d.pipeline
                 can produce them (skipped, and said so, until it can)
  fit-100        seconds to learn one class from 100 scenes (median over the four classes)
  classify       milliseconds to classify one scene (median over the held-out set)
Takes about a minute; timings on a shared machine are pessimistic.
"""

from __future__ import annotations

import argparse
import statistics
import sys
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent.parent))

from lv3d.learn import Model, fit  # noqa: E402
from lv3d.learn.engine import LearnError  # noqa: E402
from lv3d.truth_facts import truth_facts  # noqa: E402

CLASSES = ("cube", "square_pyramid", "triangular_prism", "pentagonal_prism")
W, H = 320, 240


def render_metas(classes, seeds, noise="clean"):
    from lv3d.render.frame import render_scene

    out = []
    for c in classes:
        for s in seeds:
            frame, _ = render_scene(c, int(s), noise, W, H)
            out.append((c, int(s), frame))
    return out


def facts_of(items, tag, perturb=0.0, seed=0):
    scenes = [truth_facts(f.meta, f"{tag}_{c}_{s}", "rgbd", perturb=perturb, seed=seed + i)
              for i, (c, s, f) in enumerate(items)]
    return scenes, [c for c, _, _ in items]


def accuracy(model: Model, scenes, labels) -> float:
    """Four-way accuracy; a scene where perception found no target counts as answered 'unknown'."""
    return float(np.mean([s.target is not None and model.predict(s)[0] == y for s, y in zip(scenes, labels)]))


def flip(labels, frac, rng):
    """Labels with a fraction ``frac`` changed to another class, chosen at random."""
    out = list(labels)
    for i in rng.choice(len(out), int(round(frac * len(out))), replace=False):
        out[i] = rng.choice([c for c in CLASSES if c != out[i]])
    return out


def row(name, value, target, ok):
    print(f"{name:<22} {value:<28} target {target:<26} {'ok' if ok else 'MISSED'}", flush=True)


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--per-class", type=int, default=10, help="training scenes per class")
    ap.add_argument("--heldout", type=int, default=25, help="held-out scenes per class")
    ap.add_argument("--perturb", type=float, default=0.3, help="strength of the fact perturbation")
    ap.add_argument("--seed", type=int, default=0)
    a = ap.parse_args(argv)
    rng = np.random.default_rng(a.seed)

    t0 = time.perf_counter()
    train_items = render_metas(CLASSES, range(a.seed, a.seed + a.per_class))
    test_items = render_metas(CLASSES, range(10_000 + a.seed, 10_000 + a.seed + a.heldout))
    print(f"rendered {len(train_items)} training and {len(test_items)} held-out scenes "
          f"in {time.perf_counter() - t0:.1f} s", flush=True)
    train_x, train_y = facts_of(train_items, "tr")
    test_x, test_y = facts_of(test_items, "te")

    clean_model = Model.fit(train_x, train_y, seed=a.seed)
    clean = accuracy(clean_model, test_x, test_y)
    row("clean", f"{clean:.3f}", "(reference)", True)
    for c, p in clean_model.programs.items():
        print(f"  % {c}\n  " + str(p).replace("\n", "\n  "))

    noisy_y = flip(train_y, 0.2, rng)
    acc = accuracy(Model.fit(train_x, noisy_y, seed=a.seed), test_x, test_y)
    row("labels-20%", f"{acc:.3f} ({acc - clean:+.3f})", ">= clean - 0.10", acc >= clean - 0.10)

    ptx, pty = facts_of(train_items, "tr", a.perturb, a.seed)
    pex, pey = facts_of(test_items, "te", a.perturb, a.seed + 10_000)
    acc = accuracy(Model.fit(ptx, pty, seed=a.seed), pex, pey)
    row(f"facts-p{a.perturb:g}", f"{acc:.3f} ({acc - clean:+.3f})", ">= clean - 0.10", acc >= clean - 0.10)

    try:
        from lv3d.pipeline import scene_facts

        rs_train = render_metas(CLASSES, range(a.seed, a.seed + a.per_class), "realsense")
        rs_test = render_metas(CLASSES, range(10_000 + a.seed, 10_000 + a.seed + a.heldout), "realsense")
        t = time.perf_counter()
        rx = [(scene_facts(f, f"rs_{c}_{s}", "rgbd"), c) for c, s, f in rs_train]
        ex = [scene_facts(f, f"rt_{c}_{s}", "rgbd") for c, s, f in rs_test]
        kept = [(x, c) for x, c in rx if x.target is not None]
        print(f"  pipeline facts in {time.perf_counter() - t:.0f} s; {len(rx) - len(kept)} training and "
              f"{sum(x.target is None for x in ex)} held-out scenes without a target", flush=True)
        model = Model.fit([x for x, _ in kept], [c for _, c in kept], seed=a.seed)
        acc = accuracy(model, ex, [c for c, _, _ in rs_test])
        row("realsense", f"{acc:.3f} ({acc - clean:+.3f})", ">= clean - 0.10", acc >= clean - 0.10)
    except (ImportError, AttributeError, NotImplementedError) as e:
        print(f"{'realsense':<22} skipped: perception/grounding not available ({type(e).__name__}: {e})")

    # speed: 100 scenes (25 per class), one class at a time
    big_items = render_metas(CLASSES, range(20_000, 20_025))
    big_x, big_y = facts_of(big_items, "big")
    times = []
    for c in CLASSES:
        t = time.perf_counter()
        try:
            fit(big_x, big_y, c, seed=a.seed)
        except LearnError as e:
            print(f"  {c}: {e}")
        times.append(time.perf_counter() - t)
    med = statistics.median(times)
    row("fit-100 (s)", f"{med:.3f} (max {max(times):.3f})", "median <= 1 s", med <= 1.0)

    times = []
    for s in test_x:
        t = time.perf_counter()
        clean_model.predict(s)
        times.append(time.perf_counter() - t)
    med = 1000 * statistics.median(times)
    row("classify (ms)", f"{med:.2f}", "median <= 10 ms", med <= 10.0)
    return 0


if __name__ == "__main__":
    sys.exit(main())
