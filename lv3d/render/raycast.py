"""One ray per pixel through open3d's RaycastingScene (Embree, CPU), in the camera frame.

Rays leave the camera centre with direction ((u - cx)/fx, (v - cy)/fy, 1), so the hit parameter
``t_hit`` is the depth z itself (not the length along the ray).
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import lru_cache

import cv2
import numpy as np
import open3d as o3d

from ..camera import Intrinsics
from .solids import Solid


@dataclass(frozen=True)
class Body:
    """A solid in the camera frame: ``to_camera`` (4, 4) maps its object frame into the camera frame."""

    solid: Solid
    to_camera: np.ndarray

    def vertices(self) -> np.ndarray:
        """Camera-frame vertices (n, 3), metres."""
        return self.solid.vertices @ self.to_camera[:3, :3].T + self.to_camera[:3, 3]

    def normals(self) -> np.ndarray:
        """Camera-frame outward face normals (f, 3)."""
        return self.solid.normals() @ self.to_camera[:3, :3].T


@dataclass(frozen=True)
class Hits:
    """What each pixel sees, all (H, W): ``depth`` z in metres (float32, 0 = nothing hit); ``body`` index
    into the bodies cast against and ``face`` the face id within it (-1 = none); ``gface`` the face's
    index into the flat per-face tables ``face_normal`` (F, 3) (camera-frame outward unit normals) and
    ``face_offset`` (F,) (n . X + offset = 0 on the face's plane). ``shadow``: float32 in 0..1, the
    fraction of the light blocked (all 0 when no light was given)."""

    depth: np.ndarray
    body: np.ndarray
    face: np.ndarray
    gface: np.ndarray
    face_normal: np.ndarray
    face_offset: np.ndarray
    shadow: np.ndarray  # (H, W) float32 0..1
    rays: np.ndarray  # (H, W, 3) float32 pixel ray directions with z = 1

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
    directional light, camera frame) also which points lie in shadow.

    The solids are ray cast with Embree (open3d), over the image window they can cover. The first
    ``background`` bodies are big flat surfaces (table slab, floor, wall) that would cost most of the
    ray casting time (open3d's per-hit work): each of their faces is filled as a polygon with
    OpenCV and z-buffered with the exact depth of its plane at every pixel centre.
    """
    face_base = np.cumsum([0] + [len(b.solid.faces) for b in bodies])
    face_body = np.repeat(np.arange(len(bodies)), np.diff(face_base))
    face_id = np.concatenate([np.arange(len(b.solid.faces)) for b in bodies])
    normals = np.concatenate([b.normals() for b in bodies])
    offsets_f = np.concatenate([-np.einsum("fc,fc->f", b.normals(), b.vertices()[[f[0] for f in b.solid.faces]])
                                for b in bodies])
    depth, gface = _fill_background(bodies[:background], normals, offsets_f, k)

    solids = bodies[background:]
    if solids:
        scene, offsets, tri_body, tri_face = build_scene(solids)
        (v0, v1), (u0, u1) = _window(solids, k)
        if v1 > v0 and u1 > u0:
            out = scene.cast_rays(o3d.core.Tensor(np.ascontiguousarray(rays_from_origin(k)[v0:v1, u0:u1])),
                                  nthreads=nthreads)
            t = out["t_hit"].numpy()
            hit = t < depth[v0:v1, u0:u1]  # inf where nothing was hit: never nearer
            tri = offsets[np.where(hit, out["geometry_ids"].numpy(), 0)] + np.where(hit, out["primitive_ids"].numpy(), 0)
            g = face_base[background + tri_body[tri]] + tri_face[tri]
            depth[v0:v1, u0:u1] = np.where(hit, t, depth[v0:v1, u0:u1])
            gface[v0:v1, u0:u1] = np.where(hit, g, gface[v0:v1, u0:u1])
    hit = gface >= 0
    depth = np.where(hit, depth, np.float32(0))
    body = np.where(hit, face_body[gface], -1)
    face = np.where(hit, face_id[gface], -1)
    shadow = np.zeros(depth.shape, np.float32)
    if light_cam is not None:
        shadow = _shadow_fraction(build_scene(bodies)[0], k, depth, light_cam, nthreads)
    return Hits(depth, body, face, gface, normals, offsets_f, shadow, pixel_rays(k))


def _window(bodies: list[Body], k: Intrinsics) -> tuple[tuple[int, int], tuple[int, int]]:
    """Rows and columns (half-open) of the image that the bodies' projections can cover."""
    v = np.concatenate([b.vertices() for b in bodies])
    if np.any(v[:, 2] < 1e-3):  # something reaches behind the camera: cast everywhere
        return (0, k.height), (0, k.width)
    uv = k.project(v)
    u0, v0 = np.floor(uv.min(axis=0)).astype(int) - 1
    u1, v1 = np.ceil(uv.max(axis=0)).astype(int) + 2
    return (max(v0, 0), min(v1, k.height)), (max(u0, 0), min(u1, k.width))


def clip_near(poly: np.ndarray, z_near: float) -> np.ndarray:
    """The part of the planar polygon (n, 3) with z >= ``z_near`` (Sutherland-Hodgman against one plane)."""
    out = []
    for a, b in zip(poly, np.roll(poly, -1, axis=0)):
        ina, inb = a[2] >= z_near, b[2] >= z_near
        if ina:
            out.append(a)
        if ina != inb:
            out.append(a + (b - a) * (z_near - a[2]) / (b[2] - a[2]))
    return np.asarray(out).reshape(-1, 3)


def _fill_background(bodies: list[Body], normals: np.ndarray, offsets_f: np.ndarray,
                     k: Intrinsics) -> tuple[np.ndarray, np.ndarray]:
    """Z-buffer of the flat faces of ``bodies`` (the first bodies of the flat face tables): depth (H, W)
    float32 (inf where none) and flat face index (H, W) int64 (-1 where none)."""
    depth = np.full((k.height, k.width), np.inf, np.float32)
    gface = np.full((k.height, k.width), -1, np.int64)
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
            ndr = (np.float32(n[0]) * rx[lo[0]:hi[0]])[None, :] + (np.float32(n[1]) * ry[lo[1]:hi[1]])[:, None] \
                + np.float32(n[2])
            z = np.float32(-d) / np.minimum(ndr, np.float32(-1e-9))
            win = (slice(lo[1], hi[1]), slice(lo[0], hi[0]))
            closer = (mask > 0) & (z < depth[win])
            depth[win][closer] = z[closer]
            gface[win][closer] = g - 1
    return depth, gface


def _shadow_fraction(scene, k: Intrinsics, depth: np.ndarray, light_cam: np.ndarray, nthreads: int) -> np.ndarray:
    """(H, W) float32 in 0..1: how much of the directional light each hit point misses. Shadow rays go
    from every second pixel in each direction and are upsampled bilinearly: a quarter of the rays,
    and soft shadow edges like a real penumbra. Rays start on the surface and skip the first
    millimetre (``tnear``), so a convex face never shadows itself."""
    sub = (slice(None, None, 2), slice(None, None, 2))
    d = depth[sub]
    rays = np.empty(d.shape + (6,), np.float32)
    np.multiply(pixel_rays(k)[sub], d[..., None], out=rays[..., :3])
    rays[..., 3:] = light_cam.astype(np.float32)
    occ = scene.test_occlusions(o3d.core.Tensor(rays), tnear=1e-3, tfar=20.0, nthreads=nthreads).numpy()
    occ = np.where(d > 0, occ, 0).astype(np.float32)
    return cv2.resize(occ, (k.width, k.height), interpolation=cv2.INTER_LINEAR)
