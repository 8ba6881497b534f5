"""Shared test settings (JAX in float64 on the CPU with a persistent compilation cache) and fixtures."""

import importlib.util
import json
import os
from pathlib import Path

os.environ.setdefault("JAX_PLATFORMS", "cpu")
os.environ.setdefault("LV3D_CACHE", str(Path(__file__).resolve().parent.parent / ".cache"))

import cv2  # noqa: E402
import numpy as np  # noqa: E402
import pytest  # noqa: E402

REAL_DIR = Path(__file__).resolve().parent.parent.parent / "shared" / "data" / "real" / "pcl-kinect"


@pytest.fixture
def real_dir():
    if not REAL_DIR.is_dir():
        pytest.skip(f"real Kinect frames not found at {REAL_DIR} (../shared/data/real/pcl-kinect)")
    return REAL_DIR


@pytest.fixture(scope="session", autouse=True)
def _compile_cache():
    """The test suite is an entry point: grounding's compiled programs are kept under LV3D_CACHE (above)."""
    from lv3d import compile_cache

    compile_cache.enable()


@pytest.fixture(scope="session")
def load_script():
    """Loads a module of scripts/ (maintenance scripts, not part of the package) by file name, e.g. "readme_tables"."""

    def load(name: str):
        path = Path(__file__).resolve().parents[1] / "scripts" / f"{name}.py"
        spec = importlib.util.spec_from_file_location(name, path)
        mod = importlib.util.module_from_spec(spec)
        spec.loader.exec_module(mod)
        return mod

    return load


FOLDER_CLASSES = {"cube": "box", "triangular_prism": "prism"}


def write_frame_folder(folder, frames):
    """Rendered frames written in the real layout: (name, rendered class, seed) each; objects.csv labels the
    target at the centre of its faces' pixels."""
    from lv3d.render.frame import render_scene

    folder.mkdir()
    intr, rows = {"width": 320, "height": 240, "frames": {}}, ["frame,object,u,v,shape,partial,stacked,notes"]
    for name, cls, seed in frames:
        frame, faces = render_scene(cls, seed, "clean", 320, 240)
        cv2.imwrite(str(folder / f"{name}_rgb.png"), cv2.cvtColor(frame.color, cv2.COLOR_RGB2BGR))
        cv2.imwrite(str(folder / f"{name}_depth_mm.png"), np.round(frame.depth * 1000).astype(np.uint16))
        k = frame.intrinsics
        intr["frames"][name] = {"fx": k.fx, "fy": k.fy, "cx": k.cx, "cy": k.cy, "depth_scale_m": 0.001}
        v, u = np.nonzero(faces)
        i = int(np.argmin(np.hypot(u - u.mean(), v - v.mean())))  # a pixel of the object nearest its centre
        rows.append(f"{name},1,{u[i]},{v[i]},{FOLDER_CLASSES[cls]},no,no,")
    (folder / "intrinsics.json").write_text(json.dumps(intr))
    (folder / "objects.csv").write_text("\n".join(rows) + "\n")
    return folder


@pytest.fixture(scope="module")
def frames(tmp_path_factory):
    """Six rendered frames (cubes labelled box, triangular prisms prism) in the real layout, once per module."""
    names = [(f"frame-{i:03d}", cls, 11 + i) for i, cls in enumerate(["cube", "triangular_prism"] * 3)]
    return write_frame_folder(tmp_path_factory.mktemp("real") / "frames", names)
