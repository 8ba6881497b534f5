"""``perceive``: one frame and a modality in, a :class:`lv3d.scene.Scene` out."""

from __future__ import annotations

import time

import numpy as np

from ..errors import InputError
from ..facts import MODALITIES, face_id, object_id
from ..rgbd import RGBD
from ..scene import Face, Scene, SceneObject
from .depth import MAX_OBJECTS, DepthObjectResult, DepthResult, depth_scene
from .edge_on import on_unclaimed_plane, points_dropped
from .boundary import grid_to_pixels
from .confirm import replace_unconfirmed, unconfirmed
from .face_plane import angle_deg, fit_face_plane
from .fuse import match_faces
from .holes import UnreadFace, add_hole_faces, unread_faces
from .plane_outline import simplify_on_plane
from .polygons import area, rasterize
from .rgb import RGBFace, rgb_faces
from .support import noise_threshold

_CROP_MARGIN_PX = 14
# a colour face with as many corners as its plane's depth outline, which leaves out this much of that outline
# where no other colour face lies, traced only part of the face: the depth outline is kept (session 21)
_PART_LEFT_OUT = 0.25


def perceive(frame: RGBD, modality: str, scene_id: str = "s000000", seed: int = 0,
             max_objects: int = MAX_OBJECTS) -> Scene:
    """Objects and faces of ``frame`` as a system that sees ``modality`` ('rgb', 'depth', 'rgbd') finds them.

    At most ``max_objects`` objects found by depth are described (the largest); ``Scene.dropped_objects`` counts
    the rest. Object ids are ``<scene>_o<k>`` and face ids ``<scene>_o<k>_f<j>``, k and j from 1, objects largest first.
    ``Scene.timings_ms`` holds the time of each stage. Deterministic for a given ``seed``."""
    if modality not in MODALITIES:
        raise InputError("--modality", f"unknown modality {modality!r}; choose one of {', '.join(MODALITIES)}")
    if not isinstance(max_objects, int) or max_objects < 1:
        raise InputError("--max-objects", f"must be a whole number of at least 1, got {max_objects!r}")
    _check_frame(frame, modality)
    if modality == "rgb":
        scene = Scene(scene_id, modality, frame.intrinsics, timings_ms={})
        scene.objects = _colour_objects(frame, scene_id, scene.timings_ms)
        return scene
    dres = depth_scene(frame, seed=seed, max_objects=max_objects)
    scene = Scene(scene_id, modality, frame.intrinsics, support_plane=dres.support, timings_ms=dict(dres.timings_ms),
                  dropped_objects=dres.dropped_objects)
    if modality == "depth":
        scene.objects = [_depth_object(scene_id, k + 1, o, dres, frame) for k, o in enumerate(dres.objects)]
        return scene
    scene.objects = _fused_objects(frame, scene_id, dres, scene.timings_ms)
    if not scene.objects:
        # depth found no object (too noisy, or nothing above the support): the colour path runs only inside
        # depth objects' boxes, so without this a face seen by colour alone would be lost with the object
        scene.objects = _colour_objects(frame, scene_id, scene.timings_ms)
    else:
        # objects of depth faces alone: fragments of a noisy solid that colour may see whole (confirm.py)
        weak = unconfirmed(scene.objects)
        if weak:
            colour = _colour_objects(frame, scene_id, scene.timings_ms, _box(scene.objects, weak, frame.shape))
            scene.objects = replace_unconfirmed(scene.objects, weak, colour, frame.shape, scene_id)
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


def _colour_objects(frame: RGBD, scene_id: str, timings: dict[str, float],
                    box: tuple[int, int, int, int] | None = None) -> list[SceneObject]:
    """The colour path on the whole frame (or in ``box`` = (u0, v0, u1, v1) pixels): its faces grouped into
    objects; its stage times added to ``timings``."""
    res = rgb_faces(frame.color, box=box, colour_alone=True)
    for key, v in res.timings_ms.items():
        timings[key] = timings.get(key, 0.0) + v
    return _rgb_objects(scene_id, res.faces, res.groups, res.adjacency)


def _box(objects: list[SceneObject], which: list[int], shape: tuple[int, int]) -> tuple[int, int, int, int]:
    """The box around the faces of ``objects[i]`` for i in ``which``, grown by a margin that lets a solid seen
    in fragments be seen whole: a third of the box's larger side, at least the crop margin."""
    p = np.concatenate([np.asarray(f.polygon, float) for i in which for f in objects[i].faces])
    (u0, v0), (u1, v1) = p.min(0), p.max(0)
    m = max(_CROP_MARGIN_PX, (max(u1 - u0, v1 - v0)) / 3)
    h, w = shape
    return (max(0, int(u0 - m)), max(0, int(v0 - m)), min(w, int(np.ceil(u1 + m))), min(h, int(np.ceil(v1 + m))))


def _rgb_objects(scene_id: str, faces: list[RGBFace], groups: list[list[int]],
                 adjacency: list[tuple[int, int]]) -> list[SceneObject]:
    out = []
    for k, idx in enumerate(groups, start=1):
        oid = object_id(scene_id, k)
        ids = {i: face_id(scene_id, k, j) for j, i in enumerate(idx, start=1)}
        obj_faces = [Face(ids[i], faces[i].polygon, "rgb", edge_support=faces[i].edge_support) for i in idx]
        adj = [(ids[a], ids[b]) for a, b in adjacency if a in ids and b in ids]
        out.append(SceneObject(oid, obj_faces, adj, int(round(sum(faces[i].area_px for i in idx))),
                               _centroid([faces[i].polygon for i in idx])))
    return out


def _object_pixels(o: DepthObjectResult, stride: int) -> tuple[int, tuple[float, float]]:
    ij = np.argwhere(o.obj.mask)
    return int(len(ij) * stride * stride), (float(ij[:, 1].mean() * stride), float(ij[:, 0].mean() * stride))


def _depth_object(scene_id: str, k: int, o: DepthObjectResult, dres: DepthResult, frame: RGBD) -> SceneObject:
    """The object's planes as faces, and the faces beside it that depth did not read (holes.unread_faces: on
    realsense renders most faces depth alone missed had no reading at all, docs/perception.md, session 29)."""
    stride = dres.grid.stride
    faces, index = [], {}
    for i, (p, poly) in enumerate(zip(o.planes, o.polygons)):
        if poly is None:
            continue
        index[i] = face_id(scene_id, k, len(faces) + 1)
        faces.append(Face(index[i], poly, "depth", plane=p.plane, points=p.points, plane_rms_m=p.rms_m))
    adj = [(index[a], index[b]) for a, b in o.adjacency if a in index and b in index]
    box = _crop_box(o, frame.shape)
    for f in _unread(frame, dres, o, box, grid_to_pixels(o.obj.mask, stride, box), seed=k):
        fid = face_id(scene_id, k, len(faces) + 1)
        faces.append(Face(fid, f.polygon, "depth", plane=f.plane, points=f.points, plane_rms_m=f.rms_m))
        adj += [(index[a], fid) for a in f.neighbours if a in index]
    count, centroid = _object_pixels(o, stride)
    return SceneObject(object_id(scene_id, k), faces, adj, count, centroid, _segment(o, stride, frame.shape))


def _segment(o: DepthObjectResult, stride: int, shape: tuple[int, int]) -> np.ndarray:
    """The depth object's cells as a pixel mask over the whole image (h, w)."""
    h, w = shape
    return grid_to_pixels(o.obj.mask, stride, (0, 0, w, h))


def _crop_box(o: DepthObjectResult, shape: tuple[int, int]) -> tuple[int, int, int, int]:
    """The depth object's box (u0, v0, u1, v1) grown by the crop margin, inside an image of ``shape`` (h, w)."""
    h, w = shape
    u0, v0, u1, v1 = o.box_px
    return (max(0, u0 - _CROP_MARGIN_PX), max(0, v0 - _CROP_MARGIN_PX),
            min(w, u1 + _CROP_MARGIN_PX), min(h, v1 + _CROP_MARGIN_PX))


def _unread(frame: RGBD, dres: DepthResult, o: DepthObjectResult, box: tuple[int, int, int, int],
            object_px: np.ndarray, seed: int) -> list[UnreadFace]:
    """The faces beside depth object ``o`` that depth did not read (holes.unread_faces), searched in ``box``, where
    ``object_px`` are the object's pixels."""
    known = [p.plane for p in o.planes] + ([dres.support] if dres.support is not None else [])
    return unread_faces(frame.depth, dres.grid, object_px, [p.mask for p in o.planes], known, box, seed=seed)


def _fused_objects(frame: RGBD, scene_id: str, dres: DepthResult, timings: dict[str, float]) -> list[SceneObject]:
    """Colour faces searched only in a crop around each depth object, matched to its planes."""
    stride = dres.grid.stride
    h, w = frame.shape
    for key in ("edges", "segments", "faces", "fuse"):
        timings.setdefault(key, 0.0)
    out = []
    for k, o in enumerate(dres.objects, start=1):
        box = _crop_box(o, (h, w))
        res = rgb_faces(frame.color, box=box)
        for key, v in res.timings_ms.items():
            timings[key] += v
        t0 = time.perf_counter()
        # colour faces of this object: mostly on its depth mask (the crop also holds table and neighbours)
        obj_grown = _dilate(o.obj.mask)
        grown = grid_to_pixels(obj_grown, stride, box)
        plane_px = [grid_to_pixels(q.mask, stride, box) for q in o.planes]  # once per object, not per polygon
        off = np.array([box[0], box[1]], float)
        shape = (box[3] - box[1], box[2] - box[0])
        poly_px = [rasterize(f.polygon - off, shape) for f in res.faces]
        mine = [i for i in range(len(res.faces)) if _inside(poly_px[i], grown) >= 0.6]
        polys = [res.faces[i].polygon for i in mine]
        match = match_faces(polys, [p.mask for p in o.planes], stride, box, min_iou=0.5)
        faces: list[Face] = []
        plane_face: dict[int, int] = {}
        colour_face: dict[int, int] = {}
        on_plane = [max((_inside(poly_px[i], q) for q in plane_px), default=0.0) for i in mine]
        claimed = set(match.values())
        piece: set[int] = set()  # colour faces on a plane another face has: kept only if merged into it
        # colour faces seen edge-on (edge_on.py): their points dropped as flying, or on a plane depth merged into a
        # neighbour's; kept however small
        edge_on: set[int] = set()
        # colour faces that merged two faces across a low-contrast edge take their plane's depth outline first,
        # so that the other faces' choices (below) see that outline, not the merged one
        swallowing = {a: o.polygons[m] for a, m in match.items() if o.polygons[m] is not None
                      and _swallows_plane(poly_px[mine[a]], m, o, plane_px)
                      and fit_face_plane(res.faces[mine[a]].polygon, dres.grid, seed=k) is None}
        swallowing_px = {a: rasterize(poly - off, shape) for a, poly in swallowing.items()}
        matched_poly = {a: swallowing[a] if a in swallowing else
                        _matched_polygon(res.faces[mine[a]].polygon, m, o, poly_px[mine[a]], off, dres,
                                         _off_plane_px(mine, poly_px, swallowing_px, plane_px[m], shape),
                                         seed=k) for a, m in match.items()}
        matched_px = np.zeros(shape, bool)  # the pixels that colour faces matched to a plane explain
        for a, poly in matched_poly.items():
            own_outline = poly is res.faces[mine[a]].polygon
            matched_px |= swallowing_px[a] if a in swallowing else poly_px[mine[a]] if own_outline \
                else rasterize(poly - off, shape)
        for a, i in enumerate(mine):
            f = res.faces[i]
            if a in match:
                p = o.planes[match[a]]
                poly = matched_poly[a]
                face = Face("", poly, "rgbd", plane=p.plane, points=p.points, edge_support=f.edge_support,
                            plane_rms_m=p.rms_m)
                plane_face[match[a]] = len(faces)
            else:
                own = _own_plane(f.polygon, o, dres, obj_grown, on_plane[a], plane_px, poly_px[i], claimed,
                                 seed=k)
                if own is None and on_plane[a] >= 0.5 and not on_unclaimed_plane(f, poly_px[i], plane_px, claimed):
                    continue  # a patch of print or shadow on a plane that depth already has: not a face
                if own is None and _spans_planes(poly_px[i], o, plane_px):
                    continue  # two faces of one shade traced as one: depth's planes give them (below)
                if own is None:
                    face = Face("", f.polygon, "rgb", edge_support=f.edge_support)
                    # a sliver on such a plane (just tested), or one whose points were all dropped as flying
                    if on_plane[a] >= 0.5 or points_dropped(f.polygon, frame.depth, dres.grid, obj_grown):
                        edge_on.add(len(faces))
                else:
                    (plane, pts, rms), absorbed, on_claimed = own
                    if on_claimed:
                        piece.add(len(faces))
                    face = Face("", f.polygon, "rgbd", plane=plane, points=pts, edge_support=f.edge_support,
                                plane_rms_m=rms)
                    whole = [j for j in absorbed if o.polygons[j] is not None
                             and _inside(plane_px[j] & ~poly_px[i], matched_px) < 0.5]
                    if whole:
                        # the plane reaches well beyond the colour face into pixels no other face explains:
                        # the colour face is a piece of it (cut off by texture or a shadow), the plane is the face
                        p = o.planes[whole[0]]
                        face = Face("", o.polygons[whole[0]], "rgbd", plane=p.plane, points=p.points,
                                    edge_support=f.edge_support, plane_rms_m=p.rms_m)
                    for j in absorbed:
                        plane_face[j] = len(faces)
                        claimed.add(j)
            colour_face[i] = len(faces)
            faces.append(face)
        for j, (p, poly) in enumerate(zip(o.planes, o.polygons)):
            if j not in plane_face and poly is not None:
                plane_face[j] = len(faces)
                faces.append(Face("", poly, "depth", plane=p.plane, points=p.points, plane_rms_m=p.rms_m))
        pairs = {tuple(sorted((plane_face[a], plane_face[b]))) for a, b in o.adjacency
                 if a in plane_face and b in plane_face}
        pairs |= {tuple(sorted((colour_face[a], colour_face[b]))) for a, b in res.adjacency
                  if a in colour_face and b in colour_face}
        alias = _merge_coplanar(faces, pairs)
        pairs = {tuple(sorted((alias.get(a, a), alias.get(b, b)))) for a, b in pairs}
        pairs = {(a, b) for a, b in pairs if a != b}
        merged = set(alias) | set(alias.values())
        keep = [i for i in _reliable(faces, edge_on) if i not in alias and (i not in piece or i in merged)]
        keep, masks = _drop_covered(faces, keep, shape, off)
        object_px = grid_to_pixels(o.obj.mask, stride, box)
        keep += add_hole_faces(faces, pairs, keep, frame, box, object_px, res.edge_dist, masks=masks,
                               unread=_unread(frame, dres, o, box, object_px, seed=k))
        pairs = {(a, b) for a, b in pairs if a in keep and b in keep}
        _refine_outlines(faces, keep, frame.intrinsics)
        # stable ids: faces largest first
        order = sorted(keep, key=lambda i: (-area(faces[i].polygon), float(faces[i].polygon[0, 0])))
        rank = {i: r for r, i in enumerate(order)}
        for i in order:
            faces[i].id = face_id(scene_id, k, rank[i] + 1)
        faces = [faces[i] for i in order]
        adj = sorted((min(faces[rank[a]].id, faces[rank[b]].id), max(faces[rank[a]].id, faces[rank[b]].id))
                     for a, b in pairs)
        count, centroid = _object_pixels(o, stride)
        out.append(SceneObject(object_id(scene_id, k), faces, adj, count, centroid, _segment(o, stride, (h, w))))
        timings["fuse"] += (time.perf_counter() - t0) * 1e3
    return out


def _refine_outlines(faces: list[Face], keep: list[int], k) -> None:
    """Outlines of the kept faces with planes, in place: corners judged on each face's own plane, where a face
    seen edge-on is not squeezed (see :func:`lv3d.perception.plane_outline.simplify_on_plane`); ``k``: the
    camera intrinsics. (Putting back corners where three planes meet, as depth outlines do, is left out here:
    on dev seed 2000 it added a wrong corner to a colour outline.)"""
    for i in keep:
        if faces[i].plane is not None:
            faces[i].polygon = simplify_on_plane(faces[i].polygon, faces[i].plane, k)


# A face seen by one sensor only and small beside the object's faces is most often a face seen at a
# grazing angle, cut into slivers whose outlines (a quadrilateral's two triangles) and missing plane
# give wrong side counts; a solid's view keeps its large faces, which carry what the concept needs.
_MIN_COLOUR_ONLY_FRACTION = 0.12   # of the object's total face area (px), colour face with no depth plane
_MIN_DEPTH_ONLY_FRACTION = 0.05    # depth plane with no colour face


def _reliable(faces: list[Face], exempt: set[int] = frozenset()) -> list[int]:
    """Indices of the faces to keep: every face seen by both sensors, a one-sensor face only when it is not
    small beside the others (fractions of the summed polygon areas above) or is in ``exempt``."""
    areas = [area(f.polygon) for f in faces]
    total = max(sum(areas), 1e-9)
    floor = {"rgb": _MIN_COLOUR_ONLY_FRACTION, "depth": _MIN_DEPTH_ONLY_FRACTION}
    return [i for i, f in enumerate(faces) if i in exempt or areas[i] >= floor.get(f.provenance, 0.0) * total]


# a colour face that depth segmentation missed is a face of its own when the points inside it fit a plane that
# is not the plane it was drawn on (an edge between two planes turns the normal by far more than this)
_DISTINCT_PLANE_DEG = 15.0
_SAME_PLANE_DEG = 12.0     # an unmatched depth plane this close to a colour face's own plane is that face


def _own_plane(poly: np.ndarray, o: DepthObjectResult, dres: DepthResult, obj_grown: np.ndarray, on_plane: float,
               plane_px: list[np.ndarray], poly_px: np.ndarray, claimed: set[int], seed: int):
    """For a colour face that no depth plane matched: its own plane fitted to the depth points inside it, the
    unmatched depth planes that are that face badly segmented, and whether it lies on (and along) a plane that
    another colour face has already; None when the points do not make a plane or lie on the support plane."""
    # on the object's cells grown a little (``obj_grown``): a face seen edge-on loses cells to the depth-jump
    # cuts of segmentation
    fit = fit_face_plane(poly, dres.grid, seed=seed, on_mask=obj_grown)
    if fit is None:
        return None
    plane, pts, _ = fit
    if dres.support is not None:
        # on the support plane, or a patch of it whose few noisy points tilt the fit: a shadow or the table
        height = float(np.median(dres.support.distance(pts)))
        if angle_deg(plane, dres.support) < _SAME_PLANE_DEG or \
                height < 0.5 * noise_threshold(float(np.median(pts[:, 2]))):
            return None
    # drawn on a plane that another colour face already has, and not turned away from it: print or shadow, or
    # the other part of a face that a false colour edge cut in two (told apart later: see _merge_coplanar)
    over = [j for j, q in enumerate(plane_px) if j in claimed and _inside(poly_px, q) >= 0.5]
    if any(angle_deg(plane, o.planes[j].plane) < _DISTINCT_PLANE_DEG for j in over):
        return fit, [], True
    absorbed = [j for j, q in enumerate(o.planes) if j not in claimed
                and angle_deg(plane, q.plane) < _SAME_PLANE_DEG and np.count_nonzero(plane_px[j] & poly_px)]
    return fit, absorbed, False


def _matched_polygon(colour: np.ndarray, j: int, o: DepthObjectResult, colour_px: np.ndarray, off: np.ndarray,
                     dres: DepthResult, all_colour_px: np.ndarray, seed: int) -> np.ndarray:
    """The polygon of a colour face matched to plane ``j`` (one that swallowed another plane takes the depth one
    before this is asked): see :func:`_pick_polygon`; the colour one when the depth outline reaches over the
    other colour faces (``all_colour_px``: the pixels over the crop of the colour faces not on plane ``j``,
    :func:`_off_plane_px`)."""
    depth = o.polygons[j]
    if depth is None:
        return colour
    dm = rasterize(depth - off, colour_px.shape)
    beyond = dm & ~colour_px
    if np.count_nonzero(beyond) >= 0.1 * max(1, np.count_nonzero(dm)) and _inside(beyond, all_colour_px) >= 0.5:
        return colour
    if len(depth) == len(colour):
        # as many corners, but the colour outline leaves out part of the plane's outline that no other colour face
        # holds: colour lost an edge inside the face (a shadow or shading line) and traced part of it
        return depth if np.count_nonzero(beyond) >= _PART_LEFT_OUT * max(1, np.count_nonzero(dm)) else colour
    if len(colour) > len(depth):
        # more colour corners: the depth outline may have lost a corner region of a face seen obliquely (its
        # mask thins out there); the colour one is right when it holds the depth one and is all on its plane
        # (nearly every point: a sliver of the next face taken in is a few per cent of them)
        fit = fit_face_plane(colour, dres.grid, seed=seed, min_inliers=0.97)
        if _inside(dm, colour_px) >= 0.9 and fit is not None and \
                angle_deg(fit[0], o.planes[j].plane) < _SAME_PLANE_DEG:
            return colour
    return _pick_polygon(colour, depth, colour_px, off)


def _off_plane_px(mine: list[int], poly_px: list[np.ndarray], swallowing_px: dict[int, np.ndarray],
                  plane: np.ndarray, shape: tuple[int, int]) -> np.ndarray:
    """The pixels of the colour faces ``mine`` (a swallowing face's depth outline in place of its own) that do not
    lie mostly on the plane of pixels ``plane``: the faces that may explain where that plane's depth outline
    reaches beyond the colour face matched to it. A colour face mostly on the same plane is a piece of that face
    (cut off by a shadow or a shading line), not a neighbour."""
    out = np.zeros(shape, bool)
    for a, i in enumerate(mine):
        px = swallowing_px.get(a, poly_px[i])
        if _inside(px, plane) < 0.5:
            out |= px
    return out


def _held(poly_px: np.ndarray, plane_px: list[np.ndarray], fraction: float) -> list[int]:
    """The planes (indices into ``plane_px``, their pixels) that a colour face (pixels ``poly_px``) holds at least
    ``fraction`` of."""
    return [j for j, q in enumerate(plane_px) if _inside(q, poly_px) >= fraction]


def _turned_apart(o: DepthObjectResult, a: int, b: int) -> bool:
    """Whether planes ``a`` and ``b`` of ``o`` are two faces' planes, not one face's (``_DISTINCT_PLANE_DEG``)."""
    return angle_deg(o.planes[a].plane, o.planes[b].plane) >= _DISTINCT_PLANE_DEG


# a colour outline that strays over an edge takes in a few per cent of the next plane's cells (up to ~15% on dev
# seed 4343); one that went on across a faint edge, a third of it (a pentagonal prism's top taking in its end)
_SWALLOWED_FRACTION = 0.25


def _swallows_plane(poly_px: np.ndarray, own: int, o: DepthObjectResult, plane_px: list[np.ndarray]) -> bool:
    """True when a colour face matched to plane ``own`` also holds a good part (``_SWALLOWED_FRACTION``) of another
    plane that is turned away from it: the colour outline took in part of the next face across a shared edge
    with too little contrast."""
    return any(j != own and _turned_apart(o, j, own) for j in _held(poly_px, plane_px, _SWALLOWED_FRACTION))


def _spans_planes(poly_px: np.ndarray, o: DepthObjectResult, plane_px: list[np.ndarray]) -> bool:
    """True when a colour face holds most of two planes that are turned away from each other: its outline went
    round two faces whose shared edge had too little contrast (two faces of one shade)."""
    held = _held(poly_px, plane_px, 0.5)
    return any(_turned_apart(o, a, b) for n, a in enumerate(held) for b in held[n + 1:])


_COPLANAR_DEG = 5.0


def _merge_coplanar(faces: list[Face], pairs: set[tuple[int, int]], max_excess: float = 0.1) -> dict[int, int]:
    """Merges, in place, neighbouring faces that lie on one plane (normals within ``_COPLANAR_DEG``, each one's
    points within the depth noise of the other's plane) and together tile a convex region (their hull exceeds
    the sum of their areas by at most ``max_excess``): a face cut in two by a line the colour image suggested (a
    shading step, a missed diagonal). Returns merged-away index -> the index it went into."""
    import cv2

    from .polygons import clockwise, simplify
    from .support import refine

    alias: dict[int, int] = {}
    for a, b in sorted(pairs):
        a, b = alias.get(a, a), alias.get(b, b)
        fa, fb = faces[a], faces[b]
        if a == b or fa.plane is None or fb.plane is None or fa.points is None or fb.points is None:
            continue
        if angle_deg(fa.plane, fb.plane) >= _COPLANAR_DEG:
            continue
        tol = noise_threshold(float(np.median(fa.points[:, 2])))
        if np.median(np.abs(fa.plane.distance(fb.points))) > tol or \
                np.median(np.abs(fb.plane.distance(fa.points))) > tol:
            continue
        hull = cv2.convexHull(np.concatenate([fa.polygon, fb.polygon]).astype(np.float32)).reshape(-1, 2)
        hull = clockwise(simplify(hull.astype(np.float64)))
        if area(hull) > (1 + max_excess) * (area(fa.polygon) + area(fb.polygon)):
            continue
        pts = np.concatenate([fa.points, fb.points])
        plane = refine(pts.astype(np.float64))
        rms = float(np.sqrt(np.mean(plane.distance(pts) ** 2)))
        prov = "rgbd" if "rgbd" in (fa.provenance, fb.provenance) else fa.provenance
        faces[a] = Face("", hull, prov, plane=plane, points=pts, edge_support=fa.edge_support, plane_rms_m=rms)
        alias[b] = a
        for k, v in alias.items():
            if v == b:
                alias[k] = a
    return alias


def _drop_covered(faces: list[Face], keep: list[int], shape: tuple[int, int], off: np.ndarray,
                  max_covered: float = 0.5) -> tuple[list[int], dict[int, np.ndarray]]:
    """``keep`` without the depth-only faces lying mostly (> ``max_covered`` of their pixels) on other kept
    faces that have planes: a plane that straddles an edge, or a face's plane found a little off its place,
    left over when colour faces took the pixels around it. A plane that one colour face covers but that is
    turned away from that face's plane stays: the colour outline merged it (an edge without contrast). Also
    returns the kept faces' masks (``shape`` crop at pixel offset ``off``), for the next step to reuse."""
    masks = {i: rasterize(faces[i].polygon - off, shape) for i in keep}
    out = []
    for i in keep:
        if faces[i].provenance == "depth":
            cover = {j: np.count_nonzero(masks[i] & masks[j]) for j in keep
                     if j != i and faces[j].provenance == "rgbd"}
            others = np.zeros(shape, bool)
            for j in cover:
                others |= masks[j]
            if _inside(masks[i], others) > max_covered:
                top = max(cover, key=lambda j: (cover[j], -j))
                merged = cover[top] > max_covered * np.count_nonzero(masks[i]) and \
                    angle_deg(faces[top].plane, faces[i].plane) >= _DISTINCT_PLANE_DEG
                if not merged:
                    continue
        out.append(i)
    return out, {i: masks[i] for i in out}


def _inside(poly_px: np.ndarray, mask_px: np.ndarray) -> float:
    """Fraction of a rasterised polygon's pixels that lie on a pixel mask of the same crop (both bool)."""
    a = np.count_nonzero(poly_px)
    return float(np.count_nonzero(poly_px & mask_px) / a) if a else 0.0


def _dilate(mask: np.ndarray) -> np.ndarray:
    import cv2

    return cv2.dilate(mask.astype(np.uint8), np.ones((3, 3), np.uint8), iterations=2).astype(bool)


def _pick_polygon(colour: np.ndarray, depth: np.ndarray | None, colour_px: np.ndarray, off: np.ndarray,
                  min_iou: float = 0.75) -> np.ndarray:
    """The polygon a fused face keeps: the colour one (sharper corners) when it has as many sides as the depth
    one. Otherwise the depth one, whose sides lie on plane intersections, unless the colour one has fewer sides
    and covers nearly the same pixels (IoU >= ``min_iou``; ``colour_px``: its mask over the crop at pixel
    offset ``off``): then the depth outline has a rounded or cut-off corner, while a colour face that merged two
    faces would reach over the neighbouring plane."""
    if depth is None or len(colour) == len(depth):
        return colour
    if len(colour) < len(depth):
        dm = rasterize(depth - off, colour_px.shape)
        inter = np.count_nonzero(dm & colour_px)
        if inter >= min_iou * max(1, np.count_nonzero(dm | colour_px)):
            return colour
    return depth
