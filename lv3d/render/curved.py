"""The exact shapes of the curved solids (cylinder, cone, sphere), beside the tessellation that stands in
for them wherever the renderer works on polyhedra.

A curved solid is a :class:`lv3d.render.solids.Solid` twice over:

- its ``vertices`` and ``faces`` are a fine inscribed tessellation (``SEGMENTS`` facets round a circle;
  ``facet_face`` says which face each facet belongs to). It serves what needs no more than a tenth of a
  millimetre: which body a pixel sees (Embree), the shadow the solid casts, where it stands and whom it
  touches (the separating-axis test), the camera's framing. With 64 facets round a circle of radius
  r <= 7 cm the sagitta r (1 - cos(pi / 64)) is at most 0.084 mm, under a tenth of a pixel at 0.5 m;
- its ``curved`` :class:`Curved` is the exact shape: every pixel that sees the tessellation is ray cast
  again against the true surfaces (a quadratic per ray), which gives its depth, its face and its normal
  exactly. So depth is exact (not off by the sagitta), curved faces are shaded with the true per-pixel
  normal (smooth, no facets), and a pixel lies on the cap or on the side as the true solid says. Only a
  sliver of the silhouette under a tenth of a pixel wide, where a ray meets the true solid but misses
  the inscribed tessellation, shows what lies behind.

Object frames: a cylinder's axis is z, centred at the origin (caps at z = -/+ length/2; faces 0 bottom
cap, 1 top cap, 2 side); a cone's base is at z = 0 round the z axis, its apex at z = height (faces
0 base, 1 side); a sphere is centred at the origin (face 0).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

SEGMENTS = 64            # facets round a circle of the tessellation
SPHERE_RINGS = 32        # bands of latitude of the sphere's tessellation
OUTLINE_POINTS = 96      # points of a full circle in an outline (fewer for an arc)
CURVED_CLASSES = ("cylinder", "cone", "sphere")


@dataclass(frozen=True)
class Curved:
    """The exact shape of a curved solid in its object frame (metres): ``kind`` "cylinder" (``radius``,
    ``length`` along z), "cone" (base ``radius``, ``length`` = height) or "sphere" (``radius``)."""

    kind: str
    radius: float
    length: float = 0.0

    # ---- faces -------------------------------------------------------------------------------------

    def face_kinds(self) -> tuple[str, ...]:
        """The surface type of each face: "plane", "cylinder", "cone" or "sphere"."""
        return {"cylinder": ("plane", "plane", "cylinder"), "cone": ("plane", "cone"),
                "sphere": ("sphere",)}[self.kind]

    def meeting(self) -> tuple[tuple[int, int], ...]:
        """Pairs of faces that meet along a circle (the rims)."""
        return {"cylinder": ((0, 2), (1, 2)), "cone": ((0, 1),), "sphere": ()}[self.kind]

    def rest_normal(self, face: int) -> np.ndarray:
        """Outward normal (object frame) turned down onto the table when the solid rests on ``face``: a cap,
        the cone's base, the sphere's bottom, or for the cylinder's side the line through its vertices at
        angle 0 (a cylinder lying on its side touches the table along that line)."""
        if self.kind == "cylinder":
            return np.array([[0, 0, -1.0], [0, 0, 1.0], [1.0, 0, 0]][face])
        return np.array([0, 0, -1.0])

    def support(self, u: np.ndarray) -> float:
        """The least value of u . X over the solid (``u`` a unit vector, object frame)."""
        u = np.asarray(u, np.float64)
        ring = float(np.hypot(u[0], u[1]))
        if self.kind == "cylinder":
            return -0.5 * self.length * abs(float(u[2])) - self.radius * ring
        if self.kind == "cone":
            return min(self.length * float(u[2]), -self.radius * ring)
        return -self.radius

    # ---- exact ray casting -------------------------------------------------------------------------

    def intersect(self, o: np.ndarray, d: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Where rays o + t d (``o`` (3,), ``d`` (m, 3), object frame) enter the solid: t (m,) (nan where a
        ray misses it) and the face entered (m,) int (-1 where it misses). The first point of the boundary
        along a ray from outside a convex solid is where it enters."""
        o = np.asarray(o, np.float64)
        d = np.asarray(d, np.float64)
        best_t = np.full(len(d), np.inf)
        best_f = np.full(len(d), -1, np.int64)

        def take(t, ok, face):
            ok = ok & np.isfinite(t) & (t > 0) & (t < best_t)
            best_t[ok] = t[ok]
            best_f[ok] = face

        r, h = self.radius, self.length
        eps = 1e-9
        with np.errstate(divide="ignore", invalid="ignore"):
            if self.kind in ("cylinder", "cone", "sphere"):
                if self.kind == "cylinder":
                    a = d[:, 0] ** 2 + d[:, 1] ** 2
                    b = 2 * (o[0] * d[:, 0] + o[1] * d[:, 1])
                    c = np.full(len(d), o[0] ** 2 + o[1] ** 2 - r * r)
                    lo, hi, side = -h / 2, h / 2, 2
                elif self.kind == "cone":
                    k2 = (r / h) ** 2
                    a = d[:, 0] ** 2 + d[:, 1] ** 2 - k2 * d[:, 2] ** 2
                    b = 2 * (o[0] * d[:, 0] + o[1] * d[:, 1] + k2 * (h - o[2]) * d[:, 2])
                    c = np.full(len(d), o[0] ** 2 + o[1] ** 2 - k2 * (h - o[2]) ** 2)
                    lo, hi, side = 0.0, h, 1
                else:
                    a = np.einsum("mc,mc->m", d, d)
                    b = 2 * (d @ o)
                    c = np.full(len(d), float(o @ o) - r * r)
                    lo, hi, side = -np.inf, np.inf, 0
                disc = b * b - 4 * a * c
                sq = np.sqrt(np.maximum(disc, 0))
                lin = np.abs(a) < 1e-12
                for sgn in (-1, 1):
                    t = np.where(lin, -c / b, (-b + sgn * sq) / (2 * a))
                    z = o[2] + t * d[:, 2]
                    take(t, (disc >= 0) & (z >= lo - eps) & (z <= hi + eps), side)
            if self.kind == "cylinder":
                for face, zc, sgn in ((0, -h / 2, 1), (1, h / 2, -1)):
                    t = (zc - o[2]) / d[:, 2]
                    x, y = o[0] + t * d[:, 0], o[1] + t * d[:, 1]
                    take(t, (sgn * d[:, 2] > 0) & (x * x + y * y <= r * r * (1 + 1e-9)), face)
            if self.kind == "cone":
                t = -o[2] / d[:, 2]
                x, y = o[0] + t * d[:, 0], o[1] + t * d[:, 1]
                take(t, (d[:, 2] > 0) & (x * x + y * y <= r * r * (1 + 1e-9)), 0)
        best_t[best_f < 0] = np.nan
        return best_t, best_f

    def normal(self, p: np.ndarray, face: np.ndarray) -> np.ndarray:
        """Outward unit normals (m, 3) at points ``p`` (m, 3) of faces ``face`` (m,), object frame."""
        p = np.asarray(p, np.float64)
        face = np.broadcast_to(np.asarray(face), (len(p),))
        n = np.zeros_like(p)
        kinds = self.face_kinds()
        for f, kind in enumerate(kinds):
            sel = face == f
            if not np.any(sel):
                continue
            q = p[sel]
            if kind == "plane":
                z = -1.0 if (self.kind == "cone" or f == 0) else 1.0
                n[sel] = [0.0, 0.0, z]
            elif kind == "cylinder":
                n[sel] = np.c_[q[:, 0], q[:, 1], np.zeros(len(q))]
            elif kind == "cone":
                ang = np.arctan2(q[:, 1], q[:, 0])
                n[sel] = np.c_[np.cos(ang), np.sin(ang), np.full(len(q), self.radius / self.length)]
            else:
                n[sel] = q
        return n / np.maximum(np.linalg.norm(n, axis=1, keepdims=True), 1e-300)

    # ---- ground truth ------------------------------------------------------------------------------

    def surface(self, face: int, to_camera: np.ndarray) -> dict:
        """The surface of ``face`` in the camera frame (``to_camera`` (4, 4) maps the object frame there):
        plane {"normal", "offset"} (normal towards the camera, n . X + offset = 0); cylinder {"axis" (unit,
        bottom cap to top cap), "point" (the centre of the axis), "radius", "length"}; cone {"apex", "axis"
        (unit, from the apex towards the base), "half_angle_deg", "height"}; sphere {"centre", "radius"}."""
        rot, t = to_camera[:3, :3], to_camera[:3, 3]
        kind = self.face_kinds()[face]
        r6 = lambda x: np.round(np.asarray(x, np.float64), 6).tolist()  # noqa: E731
        if kind == "plane":
            n_obj, p_obj = self._plane(face)
            n, p = rot @ n_obj, rot @ p_obj + t
            off = -float(n @ p)
            if off < 0:  # towards the camera
                n, off = -n, -off
            return {"type": "plane", "normal": r6(n), "offset": round(off, 6)}
        if kind == "cylinder":
            return {"type": "cylinder", "axis": r6(rot[:, 2]), "point": r6(t), "radius": round(self.radius, 6),
                    "length": round(self.length, 6)}
        if kind == "cone":
            return {"type": "cone", "apex": r6(rot @ [0, 0, self.length] + t), "axis": r6(-rot[:, 2]),
                    "half_angle_deg": round(float(np.degrees(np.arctan2(self.radius, self.length))), 6),
                    "height": round(self.length, 6)}
        return {"type": "sphere", "centre": r6(t), "radius": round(self.radius, 6)}

    def _plane(self, face: int) -> tuple[np.ndarray, np.ndarray]:
        """Outward normal and a point of planar ``face`` (object frame)."""
        if self.kind == "cylinder":
            z = -self.length / 2 if face == 0 else self.length / 2
            return np.array([0, 0, np.sign(z)]), np.array([0, 0, z])
        return np.array([0, 0, -1.0]), np.zeros(3)

    def _circle(self, z: float, radius: float, a0: float, a1: float, n: int) -> np.ndarray:
        a = np.linspace(a0, a1, n)
        return np.stack([radius * np.cos(a), radius * np.sin(a), np.full(n, z)], axis=1)

    def outline(self, face: int, cam: np.ndarray) -> np.ndarray | None:
        """The part of ``face`` that faces a camera at ``cam`` (object frame), as a closed loop of points
        (m, 3) on its boundary (object frame): a cap's rim; a cylinder's or cone's side between its
        silhouette lines and its rims; a sphere's silhouette circle. None when no part faces the camera.
        A convex solid hides none of the parts that face the camera, so this is the face's visible
        outline up to other objects and the image border."""
        kind = self.face_kinds()[face]
        r, h, n = self.radius, self.length, OUTLINE_POINTS
        if kind == "plane":
            nrm, p = self._plane(face)
            if float(nrm @ (cam - p)) <= 0:
                return None
            return self._circle(float(p[2]), r, 0, 2 * np.pi, n + 1)[:-1]
        rho, phi = float(np.hypot(cam[0], cam[1])), float(np.arctan2(cam[1], cam[0]))
        if kind == "cylinder":
            if rho <= r:
                return None
            al = float(np.arccos(r / rho))
            m = max(8, int(n * al / np.pi))
            bottom = self._circle(-h / 2, r, phi - al, phi + al, m)
            top = self._circle(h / 2, r, phi + al, phi - al, m)
            return np.concatenate([bottom, top])
        if kind == "cone":
            lift = (r / h) * (h - float(cam[2]))
            if rho <= 1e-12:
                return self._circle(0.0, r, 0, 2 * np.pi, n + 1)[:-1] if lift < 0 else None
            q = lift / rho
            if q >= 1:
                return None
            if q <= -1:  # the whole side faces the camera: its outline is the base's rim
                return self._circle(0.0, r, 0, 2 * np.pi, n + 1)[:-1]
            al = float(np.arccos(q))
            m = max(8, int(n * al / np.pi))
            return np.concatenate([self._circle(0.0, r, phi - al, phi + al, m), [[0.0, 0.0, h]]])
        dist = float(np.linalg.norm(cam))
        if dist <= r:
            return None
        w = cam / dist
        e1 = np.cross(w, [1.0, 0, 0] if abs(w[0]) < 0.9 else [0, 1.0, 0])
        e1 /= np.linalg.norm(e1)
        e2 = np.cross(w, e1)
        a = np.linspace(0, 2 * np.pi, n + 1)[:-1]
        rr = r * np.sqrt(1 - (r / dist) ** 2)
        return (r * r / dist) * w + rr * (np.outer(np.cos(a), e1) + np.outer(np.sin(a), e2))

    def rim_normals(self, a: int, b: int) -> tuple[np.ndarray, np.ndarray]:
        """Outward normals (object frame) of faces ``a`` and ``b`` at a point of the rim they share."""
        if self.kind == "cylinder":
            cap = np.array([0, 0, -1.0 if min(a, b) == 0 else 1.0])
            return (cap, np.array([1.0, 0, 0])) if a < b else (np.array([1.0, 0, 0]), cap)
        side = np.array([1.0, 0, self.radius / self.length])
        side /= np.linalg.norm(side)
        return (np.array([0, 0, -1.0]), side) if a < b else (side, np.array([0, 0, -1.0]))

    # ---- prints on curved faces ------------------------------------------------------------------------

    def unrolled(self, face: int) -> np.ndarray:
        """The rectangle (4, 2) that ``face`` unrolls to in print coordinates (s, t), metres: s = radius x
        the angle about the axis (-pi..pi), t = height along the axis (cylinder, cone) or radius x the
        latitude (sphere). See :meth:`print_coords`."""
        r, h = self.radius, self.length
        s = np.pi * r
        t0, t1 = {"cylinder": (-h / 2, h / 2), "cone": (0.0, h), "sphere": (-np.pi * r / 2, np.pi * r / 2)}[self.kind]
        return np.array([[-s, t0], [s, t0], [s, t1], [-s, t1]])

    def print_coords(self, x: np.ndarray, y: np.ndarray, z: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Print coordinates (s, t) (float32 metres) of object-frame points on the curved face."""
        f32 = np.float32
        s = f32(self.radius) * np.arctan2(y, x)
        if self.kind == "sphere":
            t = f32(self.radius) * np.arcsin(np.clip(z / f32(self.radius), f32(-1), f32(1)))
        else:
            t = z
        return s.astype(np.float32), np.asarray(t, np.float32)


def uv_sphere(radius: float, rings: int = SPHERE_RINGS, segments: int = SEGMENTS) -> tuple[np.ndarray, tuple]:
    """Vertices (n, 3) and facet loops (counter-clockwise seen from outside) of a sphere tessellated in
    ``rings`` bands of latitude and ``segments`` of longitude, its vertices on the sphere (the poles at
    -z and +z; each band's quads are planar isosceles trapezoids)."""
    lat = np.linspace(-np.pi / 2, np.pi / 2, rings + 1)[1:-1]
    lon = 2 * np.pi * np.arange(segments) / segments
    ring = [np.stack([np.cos(la) * np.cos(lon), np.cos(la) * np.sin(lon), np.full(segments, np.sin(la))], axis=1)
            for la in lat]
    v = np.concatenate([[[0, 0, -1.0]], *ring, [[0, 0, 1.0]]]) * radius
    top = len(v) - 1

    def vid(i: int, j: int) -> int:  # ring i (0 lowest), segment j
        return 1 + i * segments + j % segments

    faces = [(0, vid(0, j + 1), vid(0, j)) for j in range(segments)]
    for i in range(len(lat) - 1):
        faces += [(vid(i, j), vid(i, j + 1), vid(i + 1, j + 1), vid(i + 1, j)) for j in range(segments)]
    faces += [(vid(len(lat) - 1, j), vid(len(lat) - 1, j + 1), top) for j in range(segments)]
    return v, tuple(faces)
