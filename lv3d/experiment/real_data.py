"""A study's examples from folders of labelled real frames (``data.folders``; lv3d.frame_folder): every
labelled object of a study class is one example, its frame its group (no frame in both a training and a
test fold), and what each system sees of it is computed once per frame and cached on disk.

- facts: ``<facts root>/real-<folders digest>/<code version>/<modality>-refine<0|1>/<frame>.json``, one file
  per frame (perceived and grounded once, every labelled object of it refined), so an interrupted run
  resumes; each example's facts are its object's (lv3d.object_facts.example_facts);
- pixels: ``<cache>/real-<folders digest>/pixels-<size>.npz``: per example a (4, S, S) crop around the object
  rgbd perception found under its pixel (a square of a quarter of the frame's height around the pixel where
  it found none), the input of the statistical baselines.

The folders digest covers each folder's name and content (FrameFolder.signature: its files' bytes, not where it
lies or when they were written) and the study classes, so a copy of the folders keeps their caches.
Rows of objects.csv that cannot be used, and objects of classes the study does not learn, are left out
and counted (``RealData.left_out``); the runner prints the unusable rows, one line each.
"""

from __future__ import annotations

import json
from dataclasses import dataclass, field
from functools import cached_property
from pathlib import Path

import numpy as np
from tqdm import tqdm

from ..errors import InputError
from ..facts import SceneFacts
from ..frame_folder import FrameFolder, LabelledObject, Problem, scene_atom
from ..output import clean_stale
from .folds import Item

# An object perceived nowhere still gets a crop for the baselines: a square this fraction of the frame's
# height, centred on its labelled pixel (a table-top object at a metre fills about a fifth of a Kinect frame).
FALLBACK_CROP = 0.25
# The crop around a perceived object's box: its longer side times (1 + CROP_MARGIN), so that the outline
# and a little background are in view, as in the object crops of RGB-D recognition data sets.
CROP_MARGIN = 0.15


@dataclass
class RealData:
    """The examples of ``data.folders``: items (id, class, frame atom, group = frame atom), where each frame
    is, and what was left out."""

    folders: list[FrameFolder]
    items: list[Item]
    frames: dict[str, tuple[FrameFolder, str]]          # frame atom -> (folder, frame name)
    labels: dict[str, list[LabelledObject]]             # frame atom -> its labelled objects (study classes)
    example_of: dict[str, tuple[str, int]]              # item id -> (frame atom, label object)
    problems: list[Problem] = field(default_factory=list)
    other_classes: dict[str, int] = field(default_factory=dict)  # class -> objects left out (not a study class)

    @cached_property
    def key(self) -> str:
        """What the examples are made of: each folder's name and content (FrameFolder.signature), not where it lies,
        and the study's classes."""
        from .config import digest

        return "real-" + digest({"folders": [[f.name, f.signature()] for f in self.folders],
                                 "classes": sorted({it.cls for it in self.items})})

    @property
    def left_out(self) -> dict:
        return {"unusable_rows": [str(p) for p in self.problems], "other_classes": dict(self.other_classes)}


def real_data(folders, classes=None) -> RealData:
    """The examples of the folders' labelled objects whose class is one of ``classes`` (None: every class)."""
    from ..object_facts import example_id

    opened = [FrameFolder(Path(p).expanduser()) for p in folders]
    atoms: dict[str, tuple[FrameFolder, str]] = {}
    items, labels, example_of, problems, other = [], {}, {}, [], {}
    for folder in opened:
        objects, bad = folder.objects()
        problems += bad
        for frame in folder.frames:
            atom = scene_atom(frame)
            if atom in atoms:  # the same frame name in two folders
                atom = scene_atom(f"{folder.name}_{frame}")
            atoms[atom] = (folder, frame)
            mine = [o for o in objects if o.frame == frame]
            for o in mine:
                if classes is not None and o.shape not in classes:
                    other[o.shape] = other.get(o.shape, 0) + 1
                    continue
                labels.setdefault(atom, []).append(o)
                eid = example_id(atom, o.object)
                items.append(Item(eid, o.shape, atom, atom))
                example_of[eid] = (atom, o.object)
    frames = {a: v for a, v in atoms.items() if a in labels}
    return RealData(opened, items, frames, labels, example_of, problems, other)


def folder_folds(items: list[Item], rd: RealData) -> list[list[Item]]:
    """One fold per folder of ``rd``, in its order: the items of the folder's frames (data.split folders)."""
    folder_of = {atom: folder.path for atom, (folder, _) in rd.frames.items()}
    return [sorted((it for it in items if folder_of[it.dir] == f.path), key=lambda it: it.id) for f in rd.folders]


def _frame_job(job: tuple, shared=None) -> dict:
    """The cache record of one frame for one modality (runs in a worker)."""
    from ..object_facts import FrameFacts, frame_facts

    folder, frame, atom, labels, modality, refine, seed, depth = job
    try:
        rgbd = FrameFolder(Path(folder)).load(frame)
        return frame_facts(rgbd, atom, modality, labels, refine=refine, seed=seed, depth=depth).to_json()
    except InputError as e:  # a frame that cannot be read: its examples get no facts, and we count why
        return FrameFacts(frame, modality, SceneFacts(atom, modality, [], None),
                          {o: None for o, _, _ in labels}, {o: None for o, _, _ in labels}, str(e)).to_json()


def _read_record(path: Path):
    from ..object_facts import FrameFacts

    try:
        return FrameFacts.from_json(json.loads(path.read_text()), str(path))
    except (OSError, UnicodeDecodeError, ValueError, InputError):
        return None


def ensure_frame_facts(rd: RealData, root: Path, version: str, modality: str, refine: bool, workers: int = 1,
                       executor=None, seed: int = 0, depth: dict | None = None) -> dict:
    """{frame atom: FrameFacts} for every frame with a labelled object, computed where the cache lacks it;
    ``seed``: perception's; ``depth``: depth settings other than the defaults (``lv3d.depth``)."""
    from .data import facts_variant
    from .executor import cache_missing
    from ..object_facts import FrameFacts

    dest = Path(root) / rd.key / version / facts_variant(modality, refine, seed, depth)
    dest.mkdir(parents=True, exist_ok=True)
    clean_stale(dest)
    have = {a: _read_record(dest / f"{a}.json") for a in rd.frames}
    todo = [a for a in rd.frames if have[a] is None]
    jobs = [(str(rd.frames[a][0].path), rd.frames[a][1], a, [(o.object, o.u, o.v) for o in rd.labels[a]],
             modality, refine, seed, depth or {}) for a in todo]
    for name, record in cache_missing(dest, todo, _frame_job, jobs, f"facts {modality} refine={refine}", workers,
                                      executor):
        have[name] = FrameFacts.from_json(record, name)
    return have


def example_facts_of(rd: RealData, frames: dict) -> tuple[dict[str, SceneFacts], dict[str, str]]:
    """({item id: its example's facts}, {item id: why it has no target}) from the frames' facts."""
    from ..object_facts import example_facts

    facts, errors = {}, {}
    for it in rd.items:
        atom, obj = rd.example_of[it.id]
        ff = frames[atom]
        facts[it.id] = example_facts(ff, obj, it.id)
        if facts[it.id].target is None:
            folder, frame = rd.frames[atom]
            lab = next(o for o in rd.labels[atom] if o.object == obj)
            errors[it.id] = ff.error or (f"{folder.path / 'objects.csv'}: line {lab.line}: pixel {lab.pixel} "
                                         f"of {frame!r} lies on no object {ff.modality} perception found")
    return facts, errors


def crop_box(box: list[int] | None, u: int, v: int, shape: tuple[int, int]) -> tuple[int, int, int]:
    """(u0, v0, side) of the square crop of an example: around the perceived object's box, else around the
    labelled pixel (FALLBACK_CROP); it may reach past the frame (padded with no reading)."""
    h, w = shape
    if box is None:
        side = max(8, int(round(FALLBACK_CROP * h)))
        return u - side // 2, v - side // 2, side
    u0, v0, u1, v1 = box
    side = max(8, int(round(max(u1 - u0, v1 - v0) * (1 + CROP_MARGIN))))
    cu, cv = (u0 + u1) // 2, (v0 + v1) // 2
    return cu - side // 2, cv - side // 2, side


def crops_digest(rgbd_frames: dict) -> str:
    """A 16-hex digest of where the baselines' crops lie: the box of the object rgbd perception found under each
    labelled pixel, frame by frame (``rgbd_frames``: frame atom -> FrameFacts). What a baseline on real frames
    sees changes with these boxes only, whichever code found them (a change to the facts' confidences keeps
    them)."""
    import hashlib
    import json

    boxes = {atom: {str(k): b for k, b in sorted(rgbd_frames[atom].boxes.items())} for atom in sorted(rgbd_frames)}
    return hashlib.sha256(json.dumps(boxes, sort_keys=True).encode()).hexdigest()[:16]


def ensure_real_pixels(rd: RealData, cache: Path, size: int, rgbd_frames: dict) -> dict[str, np.ndarray]:
    """{item id: (4, size, size) float32 crop tensor} (lv3d.baselines.pixels' channels), cached. The crops lie
    around the objects rgbd perception found (``rgbd_frames``), so the cache is kept per :func:`crops_digest`
    of those frames."""
    from ..baselines.pixels import crop_tensor
    from ..object_facts import example_id
    from .data import read_pixels, write_pixels

    path = Path(cache) / rd.key / f"crops-{crops_digest(rgbd_frames)}" / f"pixels-{size}.npz"
    ids = [it.id for it in rd.items]
    if path.is_file():
        got = read_pixels(path, rd.items, size)
        if got is not None:
            return got
    out = {}
    for atom in tqdm(list(rd.frames), desc=f"pixels {size}x{size}"):
        folder, frame = rd.frames[atom]
        rgbd = folder.load(frame)
        for lab in rd.labels[atom]:
            box = rgbd_frames[atom].boxes.get(lab.object) if atom in rgbd_frames else None
            out[example_id(atom, lab.object)] = crop_tensor(rgbd, crop_box(box, lab.u, lab.v, rgbd.depth.shape), size)
    write_pixels(path, ids, np.stack([out[i] for i in ids]))
    return out
