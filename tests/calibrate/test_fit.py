"""lv3d.calibrate.fit: fit_final's choice per type of the final map with the best scene-grouped CV log
loss among none, the pooled isotonic map and the type's own; the scene-grouped folds."""

import numpy as np

from lv3d.calibrate.fit import fit_final


def test_fit_final_gives_a_miscalibrated_type_its_own_map_and_leaves_a_calibrated_one():
    rng = np.random.default_rng(0)
    n = 3000
    seeds = np.repeat(np.arange(n // 10), 10)               # 10 facts per scene
    c_ok, c_bad = rng.uniform(0.05, 0.95, n), rng.uniform(0.05, 0.95, n)
    oof = {"calibrated": (c_ok, (rng.random(n) < c_ok).astype(float), seeds),
           "overconfident": (c_bad, (rng.random(n) < c_bad ** 3).astype(float), seeds)}
    final, losses = fit_final(oof)
    assert set(losses["overconfident"]) == {"none", "pooled", "own"}
    assert final["by_pred"]["overconfident"] is not None    # its own map, which lowers its confidences
    own = final["by_pred"]["overconfident"]
    assert np.interp(0.5, own["x"], own["y"]) < 0.25
    assert "calibrated" not in final["by_pred"] or final["by_pred"]["calibrated"] is None  # pooled would pull it down
    assert np.all(np.diff(final["x"]) >= 0) and np.all(np.diff(final["y"]) >= 0)


def test_cross_validation_keeps_every_fact_of_a_scene_in_one_fold():
    from lv3d.calibrate.fit import _scene_fold_of

    seeds = np.repeat([30001, 30002, 31005, 40000, 40007, 40009, 50000], 9)
    fold = _scene_fold_of(seeds.tolist(), 0)
    assert set(fold) == set(seeds.tolist()) and set(fold.values()) <= set(range(5))
    assert len(set(fold.values())) == 5                      # 7 scenes cover all 5 folds
    assert _scene_fold_of(seeds[::-1].tolist(), 0) == fold   # the order of the rows does not matter


def test_scene_interval_widens_when_a_scene_s_facts_go_together():
    from lv3d.calibrate.measures import ece, scene_interval

    rng = np.random.default_rng(1)
    n_scenes, per = 60, 8
    p = np.full(n_scenes * per, 0.7)
    own = (rng.random(n_scenes * per) < p).astype(float)                         # each fact on its own
    shared = np.repeat((rng.random(n_scenes) < 0.7).astype(float), per)         # a scene's facts all true or all false
    apart, together = np.arange(n_scenes * per), np.repeat(np.arange(n_scenes), per)
    lo_a, hi_a = scene_interval(p, own, apart)
    lo_t, hi_t = scene_interval(p, shared, together)
    assert lo_a <= ece(p, own) <= hi_a and lo_t <= ece(p, shared) <= hi_t
    assert hi_t - lo_t > 2 * (hi_a - lo_a)      # 60 independent draws, not 480
    assert scene_interval(p, shared, together) == (lo_t, hi_t)                  # seeded


def test_a_key_with_rows_of_both_kinds_reports_each_map_s_loss_on_each_kind():
    """fit_one's fourth result: every candidate's CV log loss over the real rows and over the rendered rows alone
    (which kind chose the map); rendered rows where p is right, real rows where a high p is often wrong."""
    from lv3d.calibrate.fit import _wlog_loss, fit_one

    rng = np.random.default_rng(2)
    rows = []
    for i in range(600):
        real = i % 3 == 0
        p = float(rng.uniform(0.02, 0.98))
        y = rng.random() < (0.5 if real and p > 0.5 else p)
        rows.append({"pred": "perpendicular", "p": p, "y": float(y), "seed": i // 6, "support": 0.9,
                     "source": "real:x" if real else "render:clean", **({"scene": f"x/f{i // 6}"} if real else {})})
    entry, losses, conf, by_kind = fit_one(rows)
    assert set(by_kind) == {"real", "rendered"} and set(by_kind["real"]) == set(losses)
    real = np.array([r["source"].startswith("real:") for r in rows])
    y = np.array([r["y"] for r in rows])
    # the winner's out-of-fold confidences give its per-kind losses
    assert by_kind["real"][entry["map"]] == _wlog_loss(conf[real], y[real], np.ones(real.sum()))
    assert by_kind["real"]["raw"] > by_kind["rendered"]["raw"]     # the raw p is right on rendered rows only
    assert fit_one([r for r, k in zip(rows, real) if not k])[3] == {}  # one kind only: nothing to set apart
