"""Random scene layouts: a solid resting on a table, a camera looking down at it, and optional clutter,
occluder, solids in contact with the target (beside it, on it or under it) and a small table. World
frame: metres, z up, the table top is the plane z = 0."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..camera import Intrinsics
from .noise import NoiseConfig
from .solids import POLYHEDRA, Solid, box, make_solid, prism

FLOOR_Z_M = -0.75
TABLE_THICKNESS_M = 0.03


@dataclass(frozen=True)
class Placed:
    """A solid and its pose: ``to_world`` (4, 4) maps object-frame points (metres) to the world frame."""

    solid: Solid
    to_world: np.ndarray
    resting_face: int

    def world_vertices(self) -> np.ndarray:
        v = self.solid.vertices
        return v @ self.to_world[:3, :3].T + self.to_world[:3, 3]

    def centre_xy(self) -> np.ndarray:
        return self.to_world[:2, 3]


@dataclass(frozen=True)
class Contact:
    """A solid in contact with the target: ``relation`` is "beside" (on the table, against the target),
    "on_target" (lying on the target's top face) or "under_target" (the target stands on it)."""

    placed: Placed
    relation: str


@dataclass(frozen=True)
class Layout:
    """Everything placed in one scene. ``world_to_camera``: (4, 4) rigid transform into the camera frame
    (x right, y down, z forward). ``table_to_world``: the table's frame (its top is z = 0);
    ``table_half``: half-extents (metres) of the table top along its x and y; ``wall``: a point on and the
    normal (towards the scene) of the background wall, world frame. ``contacts``: solids touching the
    target; ``support_z_m``: height of the surface the target stands on (0: the table top; a box's top
    when a contact is "under_target")."""

    target: Placed
    clutter: tuple[Placed, ...]
    occluder: Placed | None
    world_to_camera: np.ndarray
    elevation_deg: float
    azimuth_deg: float
    distance_m: float
    table_to_world: np.ndarray
    table_half: tuple[float, float]
    wall_point: np.ndarray
    wall_normal: np.ndarray
    contacts: tuple[Contact, ...] = ()
    support_z_m: float = 0.0


def rotation_between(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """The smallest rotation (3, 3) taking unit vector ``a`` to unit vector ``b``."""
    v = np.cross(a, b)
    c = float(np.dot(a, b))
    if c < -1 + 1e-9:  # opposite: turn half a circle about any axis perpendicular to a
        axis = np.cross(a, [1.0, 0, 0]) if abs(a[0]) < 0.9 else np.cross(a, [0, 1.0, 0])
        axis /= np.linalg.norm(axis)
        return 2 * np.outer(axis, axis) - np.eye(3)
    vx = np.array([[0, -v[2], v[1]], [v[2], 0, -v[0]], [-v[1], v[0], 0]])
    return np.eye(3) + vx + vx @ vx / (1 + c)


def rot_z(angle: float) -> np.ndarray:
    c, s = np.cos(angle), np.sin(angle)
    return np.array([[c, -s, 0], [s, c, 0], [0, 0, 1.0]])


def rest(solid: Solid, face: int, yaw: float, xy: np.ndarray) -> Placed:
    """Stand ``solid`` on its face ``face`` on the table (z = 0), turned by ``yaw`` about the vertical,
    with the centre of its footprint's bounding vertices at ``xy``. A curved solid stands on its exact
    shape (a cap, the cone's base, the sphere's lowest point, a cylinder's side along a line)."""
    down = solid.normals()[face] if solid.curved is None else solid.curved.rest_normal(face)
    r = rot_z(yaw) @ rotation_between(down, np.array([0, 0, -1.0]))
    v = solid.vertices @ r.T
    centre = np.array([(v[:, 0].max() + v[:, 0].min()) / 2, (v[:, 1].max() + v[:, 1].min()) / 2])
    low = v[:, 2].min() if solid.curved is None else solid.curved.support(r[2])
    t = np.array([xy[0] - centre[0], xy[1] - centre[1], -low])
    m = np.eye(4)
    m[:3, :3], m[:3, 3] = r, t
    return Placed(solid, m, face)


def footprint_radius(p: Placed) -> float:
    """Horizontal radius (metres) of a placed solid about its centre: a circle that contains it."""
    v = p.world_vertices()
    return float(np.hypot(v[:, 0] - p.centre_xy()[0], v[:, 1] - p.centre_xy()[1]).max())


def look_at(eye: np.ndarray, target: np.ndarray) -> np.ndarray:
    """World-to-camera (4, 4) for a camera at ``eye`` looking at ``target`` with world z up on screen."""
    z = target - eye
    z /= np.linalg.norm(z)
    x = np.cross(z, [0, 0, 1.0])
    x /= np.linalg.norm(x)
    y = np.cross(z, x)
    r = np.stack([x, y, z])
    m = np.eye(4)
    m[:3, :3], m[:3, 3] = r, -r @ eye
    return m


def _in_view(points_world: np.ndarray, w2c: np.ndarray, k: Intrinsics, margin: float) -> bool:
    p = points_world @ w2c[:3, :3].T + w2c[:3, 3]
    if np.any(p[:, 2] < 0.1):
        return False
    uv = k.project(p)
    mu, mv = margin * k.width, margin * k.height
    return bool(np.all((uv[:, 0] >= mu) & (uv[:, 0] <= k.width - 1 - mu)
                       & (uv[:, 1] >= mv) & (uv[:, 1] <= k.height - 1 - mv)))


def _axes(p: Placed) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """World vertices (n, 3), outward face normals (f, 3) and unit edge directions (e, 3) of a placed solid."""
    v = p.world_vertices()
    e = np.array([v[b] - v[a] for a, b in p.solid.edges()])
    return v, p.solid.normals() @ p.to_world[:3, :3].T, e / np.linalg.norm(e, axis=1, keepdims=True)


def _sphere_overlaps(ball: Placed, other: Placed, tol: float) -> bool:
    """Does a placed sphere share interior points with a placed convex polyhedron (or the tessellation of a
    curved solid)? Its centre lies inside it, or nearer than the radius less ``tol`` to one of its faces."""
    c = ball.to_world[:3, 3]
    r = ball.solid.curved.radius
    v = other.world_vertices()
    n = other.solid.normals() @ other.to_world[:3, :3].T
    dist = np.inf
    inside = True
    for i, f in enumerate(other.solid.faces):
        p = v[list(f)]
        h = float(n[i] @ (c - p[0]))
        inside &= h <= 0
        foot = c - h * n[i]  # the centre's foot on the face's plane: inside the loop, or nearest its edges
        q = np.roll(p, -1, axis=0)
        if np.all(np.einsum("ec,ec->e", np.cross(q - p, foot - p), np.broadcast_to(n[i], p.shape)) >= 0):
            dist = min(dist, abs(h))
            continue
        e = q - p
        s = np.clip(np.einsum("ec,ec->e", c - p, e) / np.einsum("ec,ec->e", e, e), 0, 1)
        dist = min(dist, float(np.linalg.norm(p + s[:, None] * e - c, axis=1).min()))
    return bool(inside or dist < r - tol)


def overlaps(a: Placed, b: Placed, tol: float = 1e-7) -> bool:
    """Do two placed convex solids share interior points? Separating-axis test over the face normals of
    both and the cross products of their edge directions (exact for convex polyhedra); solids that only
    touch (a gap of up to ``tol`` metres either way) do not overlap. A cylinder or cone is tested by its
    tessellation (exact to its sagitta, under 0.1 mm); a sphere exactly, by its centre's distance."""
    for ball, other in ((a, b), (b, a)):
        if ball.solid.curved is not None and ball.solid.curved.kind == "sphere":
            return _sphere_overlaps(ball, other, tol)
    va, na, ea = _axes(a)
    vb, nb, eb = _axes(b)
    cross = np.cross(ea[:, None, :], eb[None, :, :]).reshape(-1, 3)
    norm = np.linalg.norm(cross, axis=1)
    axes = np.concatenate([na, nb, cross[norm > 1e-6] / norm[norm > 1e-6, None]])
    pa, pb = va @ axes.T, vb @ axes.T
    gap = np.maximum(pb.min(axis=0) - pa.max(axis=0), pa.min(axis=0) - pb.max(axis=0))
    return bool(np.all(gap < -tol))


def _moved(p: Placed, shift: np.ndarray) -> Placed:
    m = p.to_world.copy()
    m[:3, 3] = m[:3, 3] + shift
    return Placed(p.solid, m, p.resting_face)


def slide_to_contact(mover: Placed, fixed: list[Placed], direction: np.ndarray, far: float) -> Placed | None:
    """``mover`` shifted along the horizontal unit ``direction`` by the least distance in [0, ``far``] at
    which it overlaps none of ``fixed``: it then touches one of them (bisection to 1 micrometre; the set
    of shifts where two convex solids overlap is an interval). None when it overlaps none at 0 already
    or still overlaps at ``far``."""
    d = np.array([direction[0], direction[1], 0.0])

    def hits(t: float) -> bool:
        moved = _moved(mover, t * d)
        return any(overlaps(moved, f) for f in fixed)

    if not hits(0.0) or hits(far):
        return None
    lo, hi = 0.0, far
    while hi - lo > 1e-6:
        mid = 0.5 * (lo + hi)
        lo, hi = (mid, hi) if hits(mid) else (lo, mid)
    return _moved(mover, hi * d)


def _top_face(p: Placed) -> int | None:
    """The index into ``faces`` of the planar face of a placed solid that faces straight up (None if none
    does; a curved solid's facets are no faces)."""
    n = p.solid.normals() @ p.to_world[:3, :3].T
    if p.solid.curved is not None:
        flat = p.solid.planar_facets()
        i = flat[int(np.argmax(n[flat, 2]))] if flat else 0
        return i if flat and n[i, 2] > 1 - 1e-6 else None
    i = int(np.argmax(n[:, 2]))
    return i if n[i, 2] > 1 - 1e-6 else None


def _box_on(base_xy: np.ndarray, half_xy: np.ndarray, yaw: float, height: float) -> tuple[Solid, np.ndarray]:
    """A box (class "cuboid") of footprint 2 ``half_xy`` and ``height`` standing on the table at
    ``base_xy`` turned ``yaw``, and its to_world."""
    s = box(2 * float(half_xy[0]), 2 * float(half_xy[1]), float(height), "cuboid")
    m = np.eye(4)
    m[:3, :3] = rot_z(yaw)
    m[:3, 3] = [base_xy[0], base_xy[1], height / 2]
    return s, m


def stack(target: Placed, rng: np.random.Generator) -> tuple[Placed, Contact]:
    """A box stacked with ``target``: lying on its top face (when it has one, half the time) or under it
    (the target raised onto the box). Returns the target (moved when raised) and the box."""
    top = _top_face(target)
    v = target.world_vertices()
    if top is not None and rng.random() < 0.5:
        # on the target: a box of 60-120 % of the top face's extent, 3-10 cm tall, its centre over the face
        # (it rests stably), turned up to 30 degrees against it
        f = v[list(target.solid.faces[top])]
        yaw = float(np.arctan2(*(f[1, :2] - f[0, :2])[::-1]))
        r = rot_z(-yaw)[:2, :2]
        local = (f[:, :2] - f[:, :2].mean(axis=0)) @ r.T
        half = 0.5 * (local.max(axis=0) - local.min(axis=0)) * rng.uniform(0.6, 1.2, 2)
        centre = f[:, :2].mean(axis=0) + rng.uniform(-0.2, 0.2, 2) * (local.max(axis=0) - local.min(axis=0)) / 2
        h = float(rng.uniform(0.03, 0.10))
        s, m = _box_on(centre, np.maximum(half, 0.02), yaw + float(rng.uniform(-np.pi / 6, np.pi / 6)), h)
        m[2, 3] += float(f[:, 2].max())
        return target, Contact(Placed(s, m, 0), "on_target")
    # under the target: a box wider than its footprint by 0.5-5 cm a side, 4-15 cm tall
    yaw = float(rng.uniform(0, 2 * np.pi))
    c = target.centre_xy()
    local = (v[:, :2] - c) @ rot_z(-yaw)[:2, :2].T
    half = np.abs(local).max(axis=0) + rng.uniform(0.005, 0.05, 2)
    h = float(rng.uniform(0.04, 0.15))
    s, m = _box_on(c, half, yaw, h)
    return _moved(target, np.array([0.0, 0.0, h])), Contact(Placed(s, m, 0), "under_target")


def _stand(solid: Solid, rng: np.random.Generator, xy: np.ndarray) -> Placed:
    face = int(rng.choice(solid.resting))
    return rest(solid, face, float(rng.uniform(0, 2 * np.pi)), xy)


def sample_layout(cls: str, cfg: NoiseConfig, k: Intrinsics, rng: np.random.Generator,
                  extra_rng: np.random.Generator | None = None) -> Layout:
    """A random scene: the target solid of class ``cls`` near the world origin, the camera at 20-60 degrees
    elevation and 0.5-1.5 m away with the whole target in the image, then clutter and an occluder as
    ``cfg`` asks. ``extra_rng`` draws what the knobs ``stacked``, ``touching`` and ``small_table`` add
    (needed only when one is on); ``rng``'s draws are the same with them or without."""
    if extra_rng is None and (cfg.stacked > 0 or cfg.touching > 0 or cfg.small_table > 0):
        raise ValueError("the knobs stacked, touching and small_table draw from extra_rng: give one")
    target = _stand(make_solid(cls, rng), rng, rng.uniform(-0.05, 0.05, 2))
    contacts: list[Contact] = []
    if cfg.stacked > 0 and extra_rng.random() < cfg.stacked:
        target, box_contact = stack(target, extra_rng)
        contacts.append(box_contact)
    tv = target.world_vertices()
    if contacts:  # the stack in the image, and the camera aimed at it
        tv = np.concatenate([tv] + [c.placed.world_vertices() for c in contacts])
    centre = tv.mean(axis=0)
    r3 = float(np.linalg.norm(tv - centre, axis=1).max())
    for attempt in range(50):
        el = np.radians(rng.uniform(20, 60))
        az = rng.uniform(0, 2 * np.pi)
        lo = min(1.5, max(0.5, 3.2 * r3))
        dist = lo + (1.5 - lo) * rng.random() ** 2  # nearer views more often: more pixels on the target
        aim = centre + rng.normal(0, 0.15 * r3, 3) * (attempt < 40)
        eye = aim + dist * np.array([np.cos(el) * np.cos(az), np.cos(el) * np.sin(az), np.sin(el)])
        w2c = look_at(eye, aim)
        if _in_view(tv, w2c, k, 0.04):
            break
    r_t = footprint_radius(target)
    toward_cam = np.array([np.cos(az), np.sin(az)])
    side = np.array([-toward_cam[1], toward_cam[0]])

    placed: list[Placed] = [target]
    if cfg.touching > 0 and extra_rng.random() < cfg.touching:
        # a solid against the stack, beside or behind it as the camera sees it (like clutter)
        solid = make_solid(str(extra_rng.choice(POLYHEDRA)), extra_rng, scale=float(extra_rng.uniform(0.6, 1.0)))
        mover = _stand(solid, extra_rng, target.centre_xy())
        ang = az + np.pi + extra_rng.uniform(-0.6, 0.6) * np.pi
        stack_parts = [target] + [c.placed for c in contacts]
        far = max(float(np.linalg.norm(q.centre_xy() - target.centre_xy())) + footprint_radius(q)
                  for q in stack_parts) + footprint_radius(mover) + 0.05
        beside = slide_to_contact(mover, stack_parts, np.array([np.cos(ang), np.sin(ang)]), far)
        if beside is not None:
            contacts.append(Contact(beside, "beside"))
    placed += [c.placed for c in contacts if c.relation != "on_target"]  # what stands on the table
    clutter = []
    for _ in range(cfg.clutter):
        solid = make_solid(str(rng.choice(POLYHEDRA)), rng, scale=float(rng.uniform(0.5, 0.9)))
        for _try in range(20):
            # beside or behind the target as the camera sees it, so clutter does not hide it
            ang = az + np.pi + rng.uniform(-0.7, 0.7) * np.pi
            c = _stand(solid, rng, np.zeros(2))
            r_c = footprint_radius(c)
            d = r_t + r_c + rng.uniform(0.02, 0.15)
            xy = target.centre_xy() + d * np.array([np.cos(ang), np.sin(ang)])
            c = rest(solid, c.resting_face, float(rng.uniform(0, 2 * np.pi)), xy)
            gaps = [np.linalg.norm(c.centre_xy() - q.centre_xy()) - footprint_radius(q) - r_c for q in placed]
            if min(gaps) > 0.01:
                placed.append(c)
                clutter.append(c)
                break

    occluder = None
    if cfg.occluder > 0 and rng.random() < cfg.occluder:
        r_o = float(rng.uniform(0.025, 0.05))
        s = r_t + r_o + float(rng.uniform(0.02, 0.08))
        lat = float(rng.choice([-1, 1])) * (r_o + r_t * float(rng.uniform(0.1, 0.8)))
        height_on_ray = centre[2] + s * np.tan(el)
        h = max(0.04, height_on_ray * float(rng.uniform(0.8, 1.1)))
        solid = prism(10, 2 * r_o * np.sin(np.pi / 10), h, "occluder") if rng.random() < 0.5 \
            else box(2 * r_o * 0.7, 2 * r_o * 0.7, h, "occluder")
        xy = target.centre_xy() + s * toward_cam + lat * side
        o = rest(solid, 0, float(rng.uniform(0, 2 * np.pi)), xy)
        ov = o.world_vertices() @ w2c[:3, :3].T + w2c[:3, 3]
        if np.all(ov[:, 2] > 0.15) and not any(overlaps(o, c.placed) for c in contacts):
            occluder = o

    # table: a slab around everything placed, its edges a random way off
    t2w = np.eye(4)
    t2w[:3, :3] = rot_z(float(rng.uniform(0, np.pi)))
    t2w[:2, 3] = rng.uniform(-0.15, 0.15, 2)
    half = np.array([rng.uniform(0.45, 0.9), rng.uniform(0.35, 0.6)])
    margin = 0.03
    if cfg.small_table > 0 and extra_rng.random() < cfg.small_table:
        # just larger than what stands on it: its edge, and the floor beyond, in view
        half, margin = np.zeros(2), extra_rng.uniform(0.03, 0.20, 2)
    for p in placed + ([occluder] if occluder else []):  # nothing may hang over the edge
        local = t2w[:2, :2].T @ (p.centre_xy() - t2w[:2, 3])
        half = np.maximum(half, np.abs(local) + footprint_radius(p) + margin)
    wall_dist = float(rng.uniform(1.2, 2.5))
    wall_normal = np.array([toward_cam[0], toward_cam[1], 0.0])
    wall_point = np.array([*(-wall_dist * toward_cam), 0.0])
    support_z = next((float(c.placed.world_vertices()[:, 2].max()) for c in contacts if c.relation == "under_target"),
                     0.0)
    return Layout(target, tuple(clutter), occluder, w2c, float(np.degrees(el)), float(np.degrees(az)) % 360,
                  float(dist), t2w, (float(half[0]), float(half[1])), wall_point, wall_normal,
                  tuple(contacts), support_z)
