"""lv3d.compile_cache: only entry points turn on grounding's persistent caches; worker processes follow them."""

import subprocess
import sys
from pathlib import Path

import lv3d

ROOT = Path(lv3d.__file__).resolve().parent


def test_no_library_module_turns_the_caches_on():
    # a process-wide JAX setting that writes under the home folder: lv3d's library code never makes it
    callers = sorted(str(p.relative_to(ROOT)) for p in ROOT.rglob("*.py")
                     if "enable_cache(" in p.read_text() and p.name != "compile_cache.py")
    assert callers == []


def _run(code: str, env_ask: bool) -> str:
    import os

    env = {k: v for k, v in os.environ.items() if k != "LV3D_COMPILE_CACHE"}
    if env_ask:
        env["LV3D_COMPILE_CACHE"] = "1"
    return subprocess.run([sys.executable, "-c", code], env=env, capture_output=True, text=True, check=True).stdout


def test_a_worker_follows_its_entry_point_only_when_asked(tmp_path):
    code = ("import grounding._cache as c; from lv3d import compile_cache; compile_cache.enable_if_asked(); "
            "print(c._enabled is not None)")
    assert _run(code, env_ask=False).strip() == "False"
    assert _run(code, env_ask=True).strip() == "True"


def test_enable_asks_the_workers_it_starts(tmp_path):
    code = ("import os; from lv3d import compile_cache; compile_cache.enable(); "
            "print(os.environ.get(compile_cache.ASK))")
    assert _run(code, env_ask=False).strip() == "1"
