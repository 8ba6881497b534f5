"""The examples lv3d learns from: the facts of each example of a rendered data set or of folders of labelled
real frames, with its class. ``lv3d learn`` reads its data through :func:`read_examples`; a script does the same:

    from lv3d.examples import read_examples
    from lv3d.learn import Model

    train = read_examples("myframes/", "rgbd").learnable()
    model = Model.fit(train.scenes, train.labels, classes=["box", "cylinder"], seed=0)
    test = read_examples("otherframes/", "rgbd").learnable()
    for scene, label in zip(test.scenes, test.labels):
        print(label, model.predict(scene), model.explain(scene))  # the truth, (class, confidence), the proof

A folder of real frames (``objects.csv``; docs/real_frames.md) gives one example per labelled object, the
object perception finds under its pixel, with facts from perception cached on disk; a rendered data set
(``manifest.json``; docs/dataset.md) one example per image, with facts from perception or from the
renderer's ground truth. An example where perception found no object keeps no target (``target`` None) and a
warning; a row of objects.csv that cannot be used is no example and a warning.
"""

from __future__ import annotations

import json
import os
from dataclasses import dataclass, field
from pathlib import Path

from .errors import InputError, read_json
from .facts import MODALITIES, SceneFacts
from .frame_folder import is_frame_folder

SOURCES = ("pipeline", "truth")


@dataclass(frozen=True)
class ExampleWarning:
    """Why an example, or a row that would have been one, is not learned from: ``example`` is its id, or None
    where the row gave no example."""

    example: str | None
    text: str

    def __str__(self) -> str:
        return self.text


@dataclass(frozen=True)
class Examples:
    """Examples in the order of their data: each one's facts (``scenes``), class (``labels``), and the warnings
    of reading them."""

    scenes: list[SceneFacts]
    labels: list[str]
    warnings: list[ExampleWarning] = field(default_factory=list)

    def learnable(self) -> Examples:
        """The examples with a target object (perception found one); the others' warnings stay."""
        keep = [(s, y) for s, y in zip(self.scenes, self.labels) if s.target is not None]
        return Examples([s for s, _ in keep], [y for _, y in keep], self.warnings)

    @property
    def without_object(self) -> int:
        """How many examples have no target object."""
        return sum(s.target is None for s in self.scenes)


def default_cache() -> Path:
    """Where the facts of real frames are cached by default: $XDG_CACHE_HOME/lv3d, else ~/.cache/lv3d."""
    return Path(os.environ.get("XDG_CACHE_HOME") or Path.home() / ".cache") / "lv3d"


def read_examples(data, modality: str, *, facts: str = "pipeline", cache: str | Path | None = None,
                  depth: dict | None = None) -> Examples:
    """The examples of ``data`` as a system that sees ``modality`` (rgb, depth, rgbd) gets them: a folder of
    labelled real frames (objects.csv), a list of such folders (their examples together, in their order; a frame
    whose name an earlier folder has is named with its folder's name in front), or a rendered data set
    (manifest.json).
    ``facts``: from perception and grounding ("pipeline") or, on a rendered data set, from its ground truth
    ("truth"). ``cache``: the folder caching real frames' facts (default :func:`default_cache`). ``depth``: depth
    settings other than the defaults, ``{key: value}`` (``{"sensor.base_m": 0.006}``, the keys of
    lv3d.perception.depth.with_overrides), for frames of another sensor; facts made with them are cached apart.
    InputError for data that is none of these, or malformed, or depth settings the depth stage refuses."""
    paths = [Path(d) for d in data] if isinstance(data, (list, tuple)) else [Path(data)]
    if not paths:
        raise InputError("--data", "no data given")
    if modality not in MODALITIES:
        raise InputError("--modality", f"must be one of {', '.join(MODALITIES)}, got {modality!r}")
    if facts not in SOURCES:
        raise InputError("--facts", f"must be one of {', '.join(SOURCES)}, got {facts!r}")
    if depth:
        from .experiment.config import check_depth_settings

        depth = check_depth_settings(depth, "depth settings", prefix="")
        if facts == "truth":
            raise InputError("--facts", "ground-truth facts are not perceived: depth settings do not apply to them")
    real = [is_frame_folder(p) for p in paths]
    if all(real):
        if facts == "truth":
            raise InputError("--facts", f"{paths[0]} holds real frames: they have no ground-truth facts (use pipeline)")
        return _frame_folder_examples(paths, modality, Path(cache).expanduser() if cache else default_cache(),
                                      depth or None)
    if len(paths) > 1:
        other = paths[real.index(False)]
        raise InputError(other, "not a folder of labelled frames (no objects.csv): several --data must all be "
                                "such folders (a rendered data set is read alone)")
    return _dataset_examples(paths[0], modality, facts, depth or None)


def _frame_folder_examples(folders: list[Path], modality: str, cache: Path, depth: dict | None) -> Examples:
    from .experiment.code_version import facts_version
    from .experiment.real_data import ensure_frame_facts, example_facts_of, real_data

    rd = real_data([str(f) for f in folders])
    warnings = [ExampleWarning(None, f"{p} (left out)") for p in rd.problems]
    frames = ensure_frame_facts(rd, cache / "facts", facts_version(), modality, True, depth=depth)
    facts, errors = example_facts_of(rd, frames)
    warnings += [ExampleWarning(i, f"{errors[i]} (example {i} has no object)") for i in sorted(errors)]
    return Examples([facts[it.id] for it in rd.items], [it.cls for it in rd.items], warnings)


def _dataset_examples(data: Path, modality: str, facts: str, depth: dict | None) -> Examples:
    manifest = data / "manifest.json"
    if not manifest.is_file():
        raise InputError(data, "not a data set (no manifest.json) nor a folder of labelled frames (no objects.csv)")
    try:
        items = json.loads(manifest.read_text())["items"]
    except (OSError, UnicodeDecodeError, json.JSONDecodeError, KeyError, TypeError) as e:
        raise InputError(manifest, f"malformed: {e}") from None
    if not isinstance(items, list):
        raise InputError(manifest, "items: must be a list of {id, class, dir}")
    for i, it in enumerate(items):
        if not (isinstance(it, dict) and all(isinstance(it.get(k), str) and it.get(k) for k in ("id", "class", "dir"))):
            raise InputError(manifest, f"items[{i}]: must be {{id, class, dir}} (texts), got {it!r}")
    if not items:
        raise InputError(data, "the data set lists no items")
    scenes, labels, warnings = [], [], []
    for it in items:
        item_dir = data / it["dir"]
        if facts == "truth":
            from .truth_facts import truth_facts

            scenes.append(truth_facts(read_json(item_dir / "meta.json", "meta.json"), it["id"], modality))
        else:
            from .pipeline import scene_facts
            from .rgbd import load_item

            try:
                scenes.append(scene_facts(load_item(item_dir), it["id"], modality, depth=depth))
            except InputError as e:  # no object found: the image is kept without a target, and counted
                warnings.append(ExampleWarning(it["id"], f"{item_dir}: {e.problem} (no example)"))
                scenes.append(SceneFacts(it["id"], modality, [], None))
        labels.append(it["class"])
    return Examples(scenes, labels, warnings)
