"""``perceive``: one frame and a modality in, a :class:`lv3d.scene.Scene` out."""

from __future__ import annotations

import time

import numpy as np

from ..errors import InputError
from ..facts import MODALITIES, face_id, object_id
from ..rgbd import RGBD
from ..scene import Face, Scene, SceneObject
from .depth import DEFAULT, DepthObjectResult, DepthResult, DepthSettings, depth_scene
from .boundary import grid_to_pixels
from .fuse import fused_faces, largest_first
from .depth.holes import UnreadFace, unread_faces
from .depth.quadrics import surface_fields
from .polygons import area
from .rgb import RGBFace, rgb_faces

# the box searched around a depth object for the faces beside it that depth did not read, and the colour edges
# along its outline: the object's box grown on each side by this fraction of the image diagonal (14 px at 640x480:
# room for a face seen edge-on beside the object, a strip a few px wide, and the edges along it)
_CROP_MARGIN = 0.0175


def perceive(frame: RGBD, modality: str, scene_id: str = "s000000", seed: int = 0,
             max_objects: int | None = None, depth_settings: DepthSettings = DEFAULT) -> Scene:
    """Objects and faces of ``frame`` as a system that sees ``modality`` ('rgb', 'depth', 'rgbd') finds them.

    At most ``max_objects`` objects found by depth are described (the largest; default the depth settings'
    ``max_objects``, 24); ``Scene.dropped_objects`` counts the rest. ``depth_settings``: the depth stage's
    thresholds (depth.DepthSettings). Object ids are ``<scene>_o<k>`` and face ids ``<scene>_o<k>_f<j>``, k and j from 1, objects largest first.
    ``Scene.timings_ms`` holds the time of each stage. Deterministic for a given ``seed``."""
    if modality not in MODALITIES:
        raise InputError("--modality", f"unknown modality {modality!r}; choose one of {', '.join(MODALITIES)}")
    if max_objects is None:
        max_objects = depth_settings.max_objects
    if not isinstance(max_objects, int) or max_objects < 1:
        raise InputError("--max-objects", f"must be a whole number of at least 1, got {max_objects!r}")
    _check_frame(frame, modality)
    if modality == "rgb":
        scene = Scene(scene_id, modality, frame.intrinsics, timings_ms={})
        scene.objects = _colour_objects(frame, scene_id, scene.timings_ms)
        return scene
    dres = depth_scene(frame, seed=seed, max_objects=max_objects, settings=depth_settings)
    scene = Scene(scene_id, modality, frame.intrinsics, support_plane=dres.support, timings_ms=dict(dres.timings_ms),
                  dropped_objects=dres.dropped_objects, unconverged_fits=dres.unconverged_fits)
    if modality == "depth":
        scene.objects = [_depth_object(scene_id, k + 1, o, dres, frame) for k, o in enumerate(dres.objects)]
        return scene
    scene.objects = _fused_objects(frame, scene_id, dres, scene.timings_ms)
    if not scene.objects:
        # depth found no object (too noisy, or nothing above the support): colour alone's objects, so that the faces
        # colour sees are not lost with them
        scene.objects = _colour_objects(frame, scene_id, scene.timings_ms)
    return scene


def _check_frame(frame: RGBD, modality: str) -> None:
    h, w = frame.color.shape[:2]
    if frame.color.ndim != 3 or frame.color.shape[2] != 3 or frame.color.dtype != np.uint8:
        raise InputError(frame.name, f"colour must be (H, W, 3) uint8, got {frame.color.shape} {frame.color.dtype}")
    if frame.depth.shape != (h, w):
        raise InputError(frame.name, f"depth is {frame.depth.shape} but colour is {(h, w)}")
    if modality != "rgb" and not np.any(np.isfinite(frame.depth) & (frame.depth > 0)):
        raise InputError(frame.name, f"modality {modality!r} needs depth, but the depth has no reading")


def _centroid(polys: list[np.ndarray]) -> tuple[float, float]:
    w = np.array([area(p) for p in polys])
    c = np.array([p.mean(axis=0) for p in polys])
    return tuple(float(x) for x in (c * w[:, None]).sum(0) / max(w.sum(), 1e-9))


def _colour_objects(frame: RGBD, scene_id: str, timings: dict[str, float]) -> list[SceneObject]:
    """The colour path on the whole frame: its faces grouped into objects; its stage times added to ``timings``."""
    res = rgb_faces(frame.color)
    for key, v in res.timings_ms.items():
        timings[key] = timings.get(key, 0.0) + v
    return _rgb_objects(scene_id, res.faces, res.groups, res.adjacency)


def _rgb_objects(scene_id: str, faces: list[RGBFace], groups: list[list[int]],
                 adjacency: list[tuple[int, int]]) -> list[SceneObject]:
    out = []
    for k, idx in enumerate(groups, start=1):
        oid = object_id(scene_id, k)
        ids = {i: face_id(scene_id, k, j) for j, i in enumerate(idx, start=1)}
        obj_faces = [Face(ids[i], faces[i].polygon, "rgb", edge_support=faces[i].edge_support,
                          ellipse=faces[i].ellipse) for i in idx]
        adj = [(ids[a], ids[b]) for a, b in adjacency if a in ids and b in ids]
        out.append(SceneObject(oid, obj_faces, adj, int(round(sum(faces[i].area_px for i in idx))),
                               _centroid([faces[i].polygon for i in idx])))
    return out


def _object_pixels(o: DepthObjectResult, stride: int) -> tuple[int, tuple[float, float]]:
    ij = np.argwhere(o.obj.mask)
    return int(len(ij) * stride * stride), (float(ij[:, 1].mean() * stride), float(ij[:, 0].mean() * stride))


def _depth_object(scene_id: str, k: int, o: DepthObjectResult, dres: DepthResult, frame: RGBD) -> SceneObject:
    """The object's planes and cylindrical faces as faces, and the faces beside it that depth did not read
    (holes.unread_faces: a face seen beyond the sensor's grazing angle has no reading at all)."""
    stride = dres.grid.stride
    faces, index = [], {}
    for i, (p, poly) in enumerate(zip(o.planes, o.polygons)):
        if poly is None:
            continue
        index[i] = face_id(scene_id, k, len(faces) + 1)
        faces.append(Face(index[i], poly, "depth", plane=p.plane, points=p.points, plane_rms_m=p.rms_m))
    adj = [(index[a], index[b]) for a, b in o.adjacency if a in index and b in index]
    adj += _curved_faces(scene_id, k, o, faces, index)
    box = _crop_box(o, frame.shape)
    for f in _unread(frame, dres, o, box, grid_to_pixels(o.obj.mask, stride, box), seed=k):
        fid = face_id(scene_id, k, len(faces) + 1)
        faces.append(Face(fid, f.polygon, "depth", plane=f.plane, points=f.points, plane_rms_m=f.rms_m))
        adj += [(index[a], fid) for a in f.neighbours if a in index]
    count, centroid = _object_pixels(o, stride)
    return SceneObject(object_id(scene_id, k), faces, adj, count, centroid, _segment(o, stride, frame.shape))


def _curved_faces(scene_id: str, k: int, o: DepthObjectResult, faces: list[Face], index: dict[int, str]
                  ) -> list[tuple[str, str]]:
    """The depth object's curved faces (cylinders, spheres, cones) appended to ``faces`` (ids go on from their
    count; ``index``: plane index -> face id), and their adjacency to the plane faces."""
    adj = []
    for j, (c, poly) in enumerate(zip(o.curved, o.curved_polygons)):
        if poly is None:
            continue
        fid = face_id(scene_id, k, len(faces) + 1)
        faces.append(Face(fid, poly, "depth", points=c.points, plane_rms_m=c.rms_m, **surface_fields(c)))
        adj += [tuple(sorted((index[i], fid))) for i, jj in o.curved_adjacency if jj == j and i in index]
    return adj


def _segment(o: DepthObjectResult, stride: int, shape: tuple[int, int]) -> np.ndarray:
    """The depth object's cells as a pixel mask over the whole image (h, w)."""
    h, w = shape
    return grid_to_pixels(o.obj.mask, stride, (0, 0, w, h))


def _crop_box(o: DepthObjectResult, shape: tuple[int, int]) -> tuple[int, int, int, int]:
    """The depth object's box (u0, v0, u1, v1) grown by the crop margin (``_CROP_MARGIN``), inside an image of
    ``shape`` (h, w)."""
    h, w = shape
    m = int(round(_CROP_MARGIN * float(np.hypot(h, w))))
    u0, v0, u1, v1 = o.box_px
    return max(0, u0 - m), max(0, v0 - m), min(w, u1 + m), min(h, v1 + m)


def _unread(frame: RGBD, dres: DepthResult, o: DepthObjectResult, box: tuple[int, int, int, int],
            object_px: np.ndarray, seed: int) -> list[UnreadFace]:
    """The faces beside depth object ``o`` that depth did not read (holes.unread_faces), searched in ``box``, where
    ``object_px`` are the object's pixels."""
    known = [p.plane for p in o.planes] + ([dres.support] if dres.support is not None else [])
    # a face of the object lies within its reach: its median depth and extent (holes.unread_faces)
    return unread_faces(frame.depth, dres.grid, object_px, [p.mask for p in o.planes], known, box, seed=seed,
                        reach=o.scale, settings=dres.settings.unread, holes=dres.settings.holes,
                        sensor=dres.settings.sensor)


def _fused_objects(frame: RGBD, scene_id: str, dres: DepthResult, timings: dict[str, float]) -> list[SceneObject]:
    """Each depth object with its faces as rgbd sees them (fuse.fused_faces): depth's faces, confirmed by colour
    edges, and the faces depth could not read where colour edges confirm them."""
    stride = dres.grid.stride
    h, w = frame.shape
    timings.setdefault("edges", 0.0)
    timings.setdefault("fuse", 0.0)
    out = []
    for k, o in enumerate(dres.objects, start=1):
        t0 = time.perf_counter()
        edges_before = timings["edges"]
        box = _crop_box(o, (h, w))
        object_px = grid_to_pixels(o.obj.mask, stride, box)
        faces, pairs = fused_faces(frame, o, object_px, box, _unread(frame, dres, o, box, object_px, seed=k), timings,
                                   dres.settings.holes)
        order = largest_first(faces)
        rank = {i: r for r, i in enumerate(order)}
        for i in order:
            faces[i].id = face_id(scene_id, k, rank[i] + 1)
        adj = sorted(tuple(sorted((faces[a].id, faces[b].id))) for a, b in pairs)
        count, centroid = _object_pixels(o, stride)
        out.append(SceneObject(object_id(scene_id, k), [faces[i] for i in order], adj, count, centroid,
                               _segment(o, stride, (h, w))))
        timings["fuse"] += (time.perf_counter() - t0) * 1e3 - (timings["edges"] - edges_before)
    return out
