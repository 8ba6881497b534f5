"""Render one synthetic RGB-D frame with its ground truth: layout -> raycast -> shading -> sensor noise."""

from __future__ import annotations

import numpy as np

from ..camera import Intrinsics
from ..errors import InputError
from ..rgbd import RGBD
from .noise import NoiseConfig, as_config, noisy_color, noisy_depth
from .body import Body
from .raycast import ray_lengths, raycast
from .sampler import FLOOR_Z_M, TABLE_THICKNESS_M, Layout, sample_layout
from .appearance import design_prints, multi_hue_albedo
from .shading import environment_colour, object_albedo, shade
from .solids import CLASSES, Solid, box
from .truth import scene_truth

SCHEMA = "lv3d.scene/1"


def _quad(corners: np.ndarray, cls: str) -> Solid:
    """A one-sided rectangle (a solid with one face) from four corners in counter-clockwise order."""
    return Solid(cls, np.asarray(corners, np.float64), ((0, 1, 2, 3),), ())


def environment(layout: Layout) -> list[tuple[str, Solid, np.ndarray]]:
    """Table slab, floor and wall as (role, solid, to_world)."""
    hx, hy = layout.table_half
    table = box(2 * hx, 2 * hy, TABLE_THICKNESS_M, "table")
    t2w = layout.table_to_world.copy()
    t2w[:3, 3] = t2w[:3, 3] + t2w[:3, :3] @ np.array([0, 0, -TABLE_THICKNESS_M / 2])
    big = 20.0
    floor = _quad([[-big, -big, FLOOR_Z_M], [big, -big, FLOOR_Z_M], [big, big, FLOOR_Z_M], [-big, big, FLOOR_Z_M]],
                  "floor")
    n = layout.wall_normal
    side = np.array([-n[1], n[0], 0.0])
    p = layout.wall_point
    corners = [p + s * big * side + np.array([0, 0, z]) for s, z in ((1, FLOOR_Z_M), (-1, FLOOR_Z_M), (-1, 3.0), (1, 3.0))]
    wall = _quad(corners, "wall")
    if np.dot(wall.normals()[0], n) < 0:
        wall = _quad(corners[::-1], "wall")
    return [("table", table, t2w), ("floor", floor, np.eye(4)), ("wall", wall, np.eye(4))]


def render_scene(cls: str, seed: int, noise: str | NoiseConfig = "clean", width: int = 640, height: int = 480,
                 scene_id: str = "s000000") -> tuple[RGBD, np.ndarray]:
    """Render a ``cls`` solid on a table, seen by a D435-like camera, as ``noise`` says.

    Returns the RGBD (colour (H, W, 3) uint8; depth (H, W) float32 metres after noise and millimetre
    quantisation, 0 = no reading; ``meta`` = the meta.json dict of docs/dataset.md) and the (H, W) uint8
    face-id mask of the target (0 = not the target, k = face k-1). The same arguments give the same arrays.
    The scene's geometry and camera come from their own random stream, so one seed under two presets
    shows the same target from the same view.

    >>> frame, faces = render_scene("cube", seed=1, width=160, height=120)
    >>> frame.depth.shape, int(faces.max()) <= 6
    ((120, 160), True)
    """
    if cls not in CLASSES:
        raise InputError("class", f"unknown class {cls!r}; known: {', '.join(CLASSES)}")
    if not isinstance(seed, (int, np.integer)) or seed < 0:
        raise InputError("seed", f"seed must be a non-negative integer, got {seed!r}")
    cfg = as_config(noise)
    k = Intrinsics.realsense_d435(int(width), int(height))
    k.validate("image size")
    # one stream per concern; the last three draw only what the appearance and sensor knobs add, so the
    # knobs of the original presets see the same numbers with them or without
    layout_rng, look_rng, noise_rng, extra_rng, paint_rng, sensor_rng = (
        np.random.default_rng(s) for s in np.random.SeedSequence(int(seed)).spawn(6))
    layout = sample_layout(cls, cfg, k, layout_rng, extra_rng)
    w2c = layout.world_to_camera

    roles, bodies, albedo = [], [], []
    for role, solid, to_world in environment(layout):
        roles.append(role)
        bodies.append(Body(solid, w2c @ to_world))
        albedo.append(np.tile(environment_colour(role, look_rng), (len(solid.faces), 1)))
    objects = [("target", layout.target)] + [("clutter", c) for c in layout.clutter] \
        + [("contact", c.placed) for c in layout.contacts]
    if layout.occluder is not None:
        objects.append(("occluder", layout.occluder))
    prints = []
    for role, placed in objects:
        roles.append(role)
        body = Body(placed.solid, w2c @ placed.to_world)
        n_faces = placed.solid.n_faces
        alb = object_albedo(n_faces, paint_rng if role == "contact" else look_rng)
        if cfg.face_hues > 0 and paint_rng.random() < cfg.face_hues:
            alb = multi_hue_albedo(n_faces, paint_rng)
        if cfg.printed_faces > 0:
            first = sum(len(b.solid.faces) for b in bodies)  # the body's first flat face index
            for face, pr in design_prints(placed.solid, alb, cfg.printed_faces, paint_rng).items():
                prints.append((first + placed.solid.rep_facet(face), np.linalg.inv(body.to_camera @ pr.frame), pr))
        bodies.append(body)
        albedo.append(alb if placed.solid.facet_face is None else alb[placed.solid.face_ids()])
    target_index = roles.index("target")

    # the light comes from the camera's side of the scene, so the wall behind the table cannot shade it all
    el = np.radians(look_rng.uniform(35, 75))
    az = np.radians(layout.azimuth_deg + look_rng.uniform(-100, 100))
    light_world = np.array([np.cos(el) * np.cos(az), np.cos(el) * np.sin(az), np.sin(el)])
    light_cam = w2c[:3, :3] @ light_world
    hits = raycast(bodies, k, light_cam if cfg.shadows else None, background=3)

    color = shade(hits, layout, roles, albedo, light_cam, cfg, look_rng, prints)
    # on a face's plane n . X + offset = 0 with X = z * ray, so |n . ray| / |ray| = |offset| / (z |ray|)
    cos_inc = None
    if cfg.grazing_deg < 90:
        offset = np.take(np.append(hits.face_offset, 1.0).astype(np.float32), hits.gface)
        cos_inc = np.abs(offset) / np.maximum(hits.depth * ray_lengths(k), np.float32(1e-9))
        if len(hits.curved_idx):  # curved faces: the true normal at each pixel
            ray = hits.rays.reshape(-1, 3)[hits.curved_idx].astype(np.float64)
            cos = np.abs(np.einsum("mc,mc->m", hits.curved_normal, ray)) / np.linalg.norm(ray, axis=1)
            cos_inc.ravel()[hits.curved_idx] = cos.astype(np.float32)
    depth = noisy_depth(hits.depth, cos_inc, cfg, noise_rng, fx=k.fx, sensor_rng=sensor_rng)
    color8 = noisy_color(color, cfg, noise_rng)
    mask = np.where(hits.body == target_index, hits.face + 1, 0).astype(np.uint8)

    clutter_bodies = [b for b, r in zip(bodies, roles) if r == "clutter"]
    occluder_body = bodies[roles.index("occluder")] if "occluder" in roles else None
    contact_index = [i for i, r in enumerate(roles) if r == "contact"]
    contacts = [(c.relation, bodies[i], np.where(hits.body == i, hits.face + 1, 0).astype(np.uint8))
                for c, i in zip(layout.contacts, contact_index)]
    meta = {"schema": SCHEMA, "id": scene_id, "intrinsics": k.to_dict(), "depth_scale_m": 0.001,
            "noise": cfg.to_dict(), "seed": int(seed),
            "truth": scene_truth(layout, bodies[target_index], clutter_bodies, occluder_body, k, mask, contacts)}
    return RGBD(color8, depth, k, scene_id, meta), mask
