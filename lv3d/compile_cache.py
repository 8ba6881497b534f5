"""The persistent caches of compiled JAX programs, turned on by lv3d's entry points only.

A frame's grounding runs JAX programs that take seconds to trace and compile; grounding keeps them on
disk (``grounding.enable_cache``: JAX's compilation cache and its saved traced programs, under
``$LV3D_CACHE/jax`` or ``~/.cache/lv3d/jax``), so that a new process reuses them. That is a process-wide
JAX setting that writes under the home folder, so no library call makes it: the lv3d commands that ground
frames, the benchmarks and the test suite call :func:`enable`, and the worker processes they start call
:func:`enable_if_asked` when they begin.
"""

from __future__ import annotations

import os

ASK = "LV3D_COMPILE_CACHE"  # set by enable(): worker processes inherit it and follow


def enable() -> None:
    """Turn the caches on in this process and ask the worker processes it starts to do the same."""
    os.environ[ASK] = "1"
    import grounding

    grounding.enable_cache()


def enable_if_asked() -> None:
    """At a worker process's start: the caches, when the entry point that started it turned them on."""
    if os.environ.get(ASK) == "1":
        enable()
