"""The images of a study and what each system sees of them, computed once and cached on disk.

- the data set: rendered with :func:`lv3d.render.make_dataset` into ``<cache>/<digest>/`` (the
  digest covers classes, per_class, noise and seed), reused when its manifest is there;
- facts: ``<facts root>/<data digest>/<code version>/<modality>-refine<0|1>/<id>.json``, one file
  per image, so the expensive pipeline runs once per (image, modality, refine, version of the
  perception and grounding code) and an interrupted run resumes;
- pixels: ``<cache>/<digest>/pixels-<size>.npz``, the (N, 4, S, S) rgbd tensors of the baselines.

A cache file that cannot be read (cut short, corrupt) is computed again. Rendering into a cache folder
holds its lock (lv3d.output), so that two studies sharing a cache render a data set once; what a killed
run left half-made there is removed first.
"""

from __future__ import annotations

import hashlib
import io
import json
import zipfile
from pathlib import Path

import numpy as np
from tqdm import tqdm

from ..errors import InputError
from ..facts import SceneFacts
from ..output import clean_stale, locked, write_atomic
from .code_version import facts_version
from .config import StudyConfig, digest
from .executor import cache_missing
from .folds import Item


def data_key(cfg: StudyConfig) -> dict:
    d = cfg.data
    return {"classes": list(d.classes), "per_class": d.per_class, "noise": d.noise,
            "noise_overrides": dict(d.noise_overrides or {}), "seed": cfg.seed}


def cache_root(cfg: StudyConfig, out: Path) -> Path:
    return Path(cfg.data.cache).expanduser() if cfg.data.cache else Path(out) / "data"


def dataset_dir(cfg: StudyConfig, out: Path) -> Path:
    return cache_root(cfg, out) / digest(data_key(cfg))


def ensure_dataset(cfg: StudyConfig, out: Path) -> Path:
    """Render the study's data set unless it is already there; returns its folder."""
    from ..render import make_dataset
    from ..render.noise import noise_config

    target = dataset_dir(cfg, out)
    if (target / "manifest.json").is_file():
        return target
    root = target.parent
    try:
        root.mkdir(parents=True, exist_ok=True)
    except OSError as e:
        raise InputError(f"data.cache {root}", f"cannot create the folder: {e.strerror}") from None
    with locked(root, f"data cache {root}", wait=True):  # another study rendering into the same cache: wait
        if (target / "manifest.json").is_file():
            return target
        clean_stale(root, target.name)  # a killed rendering's .NAME.partial-PID folder
        d = cfg.data
        noise = noise_config(d.noise, **dict(d.noise_overrides or {}))
        # make_dataset renders into a hidden folder and renames it when complete: no half data set is reused
        make_dataset(target, list(d.classes), d.per_class, noise, cfg.seed, workers=d.workers)
    return target


def read_items(data: Path) -> list[Item]:
    path = Path(data) / "manifest.json"
    try:
        manifest = json.loads(path.read_text())
        return [Item(str(it["id"]), str(it["class"]), str(it["dir"])) for it in manifest["items"]]
    except (OSError, UnicodeDecodeError, json.JSONDecodeError, KeyError, TypeError) as e:
        raise InputError(path, f"cannot read the data set manifest: {e}") from None


def seed_suffix(seed: int) -> str:
    """What a cache name gains for a perception seed other than 0: ``-seed<s>`` (the default's names stay)."""
    return f"-seed{seed}" if seed else ""


def depth_suffix(depth: dict | None) -> str:
    """What a cache name gains for depth settings other than the defaults (``lv3d.depth``, flat and sorted):
    ``-depth<8 hex digits of their digest>`` (the default's names stay)."""
    return f"-depth{digest(dict(depth))[:8]}" if depth else ""


def facts_variant(modality: str, refine: bool, seed: int = 0, depth: dict | None = None) -> str:
    """The cache folder of one way of computing facts: ``<modality>-refine<0|1>`` with :func:`seed_suffix` and
    :func:`depth_suffix`."""
    return f"{modality}-refine{int(refine)}" + seed_suffix(seed) + depth_suffix(depth)


def facts_dir(cfg: StudyConfig, out: Path, modality: str, refine: bool) -> Path:
    root = Path(cfg.data.cache).expanduser() / "facts" if cfg.data.cache else Path(out) / "facts"
    lv = cfg.lv3d
    return root / digest(data_key(cfg)) / facts_version() / facts_variant(modality, refine, lv.perception_seed,
                                                                          lv.depth)


def facts_job(job: tuple, shared=None) -> dict:
    """The cache record of one image's facts: ``{"facts": ..., "error": None or why the pipeline found
    nothing}`` (runs in a worker; the caller writes it)."""
    item_dir, scene_id, modality, refine, seed, depth = job
    from ..pipeline import scene_facts
    from ..rgbd import load_item

    try:
        facts = scene_facts(load_item(Path(item_dir)), scene_id, modality, refine=refine, confidences=True,
                            seed=seed, depth=depth)
        return {"facts": facts.to_json(), "error": None}
    except InputError as e:  # e.g. no object found: the system sees an empty scene, and we count it
        return {"facts": SceneFacts(scene_id, modality, [], None).to_json(), "error": str(e)}


def _read_facts(path: Path) -> tuple[SceneFacts, str | None] | None:
    """A cached record, or None when the file is missing or unreadable (it is then computed again)."""
    try:
        record = json.loads(path.read_text())
        return SceneFacts.from_json(record["facts"], str(path)), record["error"]
    except (OSError, UnicodeDecodeError, ValueError, KeyError, TypeError, InputError):
        return None


def without_confidences(facts: SceneFacts) -> SceneFacts:
    """Every confidence set to 1: what ``scene_facts(confidences=False)`` returns, derived from the
    cached facts so that the ablation does not rerun the pipeline."""
    return SceneFacts(facts.scene, facts.modality, [type(f)(f.pred, f.args, 1.0, f.value) for f in facts.facts],
                      facts.target)


def ensure_facts(cfg: StudyConfig, out: Path, data: Path, items: list[Item], modality: str, refine: bool,
                 confidences: bool = True, workers: int = 1, executor=None
                 ) -> tuple[dict[str, SceneFacts], dict[str, str]]:
    """Facts of every item for one modality: ({id: SceneFacts}, {id: error} for scenes the pipeline
    could not read). Missing or unreadable cache entries are computed (on ``executor``, default ``workers``
    local processes) and written here as they come back."""
    dest = facts_dir(cfg, out, modality, refine)
    dest.mkdir(parents=True, exist_ok=True)
    clean_stale(dest)
    have = {it.id: _read_facts(dest / f"{it.id}.json") for it in items}
    todo = [it for it in items if have[it.id] is None]
    jobs = [(str(Path(data) / it.dir), it.id, modality, refine, cfg.lv3d.perception_seed, cfg.lv3d.depth)
            for it in todo]
    for name, record in cache_missing(dest, [it.id for it in todo], facts_job, jobs,
                                      f"facts {modality} refine={refine}", workers, executor):
        have[name] = (SceneFacts.from_json(record["facts"], name), record["error"])
    facts, errors = {}, {}
    for it in items:
        sf, error = have[it.id]
        facts[it.id] = sf if confidences else without_confidences(sf)
        if error:
            errors[it.id] = error
    return facts, errors


def facts_digest(facts: dict[str, SceneFacts]) -> str:
    """A 16-hex digest of what an lv3d system learns from and is tested on: every example's facts (their
    content, in id order), whichever code made them. Part of an lv3d fold result's key (runner.result_key)."""
    h = hashlib.sha256()
    for key in sorted(facts):
        h.update(json.dumps([key, facts[key].to_json()], sort_keys=True, separators=(",", ":")).encode())
    return h.hexdigest()[:16]


def read_pixels(path: Path, items: list[Item], size: int) -> dict[str, np.ndarray] | None:
    try:
        with np.load(path) as z:
            have = dict(zip(z["ids"].tolist(), z["x"]))
    except (OSError, EOFError, ValueError, KeyError, zipfile.BadZipFile):
        return None  # cut short or corrupt: computed again
    if not all(it.id in have and have[it.id].shape == (4, size, size) for it in items):
        return None
    return {it.id: have[it.id] for it in items}


def ensure_pixels(data: Path, items: list[Item], size: int) -> dict[str, np.ndarray]:
    """{id: (4, size, size) float32 rgbd tensor}; slice [:3] for rgb, [3:] for depth."""
    from ..baselines.pixels import frame_tensor
    from ..rgbd import load_item

    path = Path(data) / f"pixels-{size}.npz"
    if path.is_file():
        got = read_pixels(path, items, size)
        if got is not None:
            return got
    x = np.stack([frame_tensor(load_item(Path(data) / it.dir), "rgbd", size)
                  for it in tqdm(items, desc=f"pixels {size}x{size}")])
    write_pixels(path, [it.id for it in items], x)
    return {it.id: x[i] for i, it in enumerate(items)}


def write_pixels(path: Path, ids: list[str], x: np.ndarray) -> None:
    """The pixel cache file: ``ids`` and their (N, 4, S, S) tensors ``x``, written whole or not at all."""
    buf = io.BytesIO()
    np.savez_compressed(buf, ids=np.array(ids), x=x)
    Path(path).parent.mkdir(parents=True, exist_ok=True)
    write_atomic(path, buf.getvalue())
