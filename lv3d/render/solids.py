"""The solids of the data set: convex polyhedra with explicit faces, and curved solids (cylinder, cone,
sphere) whose faces are tessellated and whose exact shape rides along (:mod:`lv3d.render.curved`).

Object frame: metres, z up; the solid's resting faces are listed so that a sampler can stand it on
the table. Each face is a loop of vertex indices ordered counter-clockwise seen from outside, so the
right-hand rule gives its outward normal. Face ids are the positions in ``faces`` and are fixed per
class (prisms: 0 = bottom base, 1 = top base, 2.. = lateral faces; pyramids: 0 = base, 1.. = lateral).
A curved solid's ``faces`` are the facets of its tessellation; ``facet_face`` maps them to its faces
(cylinder: 0 bottom cap, 1 top cap, 2 side; cone: 0 base, 1 side; sphere: 0).
"""

from __future__ import annotations

from dataclasses import dataclass, field
from functools import cached_property

import numpy as np

from ..errors import InputError
from .curved import CURVED_CLASSES, SEGMENTS, Curved, uv_sphere

# the polyhedra; clutter and the solids that touch the target are drawn from these alone, so that adding
# classes changes no scene of the polyhedra
POLYHEDRA = ("cube", "cuboid", "square_pyramid", "triangular_prism", "pentagonal_prism", "hexagonal_prism",
             "tetrahedron")
CLASSES = POLYHEDRA + CURVED_CLASSES

EDGE_RANGE_M = (0.06, 0.14)


@dataclass(frozen=True)
class Solid:
    """A convex polyhedron. ``vertices``: (n, 3) metres, object frame. ``faces``: vertex-index loops,
    counter-clockwise seen from outside. ``resting``: ids of faces the solid may stand on.
    ``size_m``: the sizes it was built from (named per class, metres). A curved solid also has
    ``facet_face`` (the face each loop of ``faces``, a facet, belongs to) and ``curved`` (its exact shape)."""

    cls: str
    vertices: np.ndarray
    faces: tuple[tuple[int, ...], ...]
    resting: tuple[int, ...]
    size_m: dict = field(default_factory=dict)
    facet_face: tuple[int, ...] | None = None
    curved: Curved | None = None

    @property
    def n_faces(self) -> int:
        """The number of faces (of a curved solid: its faces, not its facets)."""
        return len(self.faces) if self.facet_face is None else max(self.facet_face) + 1

    def face_ids(self) -> np.ndarray:
        """The face id of each loop of ``faces`` (int32): 0, 1, 2, ... for a polyhedron."""
        if self.facet_face is None:
            return np.arange(len(self.faces), dtype=np.int32)
        return np.asarray(self.facet_face, np.int32)

    def rep_facet(self, face: int) -> int:
        """The first facet of face ``face`` (a planar face of a curved solid is one facet: its whole loop)."""
        return face if self.facet_face is None else self.facet_face.index(face)

    def planar_facets(self) -> list[int]:
        """The loops of ``faces`` that are whole planar faces: all of a polyhedron's, a curved solid's caps."""
        if self.curved is None:
            return list(range(len(self.faces)))
        kinds = self.curved.face_kinds()
        return [self.rep_facet(f) for f, k in enumerate(kinds) if k == "plane"]

    def normals(self) -> np.ndarray:
        """Outward unit normals (f, 3) of the faces, object frame (read-only, computed once per solid)."""
        return self._normals

    @cached_property
    def _normals(self) -> np.ndarray:
        # Newell's method (robust for any planar loop), over the edges of all faces at once
        loops = [(f, f[1:] + f[:1]) for f in self.faces]
        a = np.concatenate([f for f, _ in loops])
        b = np.concatenate([g for _, g in loops])
        face = np.repeat(np.arange(len(self.faces)), [len(f) for f in self.faces])
        p, q = self.vertices[a], self.vertices[b]
        parts = ((p[:, 1] - q[:, 1]) * (p[:, 2] + q[:, 2]), (p[:, 2] - q[:, 2]) * (p[:, 0] + q[:, 0]),
                 (p[:, 0] - q[:, 0]) * (p[:, 1] + q[:, 1]))
        out = np.stack([np.bincount(face, weights=w, minlength=len(self.faces)) for w in parts], axis=1)
        out /= np.linalg.norm(out, axis=1, keepdims=True)
        out.setflags(write=False)
        return out

    def triangles(self) -> tuple[np.ndarray, np.ndarray]:
        """Fan triangulation: triangles (t, 3) vertex indices and the face id of each triangle (t,)."""
        tris, ids = [], []
        for i, f in enumerate(self.faces):
            for k in range(1, len(f) - 1):
                tris.append((f[0], f[k], f[k + 1]))
                ids.append(i)
        return np.asarray(tris, np.int32), np.asarray(ids, np.int32)

    def edges(self) -> dict[tuple[int, int], tuple[int, int]]:
        """Each edge (sorted vertex pair) -> the two faces that share it."""
        seen: dict[tuple[int, int], list[int]] = {}
        for i, f in enumerate(self.faces):
            for a, b in zip(f, f[1:] + f[:1]):
                seen.setdefault((min(a, b), max(a, b)), []).append(i)
        return {e: (fs[0], fs[1]) for e, fs in seen.items()}


def prism(n: int, edge: float, length: float, cls: str) -> Solid:
    """Right prism over a regular ``n``-gon with side ``edge``, ``length`` tall along z, centred at the origin."""
    r = edge / (2 * np.sin(np.pi / n))
    a = 2 * np.pi * np.arange(n) / n
    ring = np.stack([r * np.cos(a), r * np.sin(a)], axis=1)
    v = np.concatenate([np.c_[ring, np.full(n, -length / 2)], np.c_[ring, np.full(n, length / 2)]])
    bottom = tuple(range(n - 1, -1, -1))        # seen from below: clockwise from above
    top = tuple(range(n, 2 * n))
    sides = tuple((i, (i + 1) % n, n + (i + 1) % n, n + i) for i in range(n))
    return Solid(cls, v, (bottom, top, *sides), tuple(range(n + 2)), {"base_edge": edge, "length": length})


def box(x: float, y: float, z: float, cls: str) -> Solid:
    """Axis-aligned box with sides ``x``, ``y``, ``z`` (metres), centred at the origin."""
    v = np.array([[sx * x / 2, sy * y / 2, sz * z / 2]
                  for sz in (-1, 1) for sy in (-1, 1) for sx in (-1, 1)])
    # vertex index = 4*(z>0) + 2*(y>0) + (x>0)
    faces = ((0, 2, 3, 1), (4, 5, 7, 6), (0, 1, 5, 4), (2, 6, 7, 3), (0, 4, 6, 2), (1, 3, 7, 5))
    return Solid(cls, v, faces, tuple(range(6)), {"x": x, "y": y, "z": z})


def pyramid(n: int, edge: float, height: float, cls: str) -> Solid:
    """Right pyramid over a regular ``n``-gon with side ``edge``; base at z = 0, apex at z = ``height``."""
    r = edge / (2 * np.sin(np.pi / n))
    a = 2 * np.pi * np.arange(n) / n + np.pi / n
    v = np.concatenate([np.stack([r * np.cos(a), r * np.sin(a), np.zeros(n)], axis=1), [[0, 0, height]]])
    base = tuple(range(n - 1, -1, -1))
    sides = tuple((i, (i + 1) % n, n) for i in range(n))
    return Solid(cls, v, (base, *sides), (0,), {"base_edge": edge, "height": height})


def tetrahedron(edge: float) -> Solid:
    """Regular tetrahedron with side ``edge``: any face can be the base."""
    s = pyramid(3, edge, edge * np.sqrt(2.0 / 3.0), "tetrahedron")
    return Solid("tetrahedron", s.vertices, s.faces, tuple(range(4)), {"edge": edge})


def cylinder(radius: float, length: float) -> Solid:
    """A cylinder of ``radius`` and ``length`` along z, centred at the origin (faces 0 bottom cap, 1 top cap,
    2 side); tessellated as a prism over a ``SEGMENTS``-gon inscribed in its circles, a vertex at angle 0."""
    s = prism(SEGMENTS, 2 * radius * np.sin(np.pi / SEGMENTS), length, "cylinder")
    return Solid("cylinder", s.vertices, s.faces, (0, 1, 2), {"radius": radius, "length": length},
                 (0, 1) + (2,) * SEGMENTS, Curved("cylinder", radius, length))


def cone(radius: float, height: float) -> Solid:
    """A right circular cone: base of ``radius`` at z = 0 (face 0), apex at z = ``height`` (face 1 the side);
    tessellated as a pyramid over a ``SEGMENTS``-gon inscribed in the base circle."""
    s = pyramid(SEGMENTS, 2 * radius * np.sin(np.pi / SEGMENTS), height, "cone")
    return Solid("cone", s.vertices, s.faces, (0,), {"radius": radius, "height": height},
                 (0,) + (1,) * SEGMENTS, Curved("cone", radius, height))


def sphere(radius: float) -> Solid:
    """A sphere of ``radius`` centred at the origin (one face), tessellated in bands of latitude."""
    v, faces = uv_sphere(radius)
    return Solid("sphere", v, faces, (0,), {"radius": radius}, (0,) * len(faces), Curved("sphere", radius))


def make_solid(cls: str, rng: np.random.Generator, scale: float = 1.0) -> Solid:
    """A solid of class ``cls`` with sizes drawn from this data set's ranges (edges 6-14 cm, times ``scale``;
    the curved solids' diameters and lengths from the same range)."""
    lo, hi = EDGE_RANGE_M[0] * scale, EDGE_RANGE_M[1] * scale

    def edge() -> float:
        return float(rng.uniform(lo, hi))

    if cls == "cube":
        e = edge()
        s = box(e, e, e, cls)
        return Solid(cls, s.vertices, s.faces, s.resting, {"edge": e})
    if cls == "cuboid":
        while True:  # clearly not a cube: some pair of sides differs by a factor >= 1.4
            x, y, z = (edge() for _ in range(3))
            if max(x, y, z) / min(x, y, z) >= 1.4:
                return box(x, y, z, cls)
    if cls == "square_pyramid":
        e = edge()
        return pyramid(4, e, e * float(rng.uniform(0.6, 1.2)), cls)
    if cls in ("triangular_prism", "pentagonal_prism", "hexagonal_prism"):
        n = {"triangular_prism": 3, "pentagonal_prism": 5, "hexagonal_prism": 6}[cls]
        # wide bases would dwarf the frame: keep the circumradius of the base within 10 cm
        e_max = max(lo, min(hi, 0.10 * scale * 2 * np.sin(np.pi / n)))
        return prism(n, float(rng.uniform(lo, e_max)), edge(), cls)
    if cls == "tetrahedron":
        return tetrahedron(edge())
    if cls == "cylinder":
        return cylinder(edge() / 2, edge())
    if cls == "cone":  # height 0.6-1.2 x the base's diameter, like the square pyramid's
        d = edge()
        return cone(d / 2, d * float(rng.uniform(0.6, 1.2)))
    if cls == "sphere":
        return sphere(edge() / 2)
    raise InputError("class", f"unknown class {cls!r}; known: {', '.join(CLASSES)}")
