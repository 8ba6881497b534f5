"""Small scenes made by the test code itself: a box on a table, ray-cast analytically; a folder of rendered frames
in the real-frame layout."""

import json

import cv2
import numpy as np
import pytest

from lv3d.camera import Intrinsics
from lv3d.perception.depth.cloud import PointGrid
from lv3d.render.sampler import look_at
from lv3d.rgbd import RGBD


def box_on_table(width=320, height=240, half=(0.05, 0.05), top=0.1, yaw_deg=30.0, noise_m=0.0, seed=0):
    """A box of half extents ``half`` (metres) and height ``top`` standing on a table (world z = 0), seen from
    0.6 m away and 40 deg above. Returns an RGBD frame (each box face its own shade of one colour) and the faces' outward
    normals in the camera frame as {name: (3,)} for the visible ones (top, and the sides that face the camera)."""
    k = Intrinsics(fx=300.0 * width / 320, fy=300.0 * width / 320, cx=(width - 1) / 2, cy=(height - 1) / 2,
                   width=width, height=height)
    eye = np.array([0.6 * np.cos(np.radians(40)), 0.0, 0.6 * np.sin(np.radians(40))]) + np.array([0, 0, 0.03])
    m = look_at(eye, np.array([0, 0, 0.04]))  # world-to-camera
    R, t = m[:3, :3], m[:3, 3]
    u, v = np.meshgrid(np.arange(width), np.arange(height))
    rays_c = np.stack([(u - k.cx) / k.fx, (v - k.cy) / k.fy, np.ones_like(u, float)], -1).reshape(-1, 3)
    rays_w = rays_c @ R  # R^T applied to each ray
    yaw = np.radians(yaw_deg)
    Rb = np.array([[np.cos(yaw), -np.sin(yaw), 0], [np.sin(yaw), np.cos(yaw), 0], [0, 0, 1]])
    o = Rb.T @ eye
    d = rays_w @ Rb
    lo = np.array([-half[0], -half[1], 0.0])
    hi = np.array([half[0], half[1], top])
    with np.errstate(divide="ignore", invalid="ignore"):
        t1 = (lo - o) / d
        t2 = (hi - o) / d
    tmin = np.nanmax(np.minimum(t1, t2), axis=1)
    tmax = np.nanmin(np.maximum(t1, t2), axis=1)
    hit_box = (tmax >= tmin) & (tmin > 0)
    axis = np.argmax(np.minimum(t1, t2), axis=1)
    t_table = -eye[2] / rays_w[:, 2]
    hit_table = (t_table > 0) & ~hit_box
    tt = np.where(hit_box, tmin, np.where(hit_table, t_table, 0.0))
    depth = (tt * rays_c[:, 2]).reshape(height, width)  # rays have z = 1 in the camera frame
    rng = np.random.default_rng(seed)
    if noise_m:
        depth = np.where(depth > 0, depth + rng.normal(0, noise_m, depth.shape), 0)
    pts_b = o + tmin[:, None] * d
    sign = np.where(np.take_along_axis(pts_b, axis[:, None], 1)[:, 0] > (lo + hi)[axis] / 2, 1, 0)
    face_code = axis * 2 + sign  # 0..5
    # one hue, each face its own shade: a solid of one colour, as the renders' (colour alone takes faces of two
    # chromaticities for two solids)
    palette = np.round(np.array([200, 110, 60])[None] * np.array([1.2, 0.55, 0.8, 0.4, 1.0, 0.65])[:, None]
                       ).clip(0, 255).astype(np.uint8)
    color = np.full((height * width, 3), 128, np.uint8)
    color[hit_box] = palette[face_code[hit_box]]
    color = color.reshape(height, width, 3)
    normals = {}
    names = {0: "-x", 1: "+x", 2: "-y", 3: "+y", 5: "top"}
    for code, name in names.items():
        n_b = np.zeros(3)
        n_b[code // 2] = 1.0 if code % 2 else -1.0
        n_c = R @ (Rb @ n_b)
        if np.count_nonzero(hit_box & (face_code == code)) > 50:
            normals[name] = n_c
    frame = RGBD(color, depth.astype(np.float32), k, name="box")
    return frame, normals


@pytest.fixture(scope="session")
def box_frame():
    return box_on_table()


def cell_grid(z: np.ndarray) -> PointGrid:
    """A point grid of 2 mm cells seen straight on, at depths ``z`` (rows, cols) metres; every cell read, normals
    left to be measured where needed (all zero)."""
    i, j = np.mgrid[0:z.shape[0], 0:z.shape[1]]
    xyz = np.stack([j * 0.002 * z, i * 0.002 * z, z], -1).astype(np.float32)
    return PointGrid(xyz, np.zeros_like(xyz), np.ones(z.shape, bool), 1)


# a box drawn in colour with a sliver of a right face, 6-8 px wide, seen nearly edge-on (corners in pixels)
A, B, C, D, E, F, F2 = (150, 30), (240, 60), (231, 100), (140, 70), (140, 170), (230, 200), (236, 200)
TOP, FRONT, SLIVER = np.array([A, B, C, D], float), np.array([D, C, F, E], float), np.array([B, F2, F, C], float)


def sliver_box(with_sliver: bool = True, table: bool = False) -> np.ndarray:
    """(240, 320, 3) uint8: the box's TOP, FRONT and (``with_sliver``) SLIVER on a grey floor, on a green table
    around it with ``table``; Gaussian noise of sigma 2, seeded."""
    img = np.full((240, 320, 3), (200, 200, 190), np.uint8)
    if table:
        cv2.fillPoly(img, [np.array([(100, 15), (290, 15), (290, 220), (100, 220)], np.int32)], (60, 150, 60))
    cv2.fillPoly(img, [TOP.astype(np.int32)], (200, 60, 60))
    cv2.fillPoly(img, [FRONT.astype(np.int32)], (140, 40, 40))
    if with_sliver:
        cv2.fillPoly(img, [SLIVER.astype(np.int32)], (90, 20, 20))
    noise = np.random.default_rng(0).normal(0.0, 2.0, img.shape)
    return np.clip(img + noise, 0, 255).astype(np.uint8)


def mask_iou(a: np.ndarray, b: np.ndarray) -> float:
    """Intersection over union of two (H, W) bool masks."""
    return float(np.count_nonzero(a & b) / np.count_nonzero(a | b))


@pytest.fixture(scope="session")
def real_layout(tmp_path_factory):
    """A folder in the real-frame layout (docs/real_frames.md) of two rendered RealSense frames, a cube and a
    cylinder, with masks and one labelled object each."""
    from lv3d.render.frame import render_scene

    f = tmp_path_factory.mktemp("real") / "frames"
    f.mkdir()
    intr = {"width": 640, "height": 480, "frames": {}}
    rows = ["frame,object,u,v,shape,partial,stacked,notes"]
    for i, cls in enumerate(["cube", "cylinder"]):
        frame, faces = render_scene(cls, 30 + i, "realsense")
        name = f"f{i}"
        cv2.imwrite(str(f / f"{name}_rgb.png"), cv2.cvtColor(frame.color, cv2.COLOR_RGB2BGR))
        cv2.imwrite(str(f / f"{name}_depth_mm.png"), np.round(frame.depth * 1000).astype(np.uint16))
        cv2.imwrite(str(f / f"{name}_label.png"), (faces > 0).astype(np.uint16))
        k = frame.intrinsics
        intr["frames"][name] = {"fx": k.fx, "fy": k.fy, "cx": k.cx, "cy": k.cy, "depth_scale_m": 0.001}
        v, u = np.nonzero(faces)
        rows.append(f"{name},1,{int(np.median(u))},{int(np.median(v))},{'box' if cls == 'cube' else 'cylinder'},no,no,")
    (f / "intrinsics.json").write_text(json.dumps(intr))
    (f / "objects.csv").write_text("\n".join(rows) + "\n")
    return f
