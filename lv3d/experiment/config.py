"""Study configs: one YAML file per study (experiments/*.yaml), validated against a fixed schema.

A config is a nested mapping; ``DEFAULTS`` lists every key a study may set, with its default.
Anything else is an error that names the file and the key. Overrides use dotted keys
(``--set train.positives=8``) whose values are parsed as YAML. A study is one or more
*conditions*: a single one (``base``), a ``sweep`` of one key over values, or named
``conditions`` each overriding some keys (the ablations).
"""

from __future__ import annotations

import copy
import hashlib
import json
import re
from pathlib import Path

import yaml

from ..errors import InputError

LOGIC_SYSTEMS = ("lv3d-rgb", "lv3d-depth", "lv3d-rgbd")
BASELINE_SYSTEMS = ("cnn-rgb", "cnn-depth", "cnn-rgbd", "cnn-rgbd-2s", "tree-rgb", "tree-depth", "tree-rgbd")
SYSTEMS = LOGIC_SYSTEMS + BASELINE_SYSTEMS

DEFAULTS: dict = {
    "name": "study",
    "seed": 0,
    "folds": 5,
    "data": {
        "classes": ["cube", "square_pyramid", "triangular_prism", "pentagonal_prism"],
        "per_class": 50,
        "noise": "realsense",       # a preset of lv3d.render.noise
        "noise_overrides": {},      # knob -> value, on top of the preset
        "cache": None,              # a folder shared between studies; default: <out>/data
        "workers": None,            # rendering processes (None: the renderer's default)
    },
    "train": {
        "positives": 40,                # per class task; capped by what the training folds hold
        "negatives_per_positive": 1.5,  # spread evenly over the other classes (40 -> 20 of each of 3)
        "multiclass": True,             # also train on all classes at once and report multi-class accuracy
        "draws": 1,                     # training samples drawn per task and fold; scores are their means
    },
    "systems": list(SYSTEMS),
    "lv3d": {
        "refine": True,            # JAX refinement before facts (False: the no-refinement ablation)
        "confidences": True,       # facts keep their confidences (False: every confidence is 1)
        "settings": {},            # lv3d.learn Settings fields, e.g. {label_noise: false}
        "workers": 1,              # processes computing facts
    },
    "baselines": {
        # CNN settings: see lv3d.baselines.cnn.CNNSettings (why 1 thread, 20 epochs, no augmentation)
        "image_size": 64, "epochs": 20, "batch_size": 16, "lr": 0.003, "weight_decay": 0.0001,
        "augment": False, "width": 16, "threads": 1, "tree_cells": 16, "tree_min_samples_leaf": 2,
        "patience": 0, "val_fraction": 0.15,  # early stopping (off: patience 0)
    },
    "stats": {
        "pairs": None,             # [[a, b], ...]; default: every lv3d pair, and lv3d-rgbd against each baseline
    },
    "sweep": None,                 # {param: dotted key, values: [...]}
    "conditions": None,            # {name: {dotted key: value}}
}

# keys whose value is a free-form mapping (checked elsewhere), not a schema section
_FREE = {("data", "noise_overrides"), ("lv3d", "settings")}


def _check(cfg: dict, schema: dict, where: Path, prefix: str = "") -> None:
    for key, value in cfg.items():
        path = f"{prefix}{key}"
        if key not in schema:
            known = ", ".join(sorted(schema))
            raise InputError(where, f"unknown key {path!r}; known here: {known}")
        if isinstance(schema[key], dict) and tuple(path.split(".")) not in _FREE:
            if not isinstance(value, dict):
                raise InputError(where, f"{path!r} must be a mapping")
            _check(value, schema[key], where, path + ".")


def _merge(base: dict, over: dict) -> dict:
    out = copy.deepcopy(base)
    for k, v in over.items():
        if isinstance(v, dict) and isinstance(out.get(k), dict) and k not in ("noise_overrides", "settings"):
            out[k] = _merge(out[k], v)
        else:
            out[k] = copy.deepcopy(v)
    return out


def set_dotted(cfg: dict, key: str, value, where: str | Path) -> None:
    """Set ``a.b.c`` in a nested mapping; the key must exist in the schema (free mappings excepted)."""
    parts = key.split(".")
    node, schema = cfg, DEFAULTS
    for i, p in enumerate(parts[:-1]):
        if tuple(parts[:i + 1]) in _FREE:  # a knob or learner setting: any name, checked later
            node = node.setdefault(p, {})
            schema = None
            continue
        if schema is None or p not in schema or not isinstance(schema[p], dict):
            raise InputError(where, f"unknown key {key!r}")
        node, schema = node.setdefault(p, {}), schema[p]
    if schema is not None and parts[-1] not in schema:
        raise InputError(where, f"unknown key {key!r}")
    node[parts[-1]] = value


_EXPONENT = re.compile(r"[-+]?(\d+\.?\d*|\.\d+)[eE][-+]?\d+")


def parse_override(text: str) -> tuple[str, object]:
    """``key=value`` with the value parsed as YAML (``8``, ``false``, ``[1, 2]``)."""
    if "=" not in text:
        raise InputError("--set", f"expected key=value, got {text!r}")
    key, raw = text.split("=", 1)
    if _EXPONENT.fullmatch(raw.strip()):  # YAML 1.1 reads 1e-3 (no dot) as a string
        return key.strip(), float(raw)
    try:
        return key.strip(), yaml.safe_load(raw)
    except yaml.YAMLError as e:
        raise InputError("--set", f"cannot parse the value of {key!r}: {e}") from None


def validate(cfg: dict, where: Path) -> None:
    """Types and names: classes, presets, knobs and systems must exist (InputError naming the key)."""
    from ..render.noise import noise_config
    from ..render.solids import CLASSES

    def need(ok: bool, key: str, problem: str):
        if not ok:
            raise InputError(where, f"{key}: {problem}")

    for key in ("seed", "folds"):
        need(isinstance(cfg[key], int) and not isinstance(cfg[key], bool), key, "must be an integer")
    need(cfg["folds"] >= 2, "folds", "needs at least 2 folds")
    d = cfg["data"]
    need(isinstance(d["classes"], list) and len(d["classes"]) >= 2, "data.classes", "needs a list of at least 2 classes")
    for c in d["classes"]:
        need(c in CLASSES, "data.classes", f"unknown class {c!r}; known: {', '.join(CLASSES)}")
    need(len(set(d["classes"])) == len(d["classes"]), "data.classes", "lists a class twice")
    need(isinstance(d["per_class"], int) and d["per_class"] >= cfg["folds"], "data.per_class",
         f"must be an integer of at least folds ({cfg['folds']})")
    try:
        noise_config(d["noise"], **(d["noise_overrides"] or {}))
    except InputError as e:
        key = "data.noise" if e.problem.startswith("unknown noise preset") else "data.noise_overrides"
        raise InputError(where, f"{key}: {e.problem}") from None
    except TypeError as e:
        raise InputError(where, f"data.noise_overrides: {e}") from None
    t = cfg["train"]
    need(isinstance(t["positives"], int) and t["positives"] >= 1, "train.positives", "must be a positive integer")
    need(isinstance(t["negatives_per_positive"], (int, float)) and t["negatives_per_positive"] > 0,
         "train.negatives_per_positive", "must be a positive number")
    need(isinstance(t["draws"], int) and not isinstance(t["draws"], bool) and t["draws"] >= 1, "train.draws",
         "must be a positive integer")
    need(isinstance(cfg["systems"], list) and cfg["systems"], "systems", "needs a non-empty list")
    for s in cfg["systems"]:
        need(s in SYSTEMS, "systems", f"unknown system {s!r}; known: {', '.join(SYSTEMS)}")
    need(isinstance(cfg["lv3d"]["settings"], dict), "lv3d.settings", "must be a mapping")
    pairs = cfg["stats"]["pairs"]
    if pairs is not None:
        for p in pairs:
            need(isinstance(p, list) and len(p) == 2 and all(s in cfg["systems"] for s in p), "stats.pairs",
                 f"{p!r} is not a pair of systems of this study")
    b = cfg["baselines"]
    need(b["image_size"] % b["tree_cells"] == 0, "baselines.tree_cells", "must divide baselines.image_size")


def conditions(cfg: dict, where: Path) -> dict[str, dict]:
    """The study's conditions: name -> fully merged and validated config."""
    sweep, named = cfg.get("sweep"), cfg.get("conditions")
    if sweep is not None and named is not None:
        raise InputError(where, "sweep and conditions: give one or the other")
    out: dict[str, dict] = {}
    if sweep is not None:
        if not isinstance(sweep, dict) or set(sweep) != {"param", "values"} or not isinstance(sweep["values"], list):
            raise InputError(where, "sweep: must be {param: dotted key, values: [...]}")
        for v in sweep["values"]:
            c = copy.deepcopy(cfg)
            set_dotted(c, sweep["param"], v, f"{where}: sweep.param")
            out[f"{sweep['param'].split('.')[-1]}={v}"] = c
    elif named is not None:
        if not isinstance(named, dict) or not named:
            raise InputError(where, "conditions: must map names to {dotted key: value}")
        for name, overrides in named.items():
            c = copy.deepcopy(cfg)
            for k, v in (overrides or {}).items():
                set_dotted(c, k, v, f"{where}: conditions.{name}")
            out[str(name)] = c
    else:
        out["base"] = copy.deepcopy(cfg)
    for c in out.values():
        c["sweep"] = c["conditions"] = None
        validate(c, where)
    return out


def load_config(path: Path, overrides: list[str] = ()) -> dict:
    """Read, merge with defaults, apply ``key=value`` overrides, validate; returns the full config."""
    path = Path(path)
    if not path.is_file():
        raise InputError(path, "config file not found")
    try:
        raw = yaml.safe_load(path.read_text()) or {}
    except yaml.YAMLError as e:
        raise InputError(path, f"not valid YAML: {e}") from None
    if not isinstance(raw, dict):
        raise InputError(path, "a config must be a mapping at the top level")
    _check(raw, DEFAULTS, path)
    cfg = _merge(DEFAULTS, raw)
    for text in overrides:
        key, value = parse_override(text)
        set_dotted(cfg, key, value, f"{path}: --set")
    conditions(cfg, path)  # validates every condition now, before any work
    return cfg


def digest(obj) -> str:
    """A short stable hash of JSON-able data (cache keys, resume checks)."""
    return hashlib.sha256(json.dumps(obj, sort_keys=True, default=str).encode()).hexdigest()[:12]
