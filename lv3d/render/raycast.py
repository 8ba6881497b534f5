"""One ray per pixel through open3d's RaycastingScene (Embree, CPU), in the camera frame.

Rays leave the camera centre with direction ((u - cx)/fx, (v - cy)/fy, 1), so the hit parameter
``t_hit`` is the depth z itself (not the length along the ray).
"""

from __future__ import annotations

from dataclasses import dataclass, field
from functools import lru_cache

import cv2
import numpy as np
import open3d as o3d

from ..camera import Intrinsics
from .body import Body, clip_near
from .shadows import soft_shadow


@dataclass(frozen=True)
class Hits:
    """What each pixel sees, all (H, W): ``depth`` z in metres (float32, 0 = nothing hit); ``body`` index
    into the bodies cast against and ``face`` the face id within it (-1 = none); ``gface`` the face's
    index into the flat per-face tables ``face_normal`` (F, 3) (camera-frame outward unit normals) and
    ``face_offset`` (F,) (n . X + offset = 0 on the face's plane). ``shadow``: float32 in 0..1, the
    fraction of the light blocked (all 0 when no light was given). The flat tables hold a curved solid's
    facets; its pixels get the first facet of the face they see, and the pixels on a curved face are
    listed in ``curved_idx`` (flat pixel indices, ascending) with the true surface's camera-frame outward
    unit normal in ``curved_normal`` (m, 3) float64."""

    depth: np.ndarray
    body: np.ndarray
    face: np.ndarray
    gface: np.ndarray
    face_normal: np.ndarray
    face_offset: np.ndarray
    shadow: np.ndarray  # (H, W) float32 0..1
    rays: np.ndarray  # (H, W, 3) float32 pixel ray directions with z = 1
    curved_idx: np.ndarray = field(default_factory=lambda: np.zeros(0, np.int64))
    curved_normal: np.ndarray = field(default_factory=lambda: np.zeros((0, 3)))

    def points(self) -> np.ndarray:
        """(H, W, 3) float32 camera-frame hit points (metres); zeros where nothing was hit."""
        return self.rays * self.depth[..., None]


@lru_cache(maxsize=8)
def pixel_rays(k: Intrinsics) -> np.ndarray:
    """(H, W, 3) float32 ray directions with z = 1 for every pixel centre."""
    u, v = np.meshgrid(np.arange(k.width, dtype=np.float64), np.arange(k.height, dtype=np.float64))
    d = np.stack([(u - k.cx) / k.fx, (v - k.cy) / k.fy, np.ones_like(u)], axis=-1)
    d = d.astype(np.float32)
    d.setflags(write=False)  # cached and shared between calls
    return d


_RAY_PLANES: dict = {}


def ray_planes(shape: tuple[int, int], rays: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The x and y components of ``rays`` (H, W, 3) as contiguous (H, W) arrays (cached per image size)."""
    key = (shape, rays[0, 0, 0].item(), rays[-1, -1, 1].item())
    if key not in _RAY_PLANES:
        _RAY_PLANES.clear()
        _RAY_PLANES[key] = (np.ascontiguousarray(rays[..., 0]), np.ascontiguousarray(rays[..., 1]))
    return _RAY_PLANES[key]


@lru_cache(maxsize=8)
def ray_lengths(k: Intrinsics) -> np.ndarray:
    """(H, W) float32 lengths of the pixel rays of :func:`pixel_rays`."""
    n = np.linalg.norm(pixel_rays(k), axis=-1)
    n.setflags(write=False)
    return n


@lru_cache(maxsize=8)
def rays_from_origin(k: Intrinsics) -> np.ndarray:
    """(H, W, 6) float32 rays (origin 0, direction with z = 1) for open3d."""
    d = pixel_rays(k)
    r = np.concatenate([np.zeros_like(d), d], axis=-1)
    r.setflags(write=False)
    return r


def build_scene(bodies: list[Body]) -> tuple[o3d.t.geometry.RaycastingScene, np.ndarray, np.ndarray, np.ndarray]:
    """A raycasting scene of ``bodies``. Also returns lookup tables: per geometry id the offset of its
    first triangle, and per global triangle the body index and the face id within the body."""
    scene = o3d.t.geometry.RaycastingScene()
    offsets, tri_body, tri_face = [], [], []
    n = 0
    for i, b in enumerate(bodies):
        tris, ids = b.solid.triangles()
        gid = scene.add_triangles(o3d.core.Tensor(b.vertices().astype(np.float32)),
                                  o3d.core.Tensor(tris.astype(np.uint32)))
        assert gid == i, "open3d numbers geometries in the order they are added"
        offsets.append(n)
        tri_body.append(np.full(len(ids), i, np.int32))
        tri_face.append(ids)
        n += len(ids)
    return scene, np.asarray(offsets, np.int64), np.concatenate(tri_body), np.concatenate(tri_face)


def raycast(bodies: list[Body], k: Intrinsics, light_cam: np.ndarray | None = None, nthreads: int = 1,
            background: int = 0) -> Hits:
    """What each pixel sees of ``bodies`` (camera frame); with ``light_cam`` (unit vector towards a
    directional light, camera frame) also which points lie in shadow (:mod:`lv3d.render.shadows`).

    The solids are ray cast with Embree (open3d), over the image window they can cover. The first
    ``background`` bodies are big flat surfaces (table slab, floor, wall) that would cost most of the
    ray casting time (open3d's per-hit work): each of their faces is filled as a polygon with
    OpenCV and z-buffered with the exact depth of its plane at every pixel centre.
    """
    face_base = np.cumsum([0] + [len(b.solid.faces) for b in bodies])
    # per flat face: its body and its id within the body; a last entry -1 answers gface = -1 (nothing hit)
    face_body = np.append(np.repeat(np.arange(len(bodies), dtype=np.int32), np.diff(face_base)), np.int32(-1))
    face_id = np.append(np.concatenate([b.solid.face_ids() for b in bodies]), np.int32(-1))
    normals = np.concatenate([b.normals() for b in bodies])
    offsets_f = np.concatenate([-np.einsum("fc,fc->f", b.normals(), b.vertices()[[f[0] for f in b.solid.faces]])
                                for b in bodies])
    depth, gface = _fill_background(bodies[:background], normals, offsets_f, k)

    solids = bodies[background:]
    scene = None
    if solids:
        scene, offsets, tri_body, tri_face = build_scene(solids)
        idx = _silhouette_pixels(solids, k)
        if len(idx):
            out = scene.cast_rays(o3d.core.Tensor(rays_from_origin(k).reshape(-1, 6)[idx]), nthreads=nthreads)
            t = out["t_hit"].numpy()
            hit = t < depth.ravel()[idx]  # inf where nothing was hit: never nearer
            idx, t = idx[hit], t[hit]
            tri = offsets[out["geometry_ids"].numpy()[hit]] + out["primitive_ids"].numpy()[hit]
            depth.ravel()[idx] = t
            gface.ravel()[idx] = face_base[background + tri_body[tri]] + tri_face[tri]
    curved_idx, curved_normal = _exact_curved(bodies, face_base, face_body, depth, gface, k)
    depth[gface < 0] = 0  # inf where nothing was hit
    body = np.take(face_body, gface)
    face = np.take(face_id, gface)
    if light_cam is not None:
        light = np.asarray(light_cam, float)
        not_receiver, extra = None, None
        if len(curved_idx):  # curved faces take their shadows from shadow rays, not from the polygons
            not_receiver = np.zeros(len(normals), bool)
            for i, b in enumerate(bodies):
                if b.solid.curved is not None:
                    flat = b.solid.planar_facets()
                    not_receiver[face_base[i]:face_base[i + 1]] = True
                    not_receiver[[face_base[i] + f for f in flat]] = False
            extra = _curved_shadow(scene, background, curved_idx, curved_normal, body.ravel()[curved_idx],
                                   depth, k, light, nthreads)
        shadow = soft_shadow(bodies, gface, normals, offsets_f, face_body[:-1], k, light, not_receiver, extra)
    else:
        shadow = np.zeros(depth.shape, np.float32)
    return Hits(depth, body, face, gface, normals, offsets_f, shadow, pixel_rays(k), curved_idx, curved_normal)


def _exact_curved(bodies: list[Body], face_base: np.ndarray, face_body: np.ndarray, depth: np.ndarray,
                  gface: np.ndarray, k: Intrinsics) -> tuple[np.ndarray, np.ndarray]:
    """Ray cast again, against their exact shapes, the pixels that see a curved solid's tessellation: their
    depth and face (``depth`` and ``gface`` changed in place: the face's first facet). Returns the flat
    indices (ascending) of the pixels on curved faces and the true outward normals there (camera frame).
    A ray that meets the inscribed tessellation meets the true solid (a little nearer)."""
    idx_all, n_all = [], []
    curved = [i for i, b in enumerate(bodies) if b.solid.curved is not None]
    if not curved:
        return np.zeros(0, np.int64), np.zeros((0, 3))
    owner = np.take(face_body, gface).ravel()
    rays = pixel_rays(k).reshape(-1, 3)
    for i in curved:
        b = bodies[i]
        idx = np.flatnonzero(owner == i)
        if len(idx) == 0:
            continue
        rot, t = b.to_camera[:3, :3], b.to_camera[:3, 3]
        o = -rot.T @ t
        d = rays[idx].astype(np.float64) @ rot  # rows: rot.T @ ray
        z, face = b.solid.curved.intersect(o, d)
        ok = face >= 0  # (a miss would be rounding at the rim: the tessellation's hit stays)
        idx, z, face, d = idx[ok], z[ok], face[ok], d[ok]
        depth.ravel()[idx] = z.astype(np.float32)
        reps = np.array([b.solid.rep_facet(f) for f in range(b.solid.n_faces)])
        gface.ravel()[idx] = face_base[i] + reps[face]
        kinds = np.array(b.solid.curved.face_kinds())
        on_curve = kinds[face] != "plane"
        p = o + z[on_curve, None] * d[on_curve]
        idx_all.append(idx[on_curve])
        n_all.append(b.solid.curved.normal(p, face[on_curve]) @ rot.T)
    if not idx_all:
        return np.zeros(0, np.int64), np.zeros((0, 3))
    idx, n = np.concatenate(idx_all), np.concatenate(n_all)
    order = np.argsort(idx, kind="stable")
    return idx[order], n[order]


def _curved_shadow(scene, background: int, idx: np.ndarray, normal: np.ndarray, owner: np.ndarray,
                   depth: np.ndarray, k: Intrinsics, light: np.ndarray, nthreads: int) -> np.ndarray:
    """(H, W) uint8: 1 where a point of a curved face that turns to the light sees another solid on the way
    to it (one shadow ray per pixel, from 0.1 mm off the surface; the tables, floor and wall cast none here)."""
    out = np.zeros(depth.shape, np.uint8)
    lit = normal @ light > 0
    idx, normal, owner = idx[lit], normal[lit], owner[lit]
    if len(idx) == 0 or scene is None:
        return out
    p = pixel_rays(k).reshape(-1, 3)[idx].astype(np.float64) * depth.ravel()[idx, None] + 1e-4 * normal
    r = np.concatenate([p, np.broadcast_to(light, p.shape)], axis=1).astype(np.float32)
    hit = scene.cast_rays(o3d.core.Tensor(r), nthreads=nthreads)
    t = hit["t_hit"].numpy()
    gid = hit["geometry_ids"].numpy().astype(np.int64)
    blocked = np.isfinite(t) & (gid + background != owner)
    out.ravel()[idx[blocked]] = 1
    return out


def _silhouette_pixels(bodies: list[Body], k: Intrinsics) -> np.ndarray:
    """Flat indices (int64, ascending) of the pixels whose rays can meet ``bodies``: the silhouette of a
    convex solid in front of the camera is the convex hull of its projected vertices, filled here and
    grown by a pixel or so (rays are cast only there: a fraction of the image)."""
    mask = np.zeros((k.height, k.width), np.uint8)
    for b in bodies:
        v = b.vertices()
        if np.any(v[:, 2] < 1e-3):  # it reaches behind the camera: cast everywhere
            mask[:] = 1
            break
        uv = k.project(v)
        if np.all(uv.max(axis=0) < -2) or np.all(uv.min(axis=0) > [k.width + 1, k.height + 1]):
            continue
        hull = cv2.convexHull(np.round(np.clip(uv, -1e5, 1e5) * 16).astype(np.int32))
        cv2.fillConvexPoly(mask, hull, 1, cv2.LINE_8, shift=4)
        cv2.polylines(mask, [hull], True, 1, 3, cv2.LINE_8, shift=4)  # pixel centres right on the outline
    return np.flatnonzero(mask)


def _fill_background(bodies: list[Body], normals: np.ndarray, offsets_f: np.ndarray,
                     k: Intrinsics) -> tuple[np.ndarray, np.ndarray]:
    """Z-buffer of the flat faces of ``bodies`` (the first bodies of the flat face tables): depth (H, W)
    float32 (inf where none) and flat face index (H, W) int32 (-1 where none)."""
    depth = np.full((k.height, k.width), np.inf, np.float32)
    gface = np.full((k.height, k.width), -1, np.int32)
    rays = pixel_rays(k)
    rx, ry = rays[0, :, 0], rays[:, 0, 1]
    g = 0
    for b in bodies:
        verts = b.vertices()
        for f in b.solid.faces:
            n, d = normals[g], offsets_f[g]
            g += 1
            if d <= 1e-9:  # the camera is behind this face's plane: it faces away
                continue
            poly = clip_near(verts[list(f)], 1e-2)
            if len(poly) < 3:
                continue
            uv = poly[:, :2] / poly[:, 2:] * [k.fx, k.fy] + [k.cx, k.cy]
            lo = np.maximum(np.floor(uv.min(axis=0)).astype(int), 0)
            hi = np.minimum(np.ceil(uv.max(axis=0)).astype(int) + 1, [k.width, k.height])
            if np.any(hi <= lo):
                continue
            mask = np.zeros((hi[1] - lo[1], hi[0] - lo[0]), np.uint8)
            pts = np.round((np.clip(uv, -1e6, 1e6) - lo) * 16).astype(np.int32)
            cv2.fillPoly(mask, [pts], 1, cv2.LINE_8, shift=4)
            # depth of the plane n . X + d = 0 along the ray (rx, ry, 1): z = -d / (n . ray)
            # (in place: these windows are often the whole image)
            z = (np.float32(n[0]) * rx[lo[0]:hi[0]] + np.float32(n[2]))[None, :] \
                + (np.float32(n[1]) * ry[lo[1]:hi[1]])[:, None]
            np.minimum(z, np.float32(-1e-9), out=z)
            np.divide(np.float32(-d), z, out=z)
            win = (slice(lo[1], hi[1]), slice(lo[0], hi[0]))
            closer = np.less(z, depth[win])
            closer &= mask.view(bool)
            np.copyto(depth[win], z, where=closer)
            np.copyto(gface[win], np.int32(g - 1), where=closer)
    return depth, gface
