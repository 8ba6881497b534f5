"""Shared test settings: JAX in float64 on the CPU with a persistent compilation cache."""

import importlib.util
import os
from pathlib import Path

os.environ.setdefault("JAX_PLATFORMS", "cpu")
os.environ.setdefault("LV3D_CACHE", str(Path(__file__).resolve().parent.parent / ".cache"))

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
