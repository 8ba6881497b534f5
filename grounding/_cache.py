"""Persistent XLA compilation cache, so that a new process reuses the programs an earlier one compiled."""

from __future__ import annotations

import os
from pathlib import Path

import jax

_enabled: Path | None = None


def enable_cache(path: str | os.PathLike | None = None) -> Path:
    """Turn on JAX's persistent compilation cache and return its folder.

    ``path`` defaults to ``$LV3D_CACHE/jax`` when the environment variable ``LV3D_CACHE`` is set,
    else ``~/.cache/lv3d/jax``. Every program is cached, however small or quick to compile: the
    grounding programs compile in well under JAX's default 1 s threshold, yet a cold compile of
    all of them costs seconds at the first frame of every new process.
    Calling it again with the same folder does nothing; a different folder switches to it.
    """
    global _enabled
    if path is None:
        root = os.environ.get("LV3D_CACHE")
        path = Path(root) / "jax" if root else Path.home() / ".cache" / "lv3d" / "jax"
    path = Path(path).expanduser().resolve()
    if _enabled == path:
        return path
    path.mkdir(parents=True, exist_ok=True)
    jax.config.update("jax_compilation_cache_dir", str(path))
    jax.config.update("jax_persistent_cache_min_compile_time_secs", 0.0)
    jax.config.update("jax_persistent_cache_min_entry_size_bytes", -1)
    _enabled = path
    return path
