"""Facts of labelled objects in real frames: every labelled object is one example for the learner.

A frame is perceived and grounded once per modality (:func:`frame_facts`); each labelled object's example
is then the perceived object under its labelled pixel (:func:`object_under`), with that object's facts
only, renamed to the example's id (:func:`example_facts`) so that two labelled objects of one frame, or
two labels that fall on one merged object, are separate examples. A label on no perceived object gives
an example with no target: the learner leaves it out of training and answers "unknown" on it, and the
study counts it.

Measurements of perception on labelled frames (benchmarks/bench_real.py, lv3d.calibrate.real) match a label
to a perceived object by another rule, which counts faces: :func:`held_object` (the most faces covering the
pixel, over :func:`face_cover`), and flag a perceived object that holds another label's region as merged
(:func:`merged_flags`).
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, field, replace

import cv2
import numpy as np

from .errors import InputError
from .facts import SceneFacts
from .rgbd import RGBD
from .scene import Scene, SceneObject

# A labelled pixel that falls just off a perceived object (a hole in its depth, a pixel on its rim) still
# names it when the object comes within this fraction of the image diagonal (8 px at 640x480): labels are
# given by eye, and a segment's border is uncertain by a few pixels.
LABEL_REACH = 0.01
HOLD_SHARE = 0.2  # a perceived object holds a labelled object when it holds this share of its mask


def face_cover(obj: SceneObject, shape: tuple[int, int]) -> np.ndarray:
    """(H, W) uint8: 1 on ``obj``'s segment where it has one; else how many of its faces cover each pixel (their
    polygons rasterised with cv2.fillPoly). The object's pixels are where it is > 0."""
    if getattr(obj, "mask", None) is not None and obj.mask.shape == shape:
        return obj.mask.astype(np.uint8)
    cover = np.zeros(shape, np.uint8)
    one = np.zeros(shape, np.uint8)
    for f in obj.faces:
        poly = np.round(np.asarray(f.polygon, float)).astype(np.int32).reshape(-1, 2)
        if len(poly) < 3:
            continue
        one[:] = 0
        cv2.fillPoly(one, [poly], 1)
        cover += one
    return cover


def _object_pixels(obj: SceneObject, shape: tuple[int, int]) -> np.ndarray:
    """(H, W) bool: the object's segment, or where it has none (colour alone), the union of its faces."""
    return face_cover(obj, shape) > 0


def held_object(covers: list[np.ndarray], u: int, v: int) -> int | None:
    """Index of the object holding pixel (u, v) (``covers``: :func:`face_cover` of each): the most faces covering
    it, ties to the first; None if none."""
    counts = [int(c[v, u]) for c in covers]
    if not counts or max(counts) == 0:
        return None
    return int(np.argmax(counts))


def region_pixels(lab, label_img: np.ndarray | None) -> tuple[np.ndarray, np.ndarray]:
    """(rows, cols) of a labelled object (lv3d.frame_folder.LabelledObject): its mask where the frame has one
    (and it is not empty), else its labelled pixel alone."""
    if label_img is not None:
        vs, us = np.nonzero(label_img == lab.object)
        if len(vs):
            return vs, us
    return np.array([lab.v]), np.array([lab.u])


def holds(mask: np.ndarray, region: tuple[np.ndarray, np.ndarray], share: float = HOLD_SHARE) -> bool:
    """Whether ``mask`` holds >= ``share`` of ``region``'s pixels (a one-pixel region: holds that pixel)."""
    vs, us = region
    return len(vs) > 0 and float(np.mean(mask[vs, us])) >= share


def merged_flags(held: list[int | None], masks: list[np.ndarray],
                 regions: list[tuple[np.ndarray, np.ndarray]]) -> list[bool]:
    """Per labelled object: its perceived object (``held``, index into ``masks``) also holds another labelled
    object's region (:func:`holds`). Not found: not merged."""
    out = []
    for i, k in enumerate(held):
        out.append(k is not None and any(holds(masks[k], regions[j]) for j in range(len(regions)) if j != i))
    return out


def object_under(scene: Scene, u: int, v: int, shape: tuple[int, int]) -> tuple[SceneObject | None, np.ndarray | None]:
    """The perceived object at pixel (u, v) and its pixels: the one covering it, else the nearest within
    LABEL_REACH of the image diagonal, else (None, None). Of several covering it (overlapping face
    outlines), the smallest."""
    h, w = shape
    reach = LABEL_REACH * float(np.hypot(w, h))
    best, best_key, best_pix = None, None, None
    for obj in scene.objects:
        pix = _object_pixels(obj, shape)
        if not pix.any():
            continue
        if pix[v, u]:
            key = (0.0, int(pix.sum()))
        else:
            r = int(np.ceil(reach))
            window = pix[max(0, v - r):v + r + 1, max(0, u - r):u + r + 1]
            if not window.any():
                continue
            ys, xs = np.nonzero(window)
            d = float(np.min(np.hypot(xs + max(0, u - r) - u, ys + max(0, v - r) - v)))
            if d > reach:
                continue
            key = (d, int(pix.sum()))
        if best_key is None or key < best_key:
            best, best_key, best_pix = obj, key, pix
    return best, best_pix


def _box(pix: np.ndarray) -> list[int]:
    ys, xs = np.nonzero(pix)
    return [int(xs.min()), int(ys.min()), int(xs.max()) + 1, int(ys.max()) + 1]


@dataclass
class FrameFacts:
    """One frame's facts for one modality: ``facts`` of the objects some label falls on (scene id = the
    frame's atom); ``under``: label object -> the perceived object's id (None: no object there);
    ``boxes``: label object -> the perceived object's pixel box [u0, v0, u1, v1) (None: no object);
    ``error``: why the frame gave no facts at all (perception found no object), else None."""

    frame: str
    modality: str
    facts: SceneFacts
    under: dict[int, str | None] = field(default_factory=dict)
    boxes: dict[int, list[int] | None] = field(default_factory=dict)
    error: str | None = None

    def to_json(self) -> dict:
        return {"frame": self.frame, "modality": self.modality, "facts": self.facts.to_json(),
                "under": {str(k): v for k, v in self.under.items()},
                "boxes": {str(k): v for k, v in self.boxes.items()}, "error": self.error}

    @classmethod
    def from_json(cls, d: dict, where: str = "frame facts") -> "FrameFacts":
        try:
            return cls(d["frame"], d["modality"], SceneFacts.from_json(d["facts"], where),
                       {int(k): v for k, v in d["under"].items()},
                       {int(k): v for k, v in d["boxes"].items()}, d.get("error"))
        except (KeyError, TypeError, ValueError, AttributeError) as e:
            raise InputError(where, f"malformed frame facts: {e}") from None


def frame_facts(frame: RGBD, frame_atom: str, modality: str, labels: list[tuple[int, int, int]], *,
                refine: bool = True, seed: int = 0, depth: Mapping[str, object] | None = None) -> FrameFacts:
    """Perceive and ground ``frame`` once as ``modality`` sees it; ``labels``: (object, u, v) of each labelled
    object. Only the labelled objects are refined and kept. ``seed``: perception's (perceive); ``depth``: depth
    settings other than the defaults (lv3d.pipeline.scene_facts)."""
    from .perception import perceive
    from .perception.depth import with_overrides

    settings = with_overrides(depth or {})
    return labelled_facts(perceive(frame, modality, scene_id=frame_atom, seed=seed, depth_settings=settings), frame,
                          labels, refine=refine)


def labelled_facts(scene: Scene, frame: RGBD, labels: list[tuple[int, int, int]], *,
                   refine: bool = True) -> FrameFacts:
    """:func:`frame_facts` of a frame already perceived: ``scene`` is ``frame`` perceived (its id the frame's
    atom, its modality the facts'). The scene is left as it was."""
    from .describe import describe

    frame_atom, modality = scene.id, scene.modality
    shape = frame.depth.shape
    under: dict[int, str | None] = {}
    boxes: dict[int, list[int] | None] = {}
    for obj_label, u, v in labels:
        obj, pix = object_under(scene, u, v, shape)
        under[obj_label] = obj.id if obj is not None else None
        boxes[obj_label] = _box(pix) if obj is not None else None
    if not scene.objects:
        return FrameFacts(frame.name, modality, SceneFacts(frame_atom, modality, [], None), under, boxes,
                          "perception found no object in this frame")
    keep = frozenset(i for i in under.values() if i is not None)
    labelled = replace(scene, objects=[o for o in scene.objects if o.id in keep])
    facts = describe(labelled, frame, refine=refine, refine_ids=keep).for_modality(modality)
    return FrameFacts(frame.name, modality, facts, under, boxes, None)


def example_facts(ff: FrameFacts, label_object: int, example_id: str) -> SceneFacts:
    """The example of one labelled object: the facts of the perceived object under its pixel (object, its
    faces and the relations among them), that object renamed ``<example_id>_o`` and its faces
    ``<example_id>_o_f<j>``; target None when no object lies under the pixel."""
    obj = ff.under.get(label_object)
    if obj is None:
        return SceneFacts(example_id, ff.modality, [], None)
    new = f"{example_id}_o"
    prefix = f"{obj}_"

    def rename(a: str) -> str | None:
        if a == obj:
            return new
        if a.startswith(prefix) and a[len(prefix):].startswith("f"):
            return new + a[len(obj):]
        return None

    kept = []
    for f in ff.facts.facts:
        args = tuple(rename(a) for a in f.args)
        if all(a is not None for a in args):
            kept.append(type(f)(f.pred, args, f.conf, f.value))
    return SceneFacts(example_id, ff.modality, kept, new if any(f.pred == "object" for f in kept) else None)


def example_id(frame_atom: str, label_object: int) -> str:
    """The example's id (a Prolog atom): the frame's atom and the label's object number."""
    return f"{frame_atom}_x{label_object}"
