"""Write a synthetic data set (docs/dataset.md, schema ``lv3d.dataset/1``): rendered in parallel,
reproducible from one seed whatever the number of workers, and written atomically."""

from __future__ import annotations

import json
import multiprocessing as mp
import sys
import os
import shutil
from pathlib import Path

import cv2
import numpy as np
from tqdm import tqdm

from ..camera import Intrinsics
from ..errors import InputError
from ..rgbd import RGBD
from .frame import render_scene
from .noise import NoiseConfig, as_config
from .raycast import rays_from_origin
from .solids import CLASSES

SCHEMA = "lv3d.dataset/1"
ITEM_FILES = ("color.png", "depth.png", "faces.png", "meta.json")


def item_seed(seed: int, index: int) -> int:
    """The render seed of item ``index`` of a data set made with ``seed`` (independent of the workers)."""
    return int(np.random.SeedSequence([int(seed), int(index)]).generate_state(1, np.uint64)[0] >> 1)


# Noisy colour and depth hardly compress: Huffman coding alone after one cheap PNG filter is about twice as
# fast as zlib level 1 for the same size; the face mask is mostly zeros, so plain level 1 without a filter.
_HUFFMAN = [cv2.IMWRITE_PNG_COMPRESSION, 1, cv2.IMWRITE_PNG_STRATEGY, cv2.IMWRITE_PNG_STRATEGY_HUFFMAN_ONLY]
PNG_FLAGS = {"color": _HUFFMAN + [cv2.IMWRITE_PNG_FILTER, cv2.IMWRITE_PNG_FILTER_SUB],
             "depth": _HUFFMAN + [cv2.IMWRITE_PNG_FILTER, cv2.IMWRITE_PNG_FILTER_UP],
             "faces": [cv2.IMWRITE_PNG_COMPRESSION, 1, cv2.IMWRITE_PNG_FILTER, cv2.IMWRITE_PNG_FILTER_NONE]}


def write_item(item_dir: Path, frame: RGBD, faces: np.ndarray) -> None:
    """Write one item's four files into the existing folder ``item_dir`` (deterministic bytes)."""
    cv2.imwrite(str(item_dir / "color.png"), np.ascontiguousarray(frame.color[:, :, ::-1]), PNG_FLAGS["color"])
    # float32 suffices: depth holds whole millimetres, far from float32's rounding at 65.535 m
    mm = np.clip(np.rint(frame.depth * np.float32(1000.0)), 0, 65535).astype(np.uint16)
    cv2.imwrite(str(item_dir / "depth.png"), mm, PNG_FLAGS["depth"])
    cv2.imwrite(str(item_dir / "faces.png"), faces, PNG_FLAGS["faces"])
    (item_dir / "meta.json").write_text(json.dumps(frame.meta, indent=1) + "\n")


def _render_job(job: tuple) -> str:
    root, item, cfg, width, height = job
    frame, faces = render_scene(item["class"], item["seed"], cfg, width, height, scene_id=item["id"])
    d = Path(root) / item["dir"]
    d.mkdir()
    write_item(d, frame, faces)
    return item["id"]


def render_job(job: tuple, shared=None) -> str:
    """:func:`_render_job` in the form an executor maps (``fn(job, shared)``; lv3d.experiment.executor)."""
    return _render_job(job)


def _check_args(classes, per_class, seed, workers) -> list[str]:
    if isinstance(classes, str):
        classes = [c for c in classes.split(",") if c]
    classes = list(classes)
    if not classes:
        raise InputError("classes", f"no classes given; known: {', '.join(CLASSES)}")
    for c in classes:
        if c not in CLASSES:
            raise InputError("classes", f"unknown class {c!r}; known: {', '.join(CLASSES)}")
    if len(set(classes)) != len(classes):
        raise InputError("classes", "a class is listed twice")
    if not isinstance(per_class, (int, np.integer)) or per_class < 1:
        raise InputError("per-class", f"need a positive number of images per class, got {per_class!r}")
    if not isinstance(seed, (int, np.integer)) or seed < 0:
        raise InputError("seed", f"seed must be a non-negative integer, got {seed!r}")
    if workers is not None and (not isinstance(workers, (int, np.integer)) or workers < 1):
        raise InputError("workers", f"need at least one worker, got {workers!r}")
    return classes


def _is_finished(out: Path, manifest: dict) -> bool:
    """Does ``out`` hold a finished data set with exactly this manifest?"""
    try:
        old = json.loads((out / "manifest.json").read_text())
    except (OSError, json.JSONDecodeError, UnicodeDecodeError):
        return False
    if old != manifest:
        return False
    return all((out / it["dir"] / f).is_file() for it in manifest["items"] for f in ITEM_FILES)


def make_dataset(out: Path, classes, per_class: int, noise: str | NoiseConfig, seed: int,
                 workers: int | None = None, width: int = 640, height: int = 480, progress: bool = True,
                 executor=None) -> Path:
    """Render ``per_class`` images of each of ``classes`` into ``out`` and return ``out``.

    Items are interleaved by class (s000000 = classes[0], s000001 = classes[1], ...); item i is rendered
    from :func:`item_seed` (seed, i), so the files are byte-identical for any ``workers``. Rendering
    goes into a hidden folder beside ``out`` that is renamed to ``out`` only when all items are written;
    on failure it is removed. An existing non-empty ``out`` is returned as it is when it is a finished
    data set with the same parameters, and is an InputError otherwise. ``executor``: where the items are
    rendered (an object with ``map(fn, jobs)``, as lv3d.experiment.executor makes them: a Dask cluster whose
    workers see ``out``'s folder); by default ``workers`` processes of this machine.
    """
    classes = _check_args(classes, per_class, seed, workers)
    cfg = as_config(noise)
    Intrinsics.realsense_d435(int(width), int(height)).validate("image size")
    out = Path(out)
    items = []
    for i in range(per_class * len(classes)):
        iid = f"s{i:06d}"
        items.append({"id": iid, "class": classes[i % len(classes)], "dir": iid, "seed": item_seed(seed, i)})
    manifest = {"schema": SCHEMA, "classes": classes, "per_class": int(per_class), "noise": cfg.preset,
                "noise_knobs": cfg.to_dict(), "seed": int(seed), "width": int(width), "height": int(height),
                "items": items}
    if out.exists():
        if not out.is_dir():
            raise InputError(out, "exists and is not a folder")
        if any(out.iterdir()):
            if _is_finished(out, manifest):
                return out
            raise InputError(out, "exists and is not empty (nor a finished data set with these parameters); "
                                  "choose another --out or remove it")
    try:
        out.parent.mkdir(parents=True, exist_ok=True)
    except OSError as e:
        raise InputError(out, f"cannot create the parent folder: {e.strerror}") from None
    tmp = out.parent / f".{out.name}.partial-{os.getpid()}"
    shutil.rmtree(tmp, ignore_errors=True)
    try:
        tmp.mkdir()
    except OSError as e:
        raise InputError(out, f"cannot write here: {e.strerror}") from None
    try:
        jobs = [(str(tmp), it, cfg, width, height) for it in items]
        n_workers = min(workers or os.cpu_count() or 1, len(jobs))
        bar = tqdm(total=len(jobs), desc=f"dataset {out.name}", unit="img", disable=not progress)
        if executor is not None:
            for _ in executor.map(render_job, jobs):
                bar.update()
        elif n_workers == 1:
            for job in jobs:
                _render_job(job)
                bar.update()
        else:
            # fork: workers start at once, without importing open3d again; each builds its own scenes.
            # Not once JAX or torch run threads in this process: a forked copy of their locks can deadlock.
            threaded = any(m in sys.modules for m in ("jax", "torch"))
            ctx = mp.get_context("fork" if "fork" in mp.get_all_start_methods() and not threaded else "spawn")
            if ctx.get_start_method() == "fork":  # fill the per-process caches once, before the workers copy them
                rays_from_origin(Intrinsics.realsense_d435(int(width), int(height)))
            with ctx.Pool(n_workers) as pool:
                for _ in pool.imap_unordered(_render_job, jobs, chunksize=1):
                    bar.update()
        bar.close()
        (tmp / "manifest.json").write_text(json.dumps(manifest, indent=1) + "\n")
        if out.exists():
            out.rmdir()  # empty (checked above)
        tmp.rename(out)
    except BaseException:
        shutil.rmtree(tmp, ignore_errors=True)
        raise
    return out
