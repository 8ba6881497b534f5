"""The quick paths kept for speed give what the plain computations give: Monte Carlo draws of only the
quantities that are read, vertex merging and point compression in pack_object, the edge field's
per-channel gradients and float32 magnitudes, and describe's face features taken per problem at once."""

import jax
import jax.numpy as jnp
import numpy as np
from jax.flatten_util import ravel_pytree

import grounding
from grounding import _confidence, _problem
from grounding._uncertainty import Quantities

INTR = (600.0, 600.0, 320.0, 240.0)


def test_draws_equal_the_columns_of_drawing_every_quantity():
    rng = np.random.default_rng(3)
    f, s, k = 4, 6, 9
    shapes = dict(side_px=(f, s), corner_deg=(f, s), para_dev_deg=(f, 2), log_side_m=(f, s), corner3d_deg=(f, s),
                  tilt_deg=(f,), dihedral_deg=(f, f), parallel_deg=(f, f))
    q = Quantities(**{name: jnp.asarray(rng.normal(size=sh), jnp.float32) for name, sh in shapes.items()})
    q_flat, unravel = ravel_pytree(q)
    jq = jnp.asarray(rng.normal(size=(q_flat.shape[0], k)), jnp.float32)
    a = rng.normal(size=(k, k))
    cov = jnp.asarray(a @ a.T + k * np.eye(k), jnp.float32)
    floors = grounding.Floors()
    got = jax.jit(_confidence.draws)(q, jq, cov, floors)

    # the plain computation: every quantity drawn inside the program from the same keys
    chol = jnp.linalg.cholesky(cov + 1e-9 * jnp.eye(k, dtype=cov.dtype))
    key_a, key_b = jax.random.split(jax.random.key(0))
    z = jax.random.normal(key_a, (_confidence.MC_DRAWS, k), cov.dtype)
    zf = jax.random.normal(key_b, (_confidence.MC_DRAWS, q_flat.shape[0]), cov.dtype)
    floor_flat = ravel_pytree(_confidence.floored(jax.tree.map(jnp.zeros_like, q), floors))[0]
    want = jax.vmap(unravel)(q_flat[None] + (z @ chol.T) @ jq.T + zf * floor_flat[None])
    for name in ("para_dev_deg", "log_side_m", "corner3d_deg"):
        np.testing.assert_allclose(getattr(got, name), getattr(want, name), rtol=1e-4, atol=1e-4)


def test_close_vertices_of_two_faces_meet_halfway_once():
    left = np.array([[100.0, 100.0], [150.0, 100.0], [150.0, 150.0], [100.0, 150.0]])
    right = np.array([[151.0, 100.0], [200.0, 100.0], [200.0, 150.0], [151.0, 151.0]])
    prob, index = grounding.pack_object([left, right], intrinsics=INTR)
    assert int(np.sum(prob.vertex_mask)) == 6
    shared = sorted(set(index[0, :4]) & set(index[1, :4]))  # slots past a face's sides are padding
    assert len(shared) == 2
    np.testing.assert_allclose(np.asarray(prob.vertices)[shared], [[150.5, 100.0], [150.5, 150.5]])
    # a face never uses one vertex twice, even where two of its own corners are within the merge distance
    tiny = np.array([[300.0, 300.0], [303.0, 300.0], [301.0, 303.0]])
    _, index = grounding.pack_object([tiny], intrinsics=INTR)
    assert len(set(index[0, :3])) == 3


def test_compressed_points_keep_the_count_and_the_mean():
    rng = np.random.default_rng(1)
    pts = np.c_[rng.uniform(-0.1, 0.1, (3000, 2)), rng.uniform(0.9, 1.1, 3000)]
    means, weights = _problem._compress(pts, 64, INTR)
    assert len(means) <= 64 and weights.sum() == len(pts)
    np.testing.assert_allclose((means * weights[:, None]).sum(0) / weights.sum(), pts.mean(0), atol=1e-9)


def test_edge_field_takes_each_edge_from_its_strongest_channel():
    img = np.zeros((120, 160, 3), np.uint8)
    img[:, 80:, 1] = 200  # a step in green only, at u = 79.5
    img[60:, :, 2] = 90   # a weaker step in blue only, at v = 59.5
    field = grounding.edge_distance_field(img)
    assert abs(field[20, 79] + 0.5) < 0.15 and abs(field[20, 80] - 0.5) < 0.15
    assert abs(field[59, 20] + 0.5) < 0.15 and abs(field[60, 20] - 0.5) < 0.15
    assert abs(field[20, 70] + 9.5) < 0.2


def test_edge_field_float32_magnitude_is_the_int32_one():
    # the field takes sqrt(dx^2 + dy^2) in float32 straight from the int16 Sobel derivatives of uint8 images
    # (|d| <= 4 * 255); that equals sqrt of the exact int32 sum, since every such sum is below 2^24
    d = np.arange(-1020, 1021, 3, dtype=np.int16)
    dx, dy = np.meshgrid(d, d)
    exact = np.sqrt((dx.astype(np.int32) ** 2 + dy.astype(np.int32) ** 2).astype(np.float32))
    fx, fy = dx.astype(np.float32), dy.astype(np.float32)
    np.testing.assert_array_equal(np.sqrt(fx * fx + fy * fy), exact)


def test_face_features_equal_the_per_face_computation():
    from lv3d.describe import _face_features
    from lv3d.perception.polygons import area

    rng = np.random.default_rng(5)
    f, s, u = 4, 6, 16
    g = {"conf": {"edge_support": rng.uniform(0, 1, f).astype(np.float32),
                  "corner_z": rng.uniform(-3, 30, (f, s)).astype(np.float32)},
         "vertices": rng.uniform(0, 400, (u, 2)).astype(np.float32),
         "scale2": np.array([2.5, 30.0, 1.0], np.float32),
         "planes": np.array([[0.0, 0.0, -1.0, 0.8]] * f, np.float32)}       # z = 0.8 m
    ns = [3, 6, 4]
    index = rng.integers(0, u, (len(ns), s))
    bumps = np.array([-0.002, 0.002, 0.001, -0.001])                      # 2, 2, 1, 1 mm off the plane
    points = [None, np.c_[np.zeros((4, 2)), 0.8 + bumps], np.zeros((0, 3))]
    got = _face_features(g, index, ns, points)
    for i, n in enumerate(ns):
        z = g["conf"]["corner_z"][i, :n]  # each corner's turn in spreads, as grounding's corner test gives it
        poly = g["vertices"][index[i, :n]]
        want = {"sides": n, "min_turn_z": float(z.min()),
                "support": float(g["conf"]["edge_support"][i]), "log_area_px": float(np.log(max(area(poly), 1.0))),
                "min_side_px": float(np.linalg.norm(np.diff(poly, axis=0, append=poly[:1]), axis=1).min()),
                "faces": len(ns), "edge_scale2": 2.5}
        if i == 1:  # the only face with points: their rms distance from its plane, mm
            assert abs(got[i].pop("plane_rms_mm") - np.sqrt(2.5)) < 1e-6
        if n > 3:  # the polygon without its weakest corner (smallest turn in spreads)
            k = int(np.argmin(z))
            rest = np.delete(poly, k, 0)
            want["fewer"] = {**want, "sides": n - 1, "min_turn_z": float(np.delete(z, k).min()),
                             "min_side_px": float(np.linalg.norm(np.diff(rest, axis=0, append=rest[:1]), axis=1).min())}
            got[i]["fewer"].pop("plane_rms_mm", None)
        assert got[i] == want


def test_normal_edge_field_in_boxes_is_the_whole_frame_field_there():
    rng = np.random.default_rng(4)
    v, u = np.mgrid[0:240, 0:320].astype(np.float32)
    depth = 0.8 + 0.0005 * u + 0.0003 * v  # a tilted floor
    roof = (np.abs(u - 120) + np.abs(v - 110) < 50)  # a pyramid-like bump: normals turn along its ridges
    depth = np.where(roof, depth - 0.002 * (50 - np.abs(u - 120) - np.abs(v - 110)), depth)
    depth = (depth * (1 + rng.normal(0, 0.001, depth.shape))).astype(np.float32)
    depth[200:215, 250:280] = 0  # a hole without readings
    intr = (300.0, 300.0, 160.0, 120.0)
    whole = grounding.normal_edge_field(depth, intr)
    boxes = [(60.2, 50.7, 181.3, 170.1), (230.0, 180.5, 300.9, 236.2)]
    part = grounding.normal_edge_field(depth, intr, roi=boxes)
    for u0, v0, u1, v1 in boxes:
        inside = (slice(int(v0), int(np.ceil(v1))), slice(int(u0), int(np.ceil(u1))))
        # each box's own field, as edge_distance_field computes a box on its own, at normal_edge_field's thresholds
        want = grounding.edge_distance_field(_normal_image_of(depth, intr)[inside], low=40.0, high=100.0)
        np.testing.assert_array_equal(part[inside], want)
    assert np.any(np.abs(whole[50:170, 60:181]) < 1) and np.all(part[:40] == 30.0)


def _normal_image_of(depth, intr):
    """The whole frame's normal image (grounding._field's own), to cut boxes from."""
    from grounding._field import _normal_image
    import cv2

    valid = depth > 0
    z = np.where(valid, depth, np.float32(0.0))
    wsum = cv2.GaussianBlur(valid.astype(np.float32), (0, 0), 2.0)
    zs = cv2.GaussianBlur(z, (0, 0), 2.0) / np.maximum(wsum, 1e-6)
    near = float(np.log(np.maximum(zs[valid].min(), 1e-3)))
    return _normal_image((0, 0, depth.shape[1], depth.shape[0]), z, valid, wsum, near, intr, 2.0)


def test_normal_image_is_the_one_its_channels_stacked_give():
    """The normal image written channel by channel into one array is the image that clipping the normals and the
    log depth apart and stacking them gives, bit for bit (with log depth and without)."""
    import cv2

    from grounding._field import _normal_image

    rng = np.random.default_rng(7)
    v, u = np.mgrid[0:120, 0:160].astype(np.float32)
    depth = (0.9 + 0.0007 * u - 0.0004 * v + rng.normal(0, 0.002, u.shape)).astype(np.float32)
    depth[30:45, 70:95] = 0
    intr = (150.0, 150.0, 80.0, 60.0)
    valid = depth > 0
    z = np.where(valid, depth, np.float32(0.0))
    wsum = cv2.GaussianBlur(valid.astype(np.float32), (0, 0), 2.0)
    pts = np.stack([(u - intr[2]) / intr[0] * z, (v - intr[3]) / intr[1] * z, z], -1)
    pts = cv2.GaussianBlur(pts, (0, 0), 2.0) / np.maximum(wsum, 1e-6)[..., None]
    du, dv = np.zeros_like(pts), np.zeros_like(pts)
    du[:, 1:-1] = pts[:, 2:] - pts[:, :-2]
    dv[1:-1] = pts[2:] - pts[:-2]
    n = np.cross(du, dv)
    n /= np.maximum(np.linalg.norm(n, axis=-1, keepdims=True), 1e-12)
    for near in (None, float(np.log(0.85))):
        want = np.clip((n + 1.0) * 127.5, 0, 255)
        if near is not None:
            logz = np.log(np.maximum(pts[..., 2], 1e-3))
            want = np.concatenate([want, np.clip((logz - near) * 400.0, 0, 255)[..., None]], -1)
        want[~valid] = 0
        got = _normal_image((0, 0, 160, 120), z, valid, wsum, near, intr, 2.0)
        np.testing.assert_array_equal(got, want.astype(np.uint8))
