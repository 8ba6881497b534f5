"""The images of a study and what each system sees of them, computed once and cached on disk.

- the data set: rendered with :func:`lv3d.render.make_dataset` into ``<cache>/<digest>/`` (the
  digest covers classes, per_class, noise and seed), reused when its manifest is there;
- facts: ``<facts root>/<data digest>/<code version>/<modality>-refine<0|1>/<id>.json``, one file
  per image, so the expensive pipeline runs once per (image, modality, refine, version of the
  perception and grounding code) and an interrupted run resumes;
- pixels: ``<cache>/<digest>/pixels-<size>.npz``, the (N, 4, S, S) rgbd tensors of the baselines.
"""

from __future__ import annotations

import json
import os
from concurrent.futures import ProcessPoolExecutor
from multiprocessing import get_context
from pathlib import Path

import numpy as np
from tqdm import tqdm

from ..errors import InputError
from ..facts import SceneFacts
from .code_version import facts_version
from .config import digest
from .folds import Item


def data_key(cfg: dict) -> dict:
    d = cfg["data"]
    return {"classes": d["classes"], "per_class": d["per_class"], "noise": d["noise"],
            "noise_overrides": d["noise_overrides"] or {}, "seed": cfg["seed"]}


def dataset_dir(cfg: dict, out: Path) -> Path:
    root = Path(cfg["data"]["cache"]) if cfg["data"]["cache"] else Path(out) / "data"
    return root / digest(data_key(cfg))


def ensure_dataset(cfg: dict, out: Path) -> Path:
    """Render the study's data set unless it is already there; returns its folder."""
    from ..render import make_dataset
    from ..render.noise import noise_config

    target = dataset_dir(cfg, out)
    if (target / "manifest.json").is_file():
        return target
    d = cfg["data"]
    noise = noise_config(d["noise"], **(d["noise_overrides"] or {}))
    # make_dataset renders into a hidden folder and renames it when complete: no half data set is reused
    make_dataset(target, list(d["classes"]), d["per_class"], noise, cfg["seed"], workers=d["workers"])
    return target


def read_items(data: Path) -> list[Item]:
    path = Path(data) / "manifest.json"
    try:
        manifest = json.loads(path.read_text())
        return [Item(str(it["id"]), str(it["class"]), str(it["dir"])) for it in manifest["items"]]
    except (OSError, json.JSONDecodeError, KeyError, TypeError) as e:
        raise InputError(path, f"cannot read the data set manifest: {e}") from None


def facts_dir(cfg: dict, out: Path, modality: str, refine: bool) -> Path:
    root = Path(cfg["data"]["cache"]) / "facts" if cfg["data"]["cache"] else Path(out) / "facts"
    return root / digest(data_key(cfg)) / facts_version() / f"{modality}-refine{int(refine)}"


def _facts_job(args) -> str:
    """Compute and store the facts of one image (runs in a worker process)."""
    item_dir, scene_id, modality, refine, dest = args
    from ..pipeline import scene_facts
    from ..rgbd import load_item

    try:
        facts = scene_facts(load_item(Path(item_dir)), scene_id, modality, refine=refine, confidences=True)
        record = {"facts": facts.to_json(), "error": None}
    except InputError as e:  # e.g. no object found: the system sees an empty scene, and we count it
        record = {"facts": SceneFacts(scene_id, modality, [], None).to_json(), "error": str(e)}
    tmp = Path(dest).with_suffix(".tmp")
    tmp.write_text(json.dumps(record))
    os.replace(tmp, dest)
    return scene_id


def without_confidences(facts: SceneFacts) -> SceneFacts:
    """Every confidence set to 1: what ``scene_facts(confidences=False)`` returns, derived from the
    cached facts so that the ablation does not rerun the pipeline."""
    return SceneFacts(facts.scene, facts.modality, [type(f)(f.pred, f.args, 1.0, f.value) for f in facts.facts],
                      facts.target)


def ensure_facts(cfg: dict, out: Path, data: Path, items: list[Item], modality: str, refine: bool,
                 confidences: bool = True, workers: int = 1) -> tuple[dict[str, SceneFacts], dict[str, str]]:
    """Facts of every item for one modality: ({id: SceneFacts}, {id: error} for scenes the pipeline
    could not read). Missing cache entries are computed (in ``workers`` processes)."""
    dest = facts_dir(cfg, out, modality, refine)
    dest.mkdir(parents=True, exist_ok=True)
    todo = [(str(data / it.dir), it.id, modality, refine, str(dest / f"{it.id}.json"))
            for it in items if not (dest / f"{it.id}.json").is_file()]
    if todo:
        desc = f"facts {modality} refine={refine}"
        if workers > 1:
            with ProcessPoolExecutor(workers, mp_context=get_context("spawn")) as pool:
                for _ in tqdm(pool.map(_facts_job, todo), total=len(todo), desc=desc):
                    pass
        else:
            for job in tqdm(todo, desc=desc):
                _facts_job(job)
    facts, errors = {}, {}
    for it in items:
        path = dest / f"{it.id}.json"
        record = json.loads(path.read_text())
        sf = SceneFacts.from_json(record["facts"], str(path))
        facts[it.id] = sf if confidences else without_confidences(sf)
        if record["error"]:
            errors[it.id] = record["error"]
    return facts, errors


def ensure_pixels(data: Path, items: list[Item], size: int) -> dict[str, np.ndarray]:
    """{id: (4, size, size) float32 rgbd tensor}; slice [:3] for rgb, [3:] for depth."""
    from ..baselines.pixels import frame_tensor
    from ..rgbd import load_item

    path = Path(data) / f"pixels-{size}.npz"
    if path.is_file():
        z = np.load(path)
        have = dict(zip(z["ids"].tolist(), z["x"]))
        if all(it.id in have for it in items):
            return {it.id: have[it.id] for it in items}
    x = np.stack([frame_tensor(load_item(Path(data) / it.dir), "rgbd", size)
                  for it in tqdm(items, desc=f"pixels {size}x{size}")])
    tmp = path.with_name(path.stem + ".tmp.npz")
    np.savez_compressed(tmp, ids=np.array([it.id for it in items]), x=x)
    os.replace(tmp, path)
    return {it.id: x[i] for i, it in enumerate(items)}
