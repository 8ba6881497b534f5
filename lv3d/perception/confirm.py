"""RGB-D objects that colour does not confirm, replaced by the colour path's own objects.

Under heavy depth noise, segmentation breaks a solid into fragments and outlines them with planes whose
boundaries follow the noise. The colour path, which in rgbd runs only in a crop around each depth object, then
finds no face lying mostly on any one fragment, and the fused object is made of depth faces alone (provenance
'depth'), with outlines of the wrong number of sides. Where the colour path run on the whole frame finds an
object over such unconfirmed objects, its faces describe the solid better than the fragments do; a face seen
by one modality only is kept and says so (provenance 'rgb'). Only objects whose planes fit their points
poorly are given up: on realsense and noisier renders an unconfirmed object is more often depth seeing what
colour misses (a face of low contrast) than a noisy fragment.
"""

from __future__ import annotations

import dataclasses

import numpy as np

from ..facts import face_id, object_id
from ..scene import Face, SceneObject
from .polygons import rasterize
from .support import noise_threshold

_SAME_OBJECT = 0.5  # an object covers another when this much of the smaller one's pixels lie on the larger
# depth at the limit of its noise model: the planes fit their points (median RMS over the faces) no better than
# this fraction of the inlier threshold; on realsense renders objects of depth faces alone sit at 0.1-0.3
_NOISY_FIT = 0.5
# a view of one convex solid shows at most a handful of faces of a few sides each; a colour "object" with
# more, or with a many-sided face, is texture, clutter or a region around the object, not a better view of it
_MAX_FACES, _MAX_SIDES = 5, 8


def _fit_ratio(f: Face) -> float:
    return float(f.plane_rms_m or 0.0) / noise_threshold(float(np.median(f.points[:, 2])))


def unconfirmed(objects: list[SceneObject]) -> list[int]:
    """Indices of the objects whose faces all come from depth alone (no colour face matched any of them), when
    their planes fit their points poorly (median over all their faces, see ``_NOISY_FIT``); else none."""
    idx = [i for i, o in enumerate(objects)
           if o.faces and all(f.provenance == "depth" and f.points is not None and len(f.points) for f in o.faces)]
    ratios = [_fit_ratio(f) for i in idx for f in objects[i].faces]
    return idx if ratios and float(np.median(ratios)) >= _NOISY_FIT else []


def _mask(o: SceneObject, shape: tuple[int, int]) -> np.ndarray:
    m = np.zeros(shape, bool)
    for f in o.faces:
        m |= rasterize(f.polygon, shape)
    return m


def replace_unconfirmed(objects: list[SceneObject], unconfirmed_idx: list[int], colour: list[SceneObject],
                        shape: tuple[int, int], scene_id: str) -> list[SceneObject]:
    """``objects`` (fused rgbd objects) with each colour object that covers unconfirmed ones (``unconfirmed_idx``,
    as :func:`unconfirmed` gives them) in their place.

    A colour object that could be one solid's view (``_MAX_FACES``, ``_MAX_SIDES``) takes the place of every
    unconfirmed object it overlaps by more than half of the smaller of the two, unless it lies as much on
    another object (there colour and depth already agree, or the depth is trusted). Objects
    are then renumbered largest first; ``shape`` is the image's (H, W)."""
    weak = set(unconfirmed_idx)
    if not weak or not colour:
        return objects
    masks = [_mask(o, shape) for o in objects]
    sizes = [np.count_nonzero(m) for m in masks]
    drop: set[int] = set()
    added: list[SceneObject] = []
    for c in colour:
        cm = _mask(c, shape)
        cn = max(np.count_nonzero(cm), 1)
        over = [i for i, m in enumerate(masks) if np.count_nonzero(cm & m) > _SAME_OBJECT * max(min(cn, sizes[i]), 1)]
        plausible = len(c.faces) <= _MAX_FACES and all(f.sides <= _MAX_SIDES for f in c.faces)
        if plausible and over and all(i in weak for i in over):
            drop.update(over)
            added.append(c)
    if not added:
        return objects
    return renumber([o for i, o in enumerate(objects) if i not in drop] + added, scene_id)


def renumber(objects: list[SceneObject], scene_id: str) -> list[SceneObject]:
    """The objects ordered largest first (by pixel count) with ids ``<scene>_o<k>`` and face ids
    ``<scene>_o<k>_f<j>`` assigned afresh, face order and adjacency kept."""
    out = []
    for k, o in enumerate(sorted(objects, key=lambda o: -o.pixel_count), start=1):
        ids = {f.id: face_id(scene_id, k, j) for j, f in enumerate(o.faces, start=1)}
        faces = [dataclasses.replace(f, id=ids[f.id]) for f in o.faces]
        adj = sorted(tuple(sorted((ids[a], ids[b]))) for a, b in o.adjacency)
        out.append(SceneObject(object_id(scene_id, k), faces, adj, o.pixel_count, o.centroid_px, o.mask))
    return out
