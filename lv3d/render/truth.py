"""Ground truth of a rendered scene in the meta.json layout of docs/dataset.md.

A face is listed when it faces the camera and covers at least ``MIN_FACE_PIXELS`` pixels of the face
mask. Its ``polygon`` is the whole 3D face projected to pixels (exact: a convex solid cannot hide its
own front faces; only other objects and the image border can), ordered clockwise on screen, i.e. with
a positive shoelace sum of (u, v); ``visible_fraction`` = mask pixels / polygon area.

Faces of the curved solids (cylinder, cone, sphere) also carry ``surface`` (the exact surface in the
camera frame: plane, cylinder, cone or sphere with its parameters); their ``polygon`` is the outline of
the part that faces the camera, sampled along its curves (not convex for a cylinder's or a cone's side
seen from above), and ``sides`` is 0: no face of theirs has straight sides. Their ``adjacency`` lists the
faces that meet along a rim, with ``"edge": "circle"``.
"""

from __future__ import annotations

import numpy as np

from ..camera import Intrinsics
from ..plane import Plane, dihedral_deg
from .body import Body
from .sampler import Layout

MIN_FACE_PIXELS = 50


def _r(x, nd: int = 6):
    return np.round(np.asarray(x, np.float64), nd).tolist()


def shoelace(poly: np.ndarray) -> float:
    """Signed area sum of an (n, 2) pixel polygon: positive when clockwise on screen (v down)."""
    u, v = poly[:, 0], poly[:, 1]
    return 0.5 * float(np.sum(u * np.roll(v, -1) - np.roll(u, -1) * v))


def plane_of(normal_cam: np.ndarray, point_cam: np.ndarray) -> Plane:
    """Camera-frame plane through ``point_cam`` with normal ``normal_cam``, oriented towards the camera."""
    return Plane.from_arrays(normal_cam, -float(np.dot(normal_cam, point_cam)))


def object_truth(body: Body, k: Intrinsics, mask: np.ndarray | None) -> dict:
    """Faces, adjacency and pose of one solid. With ``mask`` (H, W) uint8 face ids + 1, list visible faces
    with pixel counts; without it, only class, size and pose (for clutter and occluders)."""
    out = {"class": body.solid.cls, "size_m": {k_: round(float(v), 6) for k_, v in body.solid.size_m.items()},
           "object_to_camera": _r(body.to_camera)}
    if mask is None:
        return out
    if body.solid.curved is not None:
        out.update(_curved_faces(body, k, mask))
        return out
    verts = body.vertices()
    normals = body.normals()
    counts = np.bincount(mask.ravel(), minlength=len(body.solid.faces) + 1)
    faces, visible = [], set()
    for i, f in enumerate(body.solid.faces):
        p = verts[list(f)]
        front = float(np.dot(normals[i], p.mean(axis=0))) < 0  # outward normal points back at the camera
        n_px = int(counts[i + 1])
        if not front or n_px < MIN_FACE_PIXELS:
            continue
        poly = k.project(p)
        if shoelace(poly) < 0:
            poly = poly[::-1]
        area = abs(shoelace(poly))
        visible.add(i)
        faces.append({"id": i, "sides": len(f), "visible": True, "pixels": n_px,
                      "polygon": _r(poly, 3), "visible_fraction": round(min(1.0, n_px / max(area, 1e-9)), 4),
                      "plane": plane_of(normals[i], p[0]).to_dict()})
    adjacency = []
    for (a, b), (fa, fb) in sorted(body.solid.edges().items(), key=lambda e: sorted(e[1])):
        if fa in visible and fb in visible:
            i, j = sorted((fa, fb))
            adjacency.append({"faces": [i, j], "dihedral_deg": round(dihedral_deg(normals[i], normals[j]), 4)})
    out.update(faces=faces, adjacency=adjacency)
    return out


def _curved_faces(body: Body, k: Intrinsics, mask: np.ndarray) -> dict:
    """The faces and adjacency of a curved solid (see the module's docstring)."""
    shape = body.solid.curved
    rot, t = body.to_camera[:3, :3], body.to_camera[:3, 3]
    cam = -rot.T @ t  # the camera centre in the object frame
    counts = np.bincount(mask.ravel(), minlength=body.solid.n_faces + 1)
    faces, visible = [], set()
    for i, kind in enumerate(shape.face_kinds()):
        loop = shape.outline(i, cam)
        n_px = int(counts[i + 1])
        if loop is None or n_px < MIN_FACE_PIXELS:
            continue
        poly = k.project(loop @ rot.T + t)
        if shoelace(poly) < 0:
            poly = poly[::-1]
        area = abs(shoelace(poly))
        surface = shape.surface(i, body.to_camera)
        visible.add(i)
        entry = {"id": i, "sides": 0, "visible": True, "pixels": n_px, "polygon": _r(poly, 3),
                 "visible_fraction": round(min(1.0, n_px / max(area, 1e-9)), 4), "surface": surface}
        if kind == "plane":
            entry["plane"] = {"normal": surface["normal"], "offset": surface["offset"]}
        faces.append(entry)
    adjacency = []
    for a, b in shape.meeting():
        if a in visible and b in visible:
            na, nb = shape.rim_normals(a, b)
            adjacency.append({"faces": [a, b], "dihedral_deg": round(dihedral_deg(na, nb), 4), "edge": "circle"})
    return {"faces": faces, "adjacency": adjacency}


def surface_distance(surface: dict, points: np.ndarray) -> np.ndarray:
    """Unsigned distances (m,) of camera-frame points (m, 3) from a face's ``surface`` (its meta.json dict:
    plane, cylinder, cone or sphere; a cone and a cylinder as infinite surfaces of their kind)."""
    p = np.asarray(points, np.float64)
    kind = surface["type"]
    if kind == "plane":
        return np.abs(p @ np.asarray(surface["normal"], float) + float(surface["offset"]))
    if kind == "sphere":
        return np.abs(np.linalg.norm(p - np.asarray(surface["centre"], float), axis=1) - float(surface["radius"]))
    if kind == "cylinder":
        a = np.asarray(surface["axis"], float)
        q = p - np.asarray(surface["point"], float)
        radial = np.linalg.norm(q - np.outer(q @ a, a), axis=1)
        return np.abs(radial - float(surface["radius"]))
    if kind == "cone":
        a = np.asarray(surface["axis"], float)
        q = p - np.asarray(surface["apex"], float)
        along = q @ a
        radial = np.linalg.norm(q - np.outer(along, a), axis=1)
        half = np.radians(float(surface["half_angle_deg"]))
        # distance from the cone's generator in the plane through the axis and the point
        return np.abs(radial * np.cos(half) - along * np.sin(half))
    raise ValueError(f"unknown surface type {kind!r}")


def scene_truth(layout: Layout, target: Body, clutter: list[Body], occluder: Body | None,
                k: Intrinsics, mask: np.ndarray, contacts: list[tuple[str, Body, np.ndarray]] = ()) -> dict:
    """The "truth" block of meta.json. ``contacts``: per solid touching the target its relation
    ("beside", "on_target", "under_target"), body and face-id mask (like ``mask``)."""
    t = object_truth(target, k, mask)
    r = layout.world_to_camera[:3, :3]
    up = r @ np.array([0, 0, 1.0])  # the table's normal, pointing up and so towards the camera
    table = plane_of(up, layout.world_to_camera[:3, 3])  # the world origin lies on the table top
    # the surface the target stands on: the table top, or the top of the box under it
    support = plane_of(up, r @ np.array([0, 0, layout.support_z_m]) + layout.world_to_camera[:3, 3])
    t.update(resting_face=layout.target.resting_face, target_pixels=int(np.count_nonzero(mask)),
             support_plane=support.to_dict(),
             camera={"elevation_deg": round(layout.elevation_deg, 3), "azimuth_deg": round(layout.azimuth_deg, 3),
                     "distance_m": round(layout.distance_m, 4)},
             clutter=[object_truth(c, k, None) for c in clutter],
             occluder=object_truth(occluder, k, None) if occluder is not None else None,
             table_plane=table.to_dict(),
             contacts=[{"relation": rel, **object_truth(b, k, m), "pixels": int(np.count_nonzero(m))}
                       for rel, b, m in contacts])
    return t


def rasterise_polygon(poly: np.ndarray, shape: tuple[int, int]) -> np.ndarray:
    """(H, W) bool: pixel centres inside the convex pixel polygon ``poly`` (n, 2), either orientation
    (the same rule the ray caster follows, so it matches a face mask up to ties on edges)."""
    poly = np.asarray(poly, np.float64)
    if shoelace(poly) < 0:
        poly = poly[::-1]
    h, w = shape
    u0, v0 = np.floor(poly.min(axis=0)).astype(int)
    u1, v1 = np.ceil(poly.max(axis=0)).astype(int)
    u0, v0, u1, v1 = max(u0, 0), max(v0, 0), min(u1, w - 1), min(v1, h - 1)
    out = np.zeros(shape, bool)
    if u0 > u1 or v0 > v1:
        return out
    u, v = np.meshgrid(np.arange(u0, u1 + 1), np.arange(v0, v1 + 1))
    inside = np.ones(u.shape, bool)
    for (a, b), (c, d) in zip(poly, np.roll(poly, -1, axis=0)):
        inside &= (c - a) * (v - b) - (d - b) * (u - a) >= 0  # on the inner side of a clockwise loop
    out[v0:v1 + 1, u0:u1 + 1] = inside
    return out
