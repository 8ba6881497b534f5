"""The renderer's shortcuts give what the slow, obvious way gives: analytic shadows = shadow rays, rays
cast only inside the solids' silhouettes = rays cast through every pixel, and the PNG writer's options
round-trip exactly."""

import numpy as np
import open3d as o3d
import pytest

import lv3d.render.frame as frame_mod
from lv3d.render import noise_config
from lv3d.render.raycast import build_scene, raycast, rays_from_origin
from lv3d.render.shadows import shadow_mask


def _scene_inputs(cls, seed, cfg, w=160, h=120):
    """The bodies, intrinsics and light that render_scene hands to the ray caster."""
    seen = {}
    real = frame_mod.raycast

    def spy(bodies, k, light_cam=None, **kw):
        seen.update(bodies=bodies, k=k, light=light_cam, kw=kw)
        return real(bodies, k, light_cam, **kw)

    frame_mod.raycast = spy
    try:
        frame_mod.render_scene(cls, seed, cfg, w, h)
    finally:
        frame_mod.raycast = real
    return seen


@pytest.mark.parametrize("seed", [0, 1, 2, 3])
def test_analytic_shadows_match_shadow_rays(seed):
    cfg = noise_config("clean", shadows=True, clutter=3, occluder=1.0)
    s = _scene_inputs(["cube", "hexagonal_prism", "square_pyramid", "tetrahedron"][seed], seed, cfg)
    bodies, k, light = s["bodies"], s["k"], s["light"]
    hits = raycast(bodies, k, None, background=3)
    face_body = np.repeat(np.arange(len(bodies)), [len(b.solid.faces) for b in bodies])
    ours = shadow_mask(bodies, hits.gface, hits.face_normal, hits.face_offset, face_body, k, light) > 0
    # reference: one shadow ray per pixel from the visible point towards the light
    rays = np.empty(hits.depth.shape + (6,), np.float32)
    rays[..., :3] = hits.points()
    rays[..., 3:] = light.astype(np.float32)
    occluded = build_scene(bodies)[0].test_occlusions(o3d.core.Tensor(rays), tnear=1e-3, tfar=50.0).numpy()
    lit = np.append(hits.face_normal @ light > 1e-6, False)[hits.gface]  # shadows matter only there
    assert occluded[lit].sum() > 20, "the scene should hold some shadow"
    disagree = (occluded != ours)[lit].mean()
    assert disagree < 0.002, disagree


@pytest.mark.parametrize("seed", [4, 5, 6])
def test_casting_inside_silhouettes_finds_every_hit(seed):
    s = _scene_inputs("pentagonal_prism", seed, noise_config("clean", clutter=4, occluder=1.0))
    bodies, k = s["bodies"], s["k"]
    hits = raycast(bodies, k, None, background=3)
    solids = bodies[3:]
    scene, offsets, tri_body, tri_face = build_scene(solids)
    out = scene.cast_rays(o3d.core.Tensor(np.ascontiguousarray(rays_from_origin(k))))
    t = out["t_hit"].numpy()
    bg = raycast(bodies[:3], k, None, background=3)
    nearer = t < np.where(bg.depth > 0, bg.depth, np.inf)
    assert nearer.sum() > 100
    assert np.array_equal(hits.body >= 3, nearer)
    assert np.array_equal(hits.depth[nearer], t[nearer])


def test_png_options_round_trip(tmp_path):
    import cv2

    from lv3d.render.dataset import PNG_FLAGS
    rng = np.random.default_rng(0)
    arrays = {"color": rng.integers(0, 256, (48, 64, 3), dtype=np.uint8),
              "depth": rng.integers(0, 65536, (48, 64), dtype=np.uint16),
              "faces": rng.integers(0, 7, (48, 64), dtype=np.uint8)}
    for name, a in arrays.items():
        p = str(tmp_path / f"{name}.png")
        assert cv2.imwrite(p, a, PNG_FLAGS[name])
        assert np.array_equal(cv2.imread(p, cv2.IMREAD_UNCHANGED), a)


def test_convex_mask_is_the_pixel_centres_inside():
    import cv2

    from lv3d.render.shadows import convex_mask
    rng = np.random.default_rng(0)
    u, v = np.meshgrid(np.arange(60), np.arange(50))
    for t in range(100):
        hull = cv2.convexHull(rng.uniform(-5, 65, (6, 2)).astype(np.float32)).reshape(-1, 2).astype(float)
        if t % 2:
            hull = hull[::-1]
        s = np.sign(np.sum(hull[:, 0] * np.roll(hull[:, 1], -1) - np.roll(hull[:, 0], -1) * hull[:, 1]))
        inside = np.ones(u.shape, bool)
        for (a, b), (c, d) in zip(hull, np.roll(hull, -1, axis=0)):
            inside &= s * ((c - a) * (v - b) - (d - b) * (u - a)) >= 0
        assert np.array_equal(convex_mask(hull, u.shape), inside)
    square = np.array([[10, 10], [20, 10], [20, 20], [10, 20.0]])  # pixel centres on the outline count
    assert convex_mask(square, (30, 30)).sum() == 121
