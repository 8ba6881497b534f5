"""Study configs: one YAML file per study (experiments/*.yaml), read once into frozen dataclasses.

:func:`load_study` reads the file, fills in the defaults, applies ``--set key=value`` overrides (dotted
keys, values parsed as YAML), expands the study's *conditions* (a single one, ``base``; a ``sweep`` of
one key over values; or named ``conditions`` each overriding some keys) and checks every value of every
condition: its type, its range and, for names (classes, noise presets and knobs, systems, learner
settings), that it exists. Any problem is one :class:`~lv3d.errors.InputError` naming the file and the
key, raised before any work. What the runner, the data cache and the systems then read is a
:class:`StudyConfig`, typed and known to be valid.

Each field of a section carries its check (kind, range, known names) in its metadata; the ranges are
what lv3d can run in bounded time and memory (:mod:`lv3d.limits`), not what a study should use.
"""

from __future__ import annotations

import copy
import hashlib
import json
import math
import re
from collections import Counter
from dataclasses import dataclass, field, fields, replace
from pathlib import Path
from typing import Callable

import yaml

from ..errors import InputError
from ..frame_folder import FrameFolder
from ..limits import MAX_DATASET_IMAGES

LOGIC_SYSTEMS = ("lv3d-rgb", "lv3d-depth", "lv3d-rgbd")
BASELINE_SYSTEMS = ("cnn-rgb", "cnn-depth", "cnn-rgbd", "cnn-rgbd-2s", "tree-rgb", "tree-depth", "tree-rgbd",
                    "effnet-rgb", "effnet-depth", "effnet-rgbd")
# BaselineConfig's keys that only the effnet-* systems read: left out of the other baselines' result keys
EFFNET_KEYS = ("effnet_c", "effnet_input_size")
SYSTEMS = LOGIC_SYSTEMS + BASELINE_SYSTEMS
MAX_FOLDS = 100
MAX_WORKERS = 256
# a condition names a folder of the run (folds/<condition>/...): no separators, no "." or ".."
_CONDITION_NAME = re.compile(r"^[A-Za-z0-9_+=.,-]+$")


def _classes() -> tuple[str, ...]:
    from ..render.solids import CLASSES

    return tuple(CLASSES)


def _presets() -> tuple[str, ...]:
    from ..render.noise import PRESETS

    return tuple(PRESETS)


# ---- field specs: what a value must be ------------------------------------------------------------------

def _spec(default, kind: str, *, lo=None, hi=None, lo_open=False, names: Callable[[], tuple] | tuple | None = None,
          optional=False, min_len=0, doc=""):
    meta = {"kind": kind, "lo": lo, "hi": hi, "lo_open": lo_open, "names": names, "optional": optional,
            "min_len": min_len, "doc": doc}
    if isinstance(default, (list, dict, tuple)):
        return field(default_factory=lambda: copy.deepcopy(default), metadata=meta)
    return field(default=default, metadata=meta)


def _int(default, lo=None, hi=None, optional=False, doc=""):
    return _spec(default, "int", lo=lo, hi=hi, optional=optional, doc=doc)


def _num(default, lo=None, hi=None, lo_open=False, doc=""):
    return _spec(default, "number", lo=lo, hi=hi, lo_open=lo_open, doc=doc)


def _bool(default, doc=""):
    return _spec(default, "bool", doc=doc)


def _is_int(v) -> bool:
    return isinstance(v, int) and not isinstance(v, bool)


def is_number(v) -> bool:
    """A finite int or float (not a bool)."""
    return isinstance(v, (int, float)) and not isinstance(v, bool) and math.isfinite(v)


def _range_text(lo, hi, lo_open=False) -> str:
    if lo is not None and hi is not None:
        return f"{'above' if lo_open else 'from'} {lo} {'and at most' if lo_open else 'to'} {hi}"
    if lo is not None:
        return f"{'above' if lo_open else 'at least'} {lo}"
    return f"at most {hi}"


def check_value(value, meta: dict, key: str, where: str):
    """``value`` checked against a field spec; returns it (lists as tuples). InputError naming ``key``."""
    kind = meta["kind"]

    def bad(problem: str):
        raise InputError(where, f"{key}: {problem}, got {value!r}")

    if value is None and meta["optional"]:
        return None
    lo, hi, lo_open = meta["lo"], meta["hi"], meta["lo_open"]
    if kind in ("int", "number"):
        ok = _is_int(value) if kind == "int" else is_number(value)
        if not ok:
            bad("must be a whole number" if kind == "int" else "must be a number")
        if (lo is not None and (value <= lo if lo_open else value < lo)) or (hi is not None and value > hi):
            bad(f"must be {_range_text(lo, hi, lo_open)}")
        return value
    if kind == "bool":
        if not isinstance(value, bool):
            bad("must be true or false")
        return value
    if kind == "str":
        if not isinstance(value, str) or not value.strip():
            bad("must be a non-empty text")
        return value
    if kind == "path":
        if not isinstance(value, str) or not value.strip() or "\0" in value:
            bad("must be a folder (a path)")
        return value
    if kind == "paths":
        if not isinstance(value, (list, tuple)) or not value:
            bad("must be a non-empty list of folders")
        for v in value:
            if not isinstance(v, str) or not v.strip() or "\0" in v:
                raise InputError(where, f"{key}: {v!r} is not a folder (a path)")
        if len(set(value)) != len(value):
            bad("lists a folder twice")
        return tuple(value)
    def name_list(item_problem) -> tuple:
        """``value`` as a list of names, each passing ``item_problem`` (None, or what is wrong with it), none
        twice, at least ``min_len`` of them."""
        if not isinstance(value, (list, tuple)):
            bad("must be a list")
        for v in value:
            problem = item_problem(v)
            if problem is not None:
                raise InputError(where, f"{key}: {problem}")
        if len(set(value)) != len(value):
            bad("lists a name twice")
        if len(value) < meta["min_len"]:
            bad(f"needs a list of at least {meta['min_len']}")
        return tuple(value)

    if kind == "labels":  # class names: words here; which names exist depends on the data (checked in from_dict)
        return name_list(lambda v: None if isinstance(v, str) and re.fullmatch(r"[a-z][a-z0-9_]*", v)
                         else f"{v!r} is not a class name (a lower-case word)")
    names = meta["names"]() if callable(meta["names"]) else meta["names"]
    if kind == "name":
        if not isinstance(value, str) or value not in names:
            bad(f"must be one of {', '.join(names)}")
        return value
    if kind == "names":
        return name_list(lambda v: None if isinstance(v, str) and v in names
                         else f"unknown name {v!r}; known: {', '.join(names)}")
    if kind in ("ints", "bools"):  # a grid of values: a non-empty list, each value checked, none twice
        if not isinstance(value, (list, tuple)) or not value:
            bad("must be a non-empty list")
        for v in value:
            if kind == "bools" and not isinstance(v, bool):
                raise InputError(where, f"{key}: each value must be true or false, got {v!r}")
            if kind == "ints" and (not _is_int(v) or (lo is not None and v < lo) or (hi is not None and v > hi)):
                raise InputError(where, f"{key}: each value must be a whole number {_range_text(lo, hi)}, got {v!r}")
        if len(set(value)) != len(value):
            bad("lists a value twice")
        return tuple(value)
    if kind == "mapping":
        if not isinstance(value, dict):
            bad("must be a mapping")
        return dict(value)
    raise AssertionError(kind)


# ---- the sections ---------------------------------------------------------------------------------------

# how a study on folders of real frames makes its folds (DataConfig.split)
SPLITS = ("frames", "folders")


@dataclass(frozen=True)
class DataConfig:
    """The examples of the study: images rendered once, cached by (classes, per_class, noise, seed); or, with
    ``folders``, the labelled objects of real frames (lv3d.frame_folder), each object one example."""

    classes: tuple | None = _spec(("cube", "square_pyramid", "triangular_prism", "pentagonal_prism"), "labels",
                                  names=_classes, min_len=2, optional=True,
                                  doc="rendered classes; with folders, the objects.csv shapes to learn (others left "
                                      "out), None: every shape of them but other (learnable_classes)")
    folders: tuple | None = _spec(None, "paths", optional=True,
                                  doc="folders of labelled real frames (relative to the working directory); "
                                      "None: a rendered data set")
    split: str = _spec("frames", "name", names=SPLITS,
                       doc="with folders: the folds grouped by frame (frames: `folds` of them, no frame in two) or one "
                           "per folder (folders: learn from the other folders, test on it: another sensor or room)")
    per_class: int = _int(50, 1, MAX_DATASET_IMAGES // 2, doc="images per class (rendered only)")
    noise: str = _spec("realsense", "name", names=_presets, doc="a preset of lv3d.render.noise")
    noise_overrides: dict = _spec({}, "mapping", doc="knob -> value, on top of the preset")
    cache: str | None = _spec(None, "path", optional=True, doc="a folder shared between studies; None: <out>/data")
    workers: int | None = _int(None, 1, MAX_WORKERS, optional=True, doc="rendering processes (None: all cores)")


@dataclass(frozen=True)
class TrainConfig:
    positives: int = _int(40, 1, MAX_DATASET_IMAGES, doc="per class task; capped by the training folds")
    negatives_per_positive: float = _num(1.5, 0, 1000, lo_open=True, doc="spread evenly over the other classes")
    multiclass: bool = _bool(True, doc="also train on all classes at once and report multi-class accuracy")
    draws: int = _int(1, 1, 1000, doc="training samples drawn per task and fold; scores are their means")


@dataclass(frozen=True)
class Lv3dConfig:
    refine: bool = _bool(True, doc="JAX refinement before facts (false: the no-refinement ablation)")
    confidences: bool = _bool(True, doc="facts keep their confidences (false: every confidence is 1)")
    perception_seed: int = _int(0, 0, 2 ** 31 - 1, doc="seed of perception's sample consensus (0: as lv3d extract)")
    settings: dict = _spec({}, "mapping", doc="learner settings (lv3d.learn.settings), e.g. {time_limit: 20}")
    depth: dict = _spec({}, "mapping", doc="depth-stage settings other than the defaults, by dotted key "
                                           "(lv3d.perception.depth.with_overrides), e.g. {sensor.base_m: 0.006}")
    workers: int = _int(1, 1, MAX_WORKERS, doc="processes computing facts")


@dataclass(frozen=True)
class BaselineConfig:
    """CNN and tree settings: see lv3d.baselines.cnn.CNNSettings (why 1 thread, 20 epochs, no augmentation)."""

    image_size: int = _int(64, 8, 512, doc="pixels a side of the baselines' input")
    epochs: int = _int(20, 1, 10000)
    batch_size: int = _int(16, 2, 4096, doc="batch norm needs two samples")
    lr: float = _num(0.003, 0, 10, lo_open=True)
    weight_decay: float = _num(0.0001, 0, 1)
    augment: bool = _bool(False)
    width: int = _int(16, 1, 1024, doc="channels of the first layer")
    threads: int = _int(1, 1, MAX_WORKERS)
    tree_cells: int = _int(16, 1, 512, doc="cells a side the tree sees; divides image_size")
    tree_min_samples_leaf: int = _int(2, 1, 100000)
    patience: int = _int(0, 0, 10000, doc="early stopping (0: off)")
    val_fraction: float = _num(0.15, 0, 0.9)
    # The pretrained baseline (effnet-*: lv3d.baselines.pretrained.PretrainedSettings says why these values);
    # it runs its network on ``threads`` CPU threads.
    effnet_c: float = _num(0.1, 0, 1e6, lo_open=True,
                           doc="inverse L2 strength of the logistic regression on standardised features")
    effnet_input_size: int = _int(224, 32, 1024, doc="pixels a side of the network's input (tensors resized "
                                                     "bilinearly; 224: the weights' own resolution)")
    # Tuning (lv3d.baselines.tuning, experiments/README.md "Tuning the CNN"): per outer fold, on its training
    # examples only, the CNN's width, epochs, augmentation and input size are chosen from this grid by grouped
    # inner cross-validation of the multi-class task; they then replace width, epochs, augment and image_size
    # for every task of that fold. The default grid: the fixed setting (16 channels, 20 epochs, no augmentation,
    # 64 px), half and twice its width, twice its epochs, augmentation on, half its input size; its search costs
    # about 4.4 min of one core per outer fold for cnn-rgbd and 8.2 min for cnn-rgbd-2s (experiments/README.md).
    tune: bool = _bool(False, doc="tune the CNNs per outer fold (false: the fixed settings above)")
    tune_width: tuple = _spec((8, 16, 32), "ints", lo=1, hi=1024, doc="channels of the first layer tried")
    tune_epochs: tuple = _spec((20, 40), "ints", lo=1, hi=10000, doc="epochs tried")
    tune_augment: tuple = _spec((False, True), "bools", doc="augmentation off and/or on (lv3d.baselines.augment)")
    tune_image_size: tuple = _spec((32, 64), "ints", lo=8, hi=512,
                                   doc="input pixels a side tried; each divides image_size (the cached tensors "
                                       "area-downsampled by a whole factor); 8 at least: the stem halves the "
                                       "input and two 2x2 pools follow")
    tune_folds: int = _int(3, 2, 20, doc="inner cross-validation folds (groups of examples never split; one a group "
                                                  "where the training folds hold fewer)")


# BaselineConfig's tuning keys: left out of a result's key where they cannot change it (runner.result_key)
TUNE_KEYS = ("tune", "tune_width", "tune_epochs", "tune_augment", "tune_image_size", "tune_folds")


@dataclass(frozen=True)
class StatsConfig:
    pairs: tuple | None = _spec(None, "pairs", optional=True,
                                doc="[[a, b], ...]; default: every lv3d pair, and lv3d-rgbd against each baseline")


SECTIONS = {"data": DataConfig, "train": TrainConfig, "lv3d": Lv3dConfig, "baselines": BaselineConfig,
            "stats": StatsConfig}
# mappings whose keys are names checked elsewhere (noise knobs, learner settings, depth settings), not schema keys
FREE = {("data", "noise_overrides"), ("lv3d", "settings"), ("lv3d", "depth")}
# a free mapping whose keys are dotted themselves (``lv3d.depth.sensor.base_m`` sets its key ``sensor.base_m``)
DOTTED_FREE = ("lv3d", "depth")


@dataclass(frozen=True)
class StudyConfig:
    """One condition of a study, every value checked. ``to_dict()`` is the YAML form."""

    name: str = _spec("study", "str")
    seed: int = _int(0, 0, 2 ** 32 - 1)
    folds: int = _int(5, 2, MAX_FOLDS)
    data: DataConfig = field(default_factory=DataConfig)
    train: TrainConfig = field(default_factory=TrainConfig)
    systems: tuple = _spec(SYSTEMS, "names", names=SYSTEMS, min_len=1)
    lv3d: Lv3dConfig = field(default_factory=Lv3dConfig)
    baselines: BaselineConfig = field(default_factory=BaselineConfig)
    stats: StatsConfig = field(default_factory=StatsConfig)
    # derived, no YAML key: the classes of data.classes left out of a study on folders for being labelled in fewer
    # frames than folds, each with its number of labelled objects (from_dict, learnable_classes)
    left_out_classes: tuple = field(default=(), metadata={"derived": True})

    def to_dict(self) -> dict:
        """Plain nested mappings and lists (what the YAML holds, and what cache keys digest)."""
        return _plain(self)


def _plain(obj):
    if hasattr(obj, "__dataclass_fields__"):
        return {f.name: _plain(getattr(obj, f.name)) for f in fields(obj) if not f.metadata.get("derived")}
    if isinstance(obj, (list, tuple)):
        return [_plain(v) for v in obj]
    if isinstance(obj, dict):
        return {k: _plain(v) for k, v in obj.items()}
    return obj


def defaults() -> dict:
    """Every key a study may set, with its default (plus ``sweep`` and ``conditions``), as mappings."""
    return {**StudyConfig().to_dict(), "sweep": None, "conditions": None}


DEFAULTS: dict = defaults()


# ---- knobs of the renderer's noise and settings of the learner -----------------------------------------

# The range of each noise knob a study may set (lv3d.render.noise.NoiseConfig says what each means).
PROB = (0.0, 1.0)
KNOB_RANGES: dict[str, tuple[float, float]] = {
    "depth_sigma_base_m": (0.0, 0.1), "depth_sigma_k": (0.0, 1.0), "hole_blobs": (0, 1000),
    "hole_radius_px": (0.0, 500.0), "grazing_deg": (1.0, 90.0), "flying_pixels": PROB, "color_sigma": (0.0, 255.0),
    "blur_px": (0.0, 100.0), "jpeg_quality": (0, 100), "exposure": (0.0, 5.0), "occluder": PROB, "clutter": (0, 16),
    "distractor_lines": (0, 100), "texture": PROB, "table_grain": PROB, "printed_faces": PROB, "face_hues": PROB,
    "touching": PROB, "stacked": PROB, "small_table": PROB, "edge_dropout_px": (0.0, 100.0),
}


def check_noise(data: DataConfig, where: str) -> None:
    """The preset and knobs exist, each knob has its type (lv3d.render.noise) and lies in KNOB_RANGES."""
    from ..render.noise import noise_config

    try:
        noise_config(data.noise, **data.noise_overrides)
    except InputError as e:
        key = "data.noise" if e.problem.startswith("unknown noise preset") else "data.noise_overrides"
        raise InputError(where, f"{key}: {e.problem}") from None
    except TypeError as e:
        raise InputError(where, f"data.noise_overrides: {e}") from None
    for knob, value in data.noise_overrides.items():
        if knob in KNOB_RANGES and is_number(value):
            lo, hi = KNOB_RANGES[knob]
            if not lo <= value <= hi:
                raise InputError(where, f"data.noise_overrides.{knob}: must be from {lo:g} to {hi:g}, got {value!r}")
        elif knob in KNOB_RANGES:
            raise InputError(where, f"data.noise_overrides.{knob}: must be a finite number, got {value!r}")


def check_learner_settings(settings: dict, where: str) -> dict:
    from ..learn.settings import check_settings

    return check_settings(settings, where, prefix="lv3d.settings.")


def check_depth_settings(depth: dict, where: str, prefix: str = "lv3d.depth.") -> dict:
    """``lv3d.depth`` (or any mapping of depth settings) as one flat mapping of dotted keys, sorted (nested
    mappings, ``{sensor: {base_m: 0.006}}``, are flattened): InputError at ``where`` naming the key (after
    ``prefix``) the depth settings refuse (lv3d.perception.depth.with_overrides)."""
    from ..perception.depth import with_overrides

    if not isinstance(depth, dict):
        raise InputError(where, f"depth settings must be a mapping of setting to value, got {depth!r}")

    flat: dict = {}

    def walk(node: dict, above: str) -> None:
        for k, v in node.items():
            key = f"{above}{k}"
            if isinstance(v, dict):
                walk(v, key + ".")
            else:
                flat[key] = v

    walk(depth, "")
    flat = dict(sorted(flat.items()))
    try:
        with_overrides(flat)
    except ValueError as e:
        raise InputError(where, f"{prefix}{e}") from None
    return flat


# ---- building a StudyConfig from mappings ---------------------------------------------------------------

def _section(cls, raw: dict, key: str, where: str):
    values = {}
    for f in fields(cls):
        if f.name in raw:
            if f.metadata.get("kind") == "pairs":
                values[f.name] = raw[f.name]  # checked against the study's systems below
            else:
                values[f.name] = check_value(raw[f.name], f.metadata, f"{key}.{f.name}", where)
    return cls(**values)


# objects.csv's catch-all shape (../shared/data/real/README.md): an object of none of the shapes it names, which
# a study of every shape of its folders (data.classes None) does not learn as a class
OTHER_SHAPE = "other"


def class_rule(split: str, folds: int) -> str:
    """What a class of a study on folders must be to be learned and tested, in words: with ``split`` folders
    (each folder a test fold) labelled in every folder, else (folds grouped by frame, each testing a frame of
    every class) labelled in at least ``folds`` frames."""
    return "labelled in every folder of data.folders" if split == "folders" else \
        f"labelled in at least folds ({folds}) frames of data.folders"


def learnable_classes(folders, classes, folds: int, where: str, split: str = "frames"
                      ) -> tuple[tuple[str, ...], dict[str, int]]:
    """The classes of ``classes`` a study on ``folders`` can learn and test: with ``split`` frames, those labelled
    in at least ``folds`` frames (the folds are grouped by frame, and each test fold holds a frame of each class);
    with ``split`` folders, those labelled in every folder (each folder is a test fold); in their order. And the
    others, each with its number of labelled objects, which the study leaves out (and says so). ``classes`` None:
    every shape the folders' objects.csv name but ``OTHER_SHAPE``, the most labelled objects first (ties by name).
    InputError naming ``where`` when a folder cannot be read, or fewer than two classes remain (a class task's
    negatives are the other classes' objects)."""
    objects: Counter = Counter()
    frames: dict[str, set] = {}
    for k, path in enumerate(folders):
        try:
            labelled, _ = FrameFolder(Path(path).expanduser()).objects()
        except InputError as e:
            raise InputError(where, f"data.folders: {e}") from None
        for o in labelled:
            objects[o.shape] += 1
            frames.setdefault(o.shape, set()).add((k, o.frame))
    if classes is None:
        classes = tuple(sorted((c for c in objects if c != OTHER_SHAPE), key=lambda c: (-objects[c], c)))
    by_folder = split == "folders"
    # in how many folders (split folders) or frames (split frames) each class is labelled, and how many it needs
    spread = {c: len({k for k, _ in fr}) if by_folder else len(fr) for c, fr in frames.items()}
    need, unit = (len(folders), "folder(s)") if by_folder else (folds, "frame(s)")
    kept = tuple(c for c in classes if spread.get(c, 0) >= need)
    why = "data.split folders: each folder is a test fold" if by_folder else \
        "the folds are grouped by frame, and each tests a frame of every class"
    if len(kept) < 2:
        have = ", ".join(f"{c} {objects[c]} in {spread[c]} {unit}" for c in sorted(objects)) or "none"
        raise InputError(where, f"data.classes: fewer than two of {', '.join(classes) or 'its classes'} are "
                                f"{class_rule(split, folds)} ({why}); the folders hold: {have}")
    return kept, {c: objects[c] for c in classes if c not in kept}


def from_dict(cfg: dict, where: str) -> StudyConfig:
    """A merged config mapping (every key known) -> StudyConfig; InputError at the first bad value."""
    top = {}
    for f in fields(StudyConfig):
        if f.name in SECTIONS:
            top[f.name] = _section(SECTIONS[f.name], cfg.get(f.name) or {}, f.name, where)
        elif f.name in cfg:
            top[f.name] = check_value(cfg[f.name], f.metadata, f.name, where)
    study = StudyConfig(**top)
    d, b = study.data, study.baselines
    if d.split == "folders":
        if d.folders is None or len(d.folders) < 2:
            raise InputError(where, "data.split: folders (one fold per folder) needs data.folders of two folders or "
                                    f"more, got {len(d.folders or ())}")
        study = replace(study, folds=len(d.folders))  # one fold per folder, whatever folds says
    if d.folders is not None:
        kept, too_few = learnable_classes(d.folders, d.classes, study.folds, where, d.split)
        study = replace(study, data=replace(d, classes=kept), left_out_classes=tuple(too_few.items()))
        d = study.data
    elif d.classes is None:
        raise InputError(where, "data.classes: give the classes to render (every shape of the folders' objects.csv, "
                                "None, is for a study on data.folders)")
    else:
        known = _classes()
        for c in d.classes:
            if c not in known:
                raise InputError(where, f"data.classes: unknown name {c!r}; known: {', '.join(known)}")
    if d.folders is None and d.per_class < study.folds:
        raise InputError(where, f"data.per_class: must be at least folds ({study.folds}), got {d.per_class}")
    if d.folders is None and d.per_class * len(d.classes) > MAX_DATASET_IMAGES:
        raise InputError(where, f"data.per_class: {d.per_class} images of {len(d.classes)} classes exceed the "
                                f"{MAX_DATASET_IMAGES} images a data set may hold (lv3d.limits)")
    check_noise(d, where)
    lv = replace(study.lv3d, settings=check_learner_settings(study.lv3d.settings, where),
                 depth=check_depth_settings(study.lv3d.depth, where))
    if b.tree_cells > b.image_size or b.image_size % b.tree_cells:
        raise InputError(where, f"baselines.tree_cells: must divide baselines.image_size ({b.image_size}), "
                                f"got {b.tree_cells}")
    if b.tune and any(b.image_size % s for s in b.tune_image_size):
        raise InputError(where, f"baselines.tune_image_size: each must divide baselines.image_size ({b.image_size}, "
                                f"the size of the cached tensors), got {list(b.tune_image_size)}")
    pairs = study.stats.pairs
    if pairs is not None:
        if not isinstance(pairs, (list, tuple)):
            raise InputError(where, f"stats.pairs: must be a list of [system, system] pairs, got {pairs!r}")
        for p in pairs:
            if not (isinstance(p, (list, tuple)) and len(p) == 2 and p[0] != p[1]
                    and all(isinstance(s, str) and s in study.systems for s in p)):
                raise InputError(where, f"stats.pairs: {p!r} is not a pair of two systems of this study "
                                        f"({', '.join(study.systems)})")
        pairs = tuple(tuple(p) for p in pairs)
    return replace(study, lv3d=lv, stats=StatsConfig(pairs))


# ---- reading the YAML: unknown keys, defaults, overrides, conditions -----------------------------------

def _check_keys(cfg: dict, schema: dict, where: str, prefix: str = "") -> None:
    for key, value in cfg.items():
        path = f"{prefix}{key}"
        if not isinstance(key, str) or key not in schema:
            raise InputError(where, f"unknown key {path!r}; known here: {', '.join(sorted(schema))}")
        if isinstance(schema[key], dict) and tuple(path.split(".")) not in FREE:
            if not isinstance(value, dict):
                raise InputError(where, f"{path}: must be a mapping, got {value!r}")
            _check_keys(value, schema[key], where, path + ".")


def _merge(base: dict, over: dict) -> dict:
    out = copy.deepcopy(base)
    for k, v in over.items():
        if isinstance(v, dict) and isinstance(out.get(k), dict) and k not in ("noise_overrides", "settings", "depth"):
            out[k] = _merge(out[k], v)
        else:
            out[k] = copy.deepcopy(v)
    return out


def set_dotted(cfg: dict, key: str, value, where: str) -> None:
    """Set ``a.b.c`` in a nested mapping; the key must exist in the schema (free mappings excepted)."""
    if not isinstance(key, str) or not key or any(not p for p in key.split(".")):
        raise InputError(where, f"not a dotted key: {key!r}")
    parts = key.split(".")
    if parts[0] == "sweep" and len(parts) == 2:  # one half of the sweep (--set sweep.values=[1,2]); _expand checks it
        if parts[1] not in ("param", "values"):
            raise InputError(where, f"unknown key {key!r}; a sweep has param and values")
        if not isinstance(cfg.get("sweep"), dict):
            cfg["sweep"] = {}
        cfg["sweep"][parts[1]] = value
        return
    node, schema = cfg, DEFAULTS
    for i, p in enumerate(parts[:-1]):
        if tuple(parts[:i + 1]) == DOTTED_FREE:  # a depth setting: the rest of the key is its own key
            if not isinstance(node.get(p), dict):
                node[p] = {}
            node[p][".".join(parts[i + 1:])] = value
            return
        free = tuple(parts[:i + 1]) in FREE  # a knob or learner setting: any name, checked later
        if schema is None or p not in schema or not isinstance(schema[p], dict) or (free and i != len(parts) - 2):
            raise InputError(where, f"unknown key {key!r}")
        if not isinstance(node.get(p), dict):
            node[p] = {}
        node, schema = node[p], (None if free else schema[p])
    if schema is not None and parts[-1] not in schema:
        raise InputError(where, f"unknown key {key!r}")
    node[parts[-1]] = value


_EXPONENT = re.compile(r"[-+]?(\d+\.?\d*|\.\d+)[eE][-+]?\d+")


def _yaml_value(raw: str):
    if _EXPONENT.fullmatch(raw.strip()):  # YAML 1.1 reads 1e-3 (no dot) as a string
        return float(raw)
    return yaml.safe_load(raw)


def parse_override(text: str, option: str = "--set") -> tuple[str, object]:
    """``key=value`` with the value parsed as YAML (``8``, ``false``, ``[1, 2]``); InputError naming ``option``."""
    if "=" not in text:
        raise InputError(option, f"expected key=value, got {text!r}")
    key, raw = text.split("=", 1)
    try:
        return key.strip(), _yaml_value(raw)
    except yaml.YAMLError as e:
        raise InputError(option, f"cannot parse the value of {key!r}: {str(e).splitlines()[0]}") from None


class _Loader(yaml.SafeLoader):
    """YAML 1.1 with 1e-3 (no dot) read as a number, as in ``--set``."""


_Loader.add_implicit_resolver("tag:yaml.org,2002:float", _EXPONENT, list("-+0123456789."))


@dataclass(frozen=True)
class Study:
    """A study as read from its file: ``conditions`` maps each condition's name to its checked config;
    ``base`` is the first condition (name, classes and systems of the report); ``merged`` the YAML form
    written to config.yaml."""

    path: Path
    base: StudyConfig
    conditions: dict
    merged: dict

    @property
    def name(self) -> str:
        return self.base.name

    @property
    def named_conditions(self) -> bool:
        """Whether its conditions are named ones (``conditions:``, as ablations are), not a sweep or one base."""
        return bool(self.merged.get("conditions"))


def _expand(cfg: dict, where: str) -> dict[str, dict]:
    sweep, named = cfg.get("sweep"), cfg.get("conditions")
    if sweep is not None and named is not None:
        raise InputError(where, "sweep and conditions: give one or the other")
    out: dict[str, dict] = {}
    if sweep is not None:
        if not isinstance(sweep, dict) or set(sweep) != {"param", "values"} or not isinstance(sweep["values"], list) \
                or not sweep["values"] or not isinstance(sweep["param"], str):
            raise InputError(where, "sweep: must be {param: dotted key, values: [one or more values]}")
        for v in sweep["values"]:
            if isinstance(v, (dict, list)) or v is None:
                raise InputError(where, f"sweep.values: each value must be a number, text or true/false, got {v!r}")
            c = copy.deepcopy(cfg)
            name = f"{sweep['param'].split('.')[-1]}={v}"
            set_dotted(c, sweep["param"], v, f"{where}: sweep.param")
            out[name] = c
    elif named is not None:
        if not isinstance(named, dict) or not named:
            raise InputError(where, "conditions: must map names to {dotted key: value}")
        for name, overrides in named.items():
            if overrides is not None and not isinstance(overrides, dict):
                raise InputError(where, f"conditions.{name}: must be a mapping of dotted keys to values")
            c = copy.deepcopy(cfg)
            for k, v in (overrides or {}).items():
                set_dotted(c, k, v, f"{where}: conditions.{name}")
            out[str(name)] = c
    else:
        out["base"] = copy.deepcopy(cfg)
    for name in out:
        if not _CONDITION_NAME.match(name) or name in (".", ".."):
            raise InputError(where, f"condition name {name!r}: use letters, digits and _ + = . , - only")
    return out


def read_yaml(path: Path) -> dict:
    path = Path(path)
    if not path.is_file():
        raise InputError(path, "config file not found")
    try:
        raw = yaml.load(path.read_text(), Loader=_Loader) or {}
    except (yaml.YAMLError, UnicodeDecodeError) as e:
        raise InputError(path, f"not valid YAML: {str(e).splitlines()[0]}") from None
    if not isinstance(raw, dict):
        raise InputError(path, "a config must be a mapping at the top level")
    return raw


def load_study(path: Path, overrides=()) -> Study:
    """Read, merge with defaults, apply ``key=value`` overrides, expand and check every condition."""
    path = Path(path)
    raw = read_yaml(path)
    where = str(path)
    _check_keys(raw, DEFAULTS, where)
    merged = _merge(DEFAULTS, raw)
    for text in overrides:
        key, value = parse_override(text)
        set_dotted(merged, key, value, f"{where}: --set")
    _check_keys({k: v for k, v in merged.items() if k not in ("sweep", "conditions")}, DEFAULTS, where)
    conds = {}
    for name, c in _expand(merged, where).items():
        here = where if name == "base" else f"{where}: {'sweep' if merged.get('sweep') else 'conditions'} {name}"
        conds[name] = from_dict(c, here)
    return Study(path, next(iter(conds.values())), conds, merged)


def digest(obj) -> str:
    """A short stable hash of JSON-able data (cache keys, resume checks)."""
    if hasattr(obj, "__dataclass_fields__"):
        obj = _plain(obj)
    return hashlib.sha256(json.dumps(obj, sort_keys=True, default=str).encode()).hexdigest()[:12]
