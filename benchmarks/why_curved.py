"""Why a labelled object of a real frame has or lacks a cylindrical face: every curved surface (sphere, cone,
cylinder) the depth stage weighed on its object, and the test each one passed or failed, with the measured value
beside the limit.

    .venv/bin/python -m benchmarks.why_curved                                 # cylinders and boxes, every dev folder
    .venv/bin/python -m benchmarks.why_curved ../shared/data/real/ycb-realsense --shapes cylinder
    .venv/bin/python -m benchmarks.why_curved --seed 1 --set curved.trials=1024 --csv out/why_curved.csv

A diagnostic of the curved-surface searches (lv3d/perception/depth/quadrics.py and curved.py), for work on the
``cylinder_read_frac`` and ``box_curved_frac`` figures of bench_real: a cylinder missed on a can and a cylinder
found on a box are both a candidate's tests deciding, and which test decides says what to change.

Every frame of each folder (``--limit N``: the first N) is perceived by the depth stage (lv3d.perception.depth,
seed ``--seed``, settings with each ``--set KEY=VALUE`` as bench_real takes them); the object of each labelled
object of ``--shapes`` is the depth object whose grid mask holds its labelled pixel (none: *not found*). For that
object it prints:

- whether the planes left room for the sample consensus (quadrics.leaves_room; without room only a fan of planes
  is tried, see curved.object_cylinders);
- each sphere and cone that reached the acceptance tests of that search (``quadrics._stands``, which runs
  first): its radius (a cone's: its half-angle), cells and, test by test, ``cells``, ``rms`` (mm, <= the inlier
  distance), ``normals`` (median turn of the cells' normals from the surface's, deg, <= ``normal_fit_deg``),
  ``planes`` (RMS over the cells on a plane, mm, <= ``plane_ratio`` times theirs from their planes), then for a
  sphere ``spread`` (deg, >= ``min_spread_deg``), ``over cylinder`` and ``share`` (shares of a least-squares
  cylinder's and a plane's residual variance explained, >= ``min_share``), for a cone ``profile`` (arc deg >=
  ``min_arc_deg``, dip >= ``min_dip``), ``over plane`` (>= ``min_share``) and ``share`` (of a cylinder's, >=
  ``min_cone_share``);
- each cylinder candidate that reached the acceptance tests (``curved._stands``; a fan of planes is a candidate
  once fan_cylinder found it; the fan tests inside fan_cylinder are not shown): its radius, cells, side (+1
  outside, -1 inside), origin (fan or sample) and, test by test in the order they run, the value and the limit:
  ``cells`` (>= max(20, the fewest cells of a face)), ``rms`` (mm, <= the inlier distance), ``misfit`` (sampled
  candidates only: the cylinder's systematic misfit over the cells the planes held, mm, <= ``misfit_ratio``
  times the planes'), ``track`` (arc deg >= ``min_arc_deg``, gap deg <= ``max_gap_deg``), ``profile`` (normal
  arc deg >= ``sample_arc_deg``, dip >= ``min_dip``), ``sphere`` (insides only: share of the sphere's residual
  variance explained >= ``min_share``), ``share`` (curved_share >= ``min_share``). After them, whatever they
  decided, ``two planes``: a measurement and no test, the cylinder's systematic misfit over all its cells
  (:func:`lv3d.perception.depth.curved.misfit`, mm) beside the best pair of planes' (:func:`two_planes`: its cells
  split at one position around the axis, a least-squares plane on each side), and their ratio; under 1 the
  cylinder fits its cells better than a box's two faces meeting at an edge would.
  The first test that fails is a candidate's verdict. The depth stage's own verdict is kept beside it: a row
  where the two differ says ``DIFFERS``;
- the object's surfaces as the depth stage left them (planes, cylinders, cones, spheres).

The outcome of each object: ``cylinder`` (a cylindrical face), ``cone`` / ``sphere`` (such a face and no
cylinder), ``no room`` (no cylinder candidate, and the planes left no room for the sample consensus),
``no candidate`` (it ran and no cylinder reached the tests), ``rejected: TEST`` (cylinder candidates, none stood:
the test that stopped the one with the most cells) or ``not found``. The summary counts outcomes per shape;
``--csv FILE`` writes a row per candidate. Unoccluded objects only (``partial`` no) unless ``--partial``. Where
the real frames are absent it says so and exits 0.
"""

from __future__ import annotations

if __name__ == "__main__":  # one core, as bench_real
    import os

    for _var in ("OMP_NUM_THREADS", "MKL_NUM_THREADS", "OPENBLAS_NUM_THREADS", "NUMEXPR_NUM_THREADS"):
        os.environ[_var] = "1"
    os.environ.setdefault("JAX_PLATFORMS", "cpu")

import argparse
import contextlib
import csv
import sys
from collections import Counter
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from benchmarks.bench_real import _one_core, named_folders, depth_settings
from lv3d.errors import InputError
from lv3d.frame_folder import FrameFolder

TESTS = ("cells", "rms", "misfit", "track", "profile", "sphere", "two planes", "normals", "planes", "spread",
         "over cylinder",
         "over plane", "share")


@dataclass
class Candidate:
    """One curved surface that reached the acceptance tests: its ``size`` (radius, mm; a cone's half-angle, deg), cells,
    side, origin ('fan' or 'sample' for a cylinder, 'sphere', 'cone'), each test run as (name, value text, limit
    text, passed), and the depth stage's verdict."""

    size: float
    cells: int
    side: int
    origin: str
    tests: list[tuple[str, str, str, bool]]
    stood: bool

    @property
    def verdict(self) -> str:
        failed = [name for name, _, _, ok in self.tests if not ok]
        return failed[0] if failed else "stands"

    @property
    def agrees(self) -> bool:
        return (self.verdict == "stands") == self.stood


@dataclass
class Weighed:
    """What the curved-surface searches did on one depth object: ``room`` (the sample consensus of spheres,
    cones and cylinders ran on it) and the candidates they weighed."""

    room: bool = False
    candidates: list[Candidate] = field(default_factory=list)


class _Tests(list):
    """The tests run on one candidate, each (name, value, limit, passed); called as ``test(name, value, limit,
    ok)``, it records one and returns whether it passed."""

    def __call__(self, name: str, value: str, limit: str, ok) -> bool:
        self.append((name, value, limit, bool(ok)))
        return bool(ok)


def _size_and_fit(tests: _Tests, min_cells: int, res: np.ndarray, dist_m: float) -> float | None:
    """The two tests both searches run first, on a candidate's residuals ``res`` (m,) metres: enough cells
    (max(20, ``min_cells``)) and an RMS residual within the inlier distance. The RMS where both pass, else None."""
    need = max(20, min_cells)
    if not tests("cells", str(len(res)), f">= {need}", len(res) >= need):
        return None
    rms = float(np.sqrt(np.mean(res ** 2)))
    ok = tests("rms", f"{1e3 * rms:.2f} mm", f"<= {1e3 * dist_m:.2f} mm", np.isfinite(rms) and rms <= dist_m)
    return rms if ok else None


def two_planes(cyl, pts: np.ndarray, bin_deg: float, splits: int = 17) -> float:
    """The systematic misfit (curved.misfit, metres) of the best pair of planes over points (m, 3) on or near a
    cylinder: the points cut at one position around its axis (``splits`` positions, at the 10th to the 90th
    percentile of the points' angles, unwrapped at their widest gap), a least-squares plane fitted to each side,
    residuals signed positive towards the camera. What a box's two faces meeting at an edge leave; inf with
    fewer than 10 points a side at every cut."""
    from lv3d.perception.depth import curved
    from lv3d.perception.depth.support import refine

    _, b1, b2 = curved.axis_basis(cyl.axis)
    d = pts - np.asarray(cyl.point)
    theta = np.degrees(np.arctan2(d @ b2, d @ b1))
    order = np.sort(theta)
    gaps = np.diff(np.concatenate([order, order[:1] + 360.0]))
    theta = (theta - order[(int(np.argmax(gaps)) + 1) % len(order)]) % 360.0
    best = np.inf
    for cut in np.quantile(theta, np.linspace(0.1, 0.9, splits)):
        left = theta < cut
        if min(np.count_nonzero(left), np.count_nonzero(~left)) < 10:
            continue
        res = np.empty(len(pts))
        for side in (left, ~left):
            part = pts[side]
            plane = refine(part)
            r = plane.distance(part)
            res[side] = -r if float(plane.n @ part.mean(axis=0)) > 0 else r
        best = min(best, curved.misfit(cyl, pts, res, bin_deg))
    return best


def gate_tests(cyl, pts: np.ndarray, nrm: np.ndarray, plane_fit, dist_m: float, min_cells: int, settings,
               side: float) -> list[tuple[str, str, str, bool]]:
    """The acceptance tests of curved._stands on one candidate, in its order, each as (name, value, limit,
    passed), up to the first that fails; then ``two planes``, a measurement that always passes
    (:func:`two_planes`)."""
    tests = _gate_tests(cyl, pts, nrm, plane_fit, dist_m, min_cells, settings, side)
    from lv3d.perception.depth import curved

    bin_deg = settings.max_gap_deg / 2
    mine = curved.misfit(cyl, pts, side * (cyl.radial(pts)[0] - cyl.radius), bin_deg)
    theirs = two_planes(cyl, pts, bin_deg)
    ratio = mine / theirs if theirs > 0 else np.inf
    tests("two planes", f"{1e3 * mine:.2f} mm / {1e3 * theirs:.2f} mm = {ratio:.2f}", "a measurement", True)
    return tests


def _gate_tests(cyl, pts: np.ndarray, nrm: np.ndarray, plane_fit, dist_m: float, min_cells: int, settings,
                side: float) -> _Tests:
    from lv3d.perception.depth import curved
    from lv3d.sphere import algebraic_sphere

    tests = _Tests()
    rms = _size_and_fit(tests, min_cells, cyl.radial(pts)[0] - cyl.radius, dist_m)
    if rms is None:
        return tests
    if plane_fit is not None:
        on_planes, plane_res = plane_fit
        bin_deg = settings.max_gap_deg / 2
        theirs = curved.misfit(cyl, on_planes, plane_res, bin_deg)
        mine = curved.misfit(cyl, on_planes, side * (cyl.radial(on_planes)[0] - cyl.radius), bin_deg)
        if not tests("misfit", f"{1e3 * mine:.2f} mm", f"<= {settings.misfit_ratio} x {1e3 * theirs:.2f} mm",
                     mine <= settings.misfit_ratio * theirs):
            return tests
    _, arc, gap = curved.track(cyl, pts, nrm, settings.max_gap_deg / 2, settings.bin_cells)
    if not tests("track", f"arc {arc:.0f} gap {gap:.0f}", f"arc >= {settings.min_arc_deg:g} gap <= "
                 f"{settings.max_gap_deg:g}", arc >= settings.min_arc_deg and gap <= settings.max_gap_deg):
        return tests
    arc, dip = curved.normal_profile(cyl, nrm, settings.max_gap_deg / 2)
    if not tests("profile", f"arc {arc:.0f} dip {dip:.2f}", f"arc >= {settings.sample_arc_deg:g} dip >= "
                 f"{settings.min_dip:g}", arc >= settings.sample_arc_deg and dip >= settings.min_dip):
        return tests
    if side < 0:
        sphere = algebraic_sphere(pts)
        if sphere is not None:
            over = curved.explained_share(rms * rms, float(np.mean(sphere.residual(pts) ** 2)))
            if not tests("sphere", "none" if over is None else f"{over:.2f}", f">= {settings.min_share:g}",
                         over is not None and over >= settings.min_share):
                return tests
    share = curved.curved_share(pts, cyl)
    tests("share", f"{share:.2f}", f">= {settings.min_share:g}", share >= settings.min_share)
    return tests


def quadric_tests(model, pts: np.ndarray, nrm: np.ndarray, plane_res: np.ndarray, dist_m: float, min_cells: int,
                  settings) -> list[tuple[str, str, str, bool]]:
    """The acceptance tests of quadrics._stands on one sphere or cone, in its order, each as (name, value,
    limit, passed), up to the first that fails."""
    from lv3d.perception.depth import quadrics
    from lv3d.sphere import Sphere

    tests = _Tests()
    res, normal = quadrics._residual_normal(model, pts)
    if _size_and_fit(tests, min_cells, res, dist_m) is None:
        return tests
    turn = float(np.median(np.degrees(np.arccos(np.clip(np.einsum("ij,ij->i", normal, nrm), -1.0, 1.0)))))
    if not tests("normals", f"{turn:.1f} deg", f"<= {settings.normal_fit_deg:g} deg", turn <= settings.normal_fit_deg):
        return tests
    on_plane = np.isfinite(plane_res)
    if np.count_nonzero(on_plane) >= 20:
        mine = float(np.sqrt(np.mean(res[on_plane] ** 2)))
        theirs = float(np.sqrt(np.mean(plane_res[on_plane] ** 2)))
        if not tests("planes", f"{1e3 * mine:.2f} mm", f"<= {settings.plane_ratio} x {1e3 * theirs:.2f} mm",
                     mine <= settings.plane_ratio * theirs):
            return tests
    if isinstance(model, Sphere):
        spread = quadrics._spread_deg(nrm)
        if not tests("spread", f"{spread:.1f} deg", f">= {settings.min_spread_deg:g} deg",
                     spread >= settings.min_spread_deg):
            return tests
        _, vecs = np.linalg.eigh(nrm.T @ nrm)
        over = quadrics._share(float(np.mean(res ** 2)), quadrics.cylinder_ms(pts, vecs[:, 0]))
        if not tests("over cylinder", "none" if over is None else f"{over:.2f}", f">= {settings.min_share:g}",
                     over is None or over >= settings.min_share):
            return tests
        share, least = quadrics.sphere_evidence(pts, model), settings.min_share
    else:
        arc, dip = quadrics._azimuth_profile(model.axis, nrm, settings.bin_deg)
        if not tests("profile", f"arc {arc:.0f} dip {dip:.2f}", f"arc >= {settings.min_arc_deg:g} dip >= "
                     f"{settings.min_dip:g}", arc >= settings.min_arc_deg and dip >= settings.min_dip):
            return tests
        plane = quadrics._share(float(np.mean(res ** 2)), quadrics.plane_ms(pts))
        if not tests("over plane", "none" if plane is None else f"{plane:.2f}", f">= {settings.min_share:g}",
                     plane is not None and plane >= settings.min_share):
            return tests
        share, least = quadrics.cone_evidence(pts, model), settings.min_cone_share
    tests("share", "none" if share is None else f"{share:.2f}", f">= {least:g}", share is not None and share >= least)
    return tests


@contextlib.contextmanager
def watching(record: dict[bytes, Weighed]):
    """Within: the depth stage's cylinder search recorded per object (keyed by its grid mask's bytes) into
    ``record``. Wraps stage.quadric_faces and stage._curved (which object), stage.object_cylinders (whether the
    consensus ran), quadrics._stands and curved._stands (each candidate), and restores them on leaving."""
    from lv3d.perception.depth import curved, quadrics, stage

    own = (stage.quadric_faces, stage._curved, stage.object_cylinders, quadrics._stands, curved._stands)
    own_quadrics, own_curved, own_search, own_quadric_stands, own_stands = own
    current: list[Weighed] = []

    @contextlib.contextmanager
    def within(mask: np.ndarray):
        current.append(record.setdefault(np.packbits(mask).tobytes(), Weighed()))
        try:
            yield
        finally:
            current.pop()

    def quadrics_of(xyz, mask, *args, room=None, **kw):
        with within(mask):
            current[-1].room |= room is None or bool(room)
            return own_quadrics(xyz, mask, *args, room=room, **kw)

    def curved_of(grid, o, *args, **kw):
        with within(o.mask):
            return own_curved(grid, o, *args, **kw)

    def quadric_stands(model, pts, nrm, plane_res, dist_m, min_cells, settings):
        stood = own_quadric_stands(model, pts, nrm, plane_res, dist_m, min_cells, settings)
        if current:
            cone = getattr(model, "half_angle_deg", None)
            current[-1].candidates.append(Candidate(
                cone if cone is not None else 1e3 * model.radius, len(pts), 0, "sphere" if cone is None else "cone",
                quadric_tests(model, pts, nrm, plane_res, dist_m, min_cells, settings), stood))
        return stood

    def search(*args, sample: bool = True, **kw):
        if current:
            current[-1].room |= bool(sample)
        return own_search(*args, sample=sample, **kw)

    def stands(cyl, pts, nrm, plane_fit, dist_m, min_cells, settings, side=1.0):
        stood = own_stands(cyl, pts, nrm, plane_fit, dist_m, min_cells, settings, side)
        if current:
            current[-1].candidates.append(Candidate(
                1e3 * cyl.radius, len(pts), int(side), "fan" if plane_fit is None else "sample",
                gate_tests(cyl, pts, nrm, plane_fit, dist_m, min_cells, settings, side), stood))
        return stood

    stage.quadric_faces, stage._curved, stage.object_cylinders, quadrics._stands, curved._stands = \
        quadrics_of, curved_of, search, quadric_stands, stands
    try:
        yield record
    finally:
        stage.quadric_faces, stage._curved, stage.object_cylinders, quadrics._stands, curved._stands = own


def surfaces(result) -> Counter:
    """The surfaces of one depth object as the depth stage left them: planes and curved faces by kind."""
    kinds = Counter({"plane": len(result.planes)})
    for c in result.curved:
        kinds[getattr(c, "surface", "cylinder")] += 1
    return +kinds


def outcome(kinds: Counter, weighed: Weighed | None) -> str:
    for kind in ("cylinder", "cone", "sphere"):
        if kinds.get(kind):
            return kind
    cylinders = [c for c in weighed.candidates if c.origin in ("fan", "sample")] if weighed is not None else []
    if not cylinders:
        return "no candidate" if weighed is not None and weighed.room else "no room"
    return f"rejected: {max(cylinders, key=lambda c: c.cells).verdict}"


def weigh_folder(folder: Path, shapes: tuple[str, ...], limit: int | None, seed: int, settings,
                 partial: bool) -> list[dict]:
    """One record per labelled object of ``shapes`` in the folder's frames: frame, object, shape, notes,
    outcome, surfaces and candidates."""
    from lv3d.perception.depth import depth_scene

    ff = FrameFolder(folder)
    labels = ff.labels()  # any class: ``shapes`` picks the ones shown
    notes = _notes(folder)
    frames = ff.frames[:limit] if limit else ff.frames
    rows = []
    for name in frames:
        chosen = [lab for lab in labels.get(name, []) if lab.shape in shapes and (partial or not lab.partial)]
        if not chosen:
            continue
        record: dict[bytes, Weighed] = {}
        with watching(record):
            res = depth_scene(ff.load(name), seed=seed, settings=settings)
        stride = res.settings.stride
        for lab in chosen:
            i, j = lab.v // stride, lab.u // stride
            held = [r for r in res.objects if r.obj.mask[i, j]]
            row = {"folder": folder.name, "frame": name, "object": lab.object, "shape": lab.shape,
                   "notes": notes.get((name, str(lab.object)), ""), "candidates": [], "surfaces": Counter()}
            if not held:
                row["outcome"] = "not found"
            else:
                weighed = record.get(np.packbits(held[0].obj.mask).tobytes())
                row["surfaces"] = surfaces(held[0])
                row["candidates"] = weighed.candidates if weighed else []
                row["room"] = bool(weighed and weighed.room)
                row["outcome"] = outcome(row["surfaces"], weighed)
            rows.append(row)
    return rows


def _notes(folder: Path) -> dict[tuple[str, str], str]:
    with open(folder / "objects.csv", newline="") as f:
        return {(r.get("frame", ""), r.get("object", "")): r.get("notes") or "" for r in csv.DictReader(f)}


def show(row: dict) -> str:
    kinds = " + ".join(f"{k}*{n}" for k, n in sorted(row["surfaces"].items())) or "-"
    head = (f"{row['folder']} {row['frame']} object {row['object']} ({row['shape']}"
            f"{': ' + row['notes'] if row['notes'] else ''}): {row['outcome']}; surfaces {kinds}"
            f"{'' if row['outcome'] == 'not found' else '; consensus ' + ('ran' if row.get('room') else 'not run')}")
    lines = [head]
    for c in row["candidates"]:
        tests = "; ".join(f"{name} {value} ({limit}){'' if ok else ' FAIL'}" for name, value, limit, ok in c.tests)
        size = f"half-angle {c.size:.0f} deg" if c.origin == "cone" else f"r {c.size:.0f} mm"
        side = f", side {c.side:+d}" if c.origin in ("fan", "sample") else ""
        lines.append(f"    {c.origin} {size}, {c.cells} cells{side}: {c.verdict}"
                     f"{'' if c.agrees else ' DIFFERS from the depth stage'} | {tests}")
    return "\n".join(lines)


def summary(rows: list[dict], shapes: tuple[str, ...]) -> str:
    lines = ["", "outcomes (objects):"]
    for shape in shapes:
        mine = [r for r in rows if r["shape"] == shape]
        if not mine:
            continue
        counts = Counter(r["outcome"] for r in mine)
        lines.append(f"  {shape} ({len(mine)}): " + ", ".join(f"{k} {n}" for k, n in counts.most_common()))
    cands = [c for r in rows for c in r["candidates"]]
    if cands:
        by = Counter((c.origin, c.verdict) for c in cands)
        lines.append("candidates by origin and verdict: " + ", ".join(f"{o} {v} {n}" for (o, v), n in
                                                                      sorted(by.items())))
    ratios: dict[str, list[float]] = {}
    for r in rows:
        for c in r["candidates"]:
            got = [v for name, v, _, _ in c.tests if name == "two planes"]
            if c.verdict == "stands" and got:
                ratios.setdefault(r["shape"], []).append(float(got[0].rsplit("= ", 1)[1]))
    if ratios:
        lines.append("cylinders that stand, their misfit over the best two planes' (median [least, most]): " +
                     ", ".join(f"on a {k} {np.median(v):.2f} [{min(v):.2f}, {max(v):.2f}] of {len(v)}"
                               for k, v in sorted(ratios.items())))
    differ = sum(not c.agrees for c in cands)
    lines.append(f"verdicts that differ from the depth stage's: {differ}")
    return "\n".join(lines)


def write_csv(path: Path, rows: list[dict]) -> None:
    path.parent.mkdir(parents=True, exist_ok=True)
    with open(path, "w", newline="") as f:
        w = csv.writer(f)
        w.writerow(["folder", "frame", "object", "shape", "outcome", "origin", "size", "cells", "side",
                    "verdict", "stood", *TESTS])
        for r in rows:
            for c in r["candidates"] or [None]:
                if c is None:
                    w.writerow([r["folder"], r["frame"], r["object"], r["shape"], r["outcome"], *[""] * 6,
                                *[""] * len(TESTS)])
                    continue
                got = {name: f"{value} ({limit}){'' if ok else ' FAIL'}" for name, value, limit, ok in c.tests}
                w.writerow([r["folder"], r["frame"], r["object"], r["shape"], r["outcome"], c.origin,
                            f"{c.size:.1f}", c.cells, c.side, c.verdict, c.stood,
                            *[got.get(t, "") for t in TESTS]])


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(prog="why_curved.py", description=__doc__,
                                 formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("folders", nargs="*", type=Path,
                    help="folders in the real layout, or a folder of them (default: the dev folders)")
    ap.add_argument("--shapes", default="cylinder,box",
                    help="the classes of objects.csv to show, any of its words (default cylinder,box)")
    ap.add_argument("--limit", type=int, metavar="N", help="only the first N frames of each folder")
    ap.add_argument("--seed", type=int, default=0, help="perception's seed (default 0)")
    ap.add_argument("--set", action="append", default=[], metavar="KEY=VALUE", dest="overrides",
                    help="a depth setting other than its default, as bench_real takes it (repeatable)")
    ap.add_argument("--partial", action="store_true", help="occluded objects (partial yes) too")
    ap.add_argument("--csv", type=Path, metavar="FILE", help="a row per candidate (a row per object without one)")
    args = ap.parse_args(argv)
    if args.limit is not None and args.limit < 1:
        ap.error("--limit must be at least 1")
    shapes = tuple(s.strip() for s in args.shapes.split(",") if s.strip())
    if not shapes:
        ap.error("--shapes names no shape")
    try:
        settings = depth_settings(args.overrides)
    except InputError as e:
        print(f"why_curved.py: error: {e}", file=sys.stderr)
        return 2
    _one_core()
    folders = named_folders(args.folders)
    if not folders:
        print("why_curved.py: no real frames with objects.csv (../shared/data/real): nothing to weigh")
        return 0
    rows: list[dict] = []
    for folder in folders:
        try:
            got = weigh_folder(folder, shapes, args.limit, args.seed, settings, args.partial)
        except InputError as e:
            print(f"why_curved.py: error: {e}", file=sys.stderr)
            return 2
        for row in got:
            print(show(row))
        rows += got
    print(summary(rows, shapes))
    if args.csv:
        write_csv(args.csv, rows)
        print(f"wrote {args.csv}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
