"""``call_saved`` exports a traced program to the cache folder, and a second process runs it from there
(deserialised, not traced again) with the same result. A small function stands in for ``ground_object``,
whose tracing alone takes ~20 s; the benchmark's first-call figure exercises that one."""

import os
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from grounding import _cache

ROOT = Path(__file__).resolve().parents[2]

CODE = r"""
import sys, jax, jax.numpy as jnp, numpy as np
import grounding
from grounding._cache import call_saved
grounding.enable_cache(sys.argv[1])
traced = []
def fn(x, k):
    traced.append(1)  # runs only while tracing
    return {"y": jnp.sin(x) * k, "s": jnp.sum(x)}
out = call_saved("probe", fn, (np.linspace(0, 1, 5).astype(np.float32), 3.0))
print(repr([np.asarray(v).tolist() for v in out]), len(traced))
"""


@pytest.mark.skipif(not _cache._CAN_SAVE, reason="jax.export needs the flatbuffers package")
def test_second_process_loads_the_exported_program(tmp_path):
    env = dict(os.environ, PYTHONPATH=str(ROOT))

    def run():
        r = subprocess.run([sys.executable, "-c", CODE, str(tmp_path)], capture_output=True, text=True, env=env,
                           cwd=ROOT, timeout=120)
        assert r.returncode == 0, r.stderr[-2000:]
        values, traced = r.stdout.strip().splitlines()[-1].rsplit(" ", 1)
        return eval(values), int(traced)

    first, traced_first = run()
    saved = list(tmp_path.glob("probe-*.jaxexport"))
    assert len(saved) == 1 and traced_first == 1
    stamp = saved[0].stat().st_mtime_ns
    second, traced_second = run()
    assert traced_second == 0  # deserialised, not traced
    assert saved[0].stat().st_mtime_ns == stamp
    np.testing.assert_allclose(second[0], first[0], rtol=1e-6)
    np.testing.assert_allclose(second[1], 3.0 * np.sin(np.linspace(0, 1, 5)), rtol=1e-5)
