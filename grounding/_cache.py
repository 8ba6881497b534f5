"""Persistent caches, so that a new process reuses the programs an earlier one traced and compiled."""

from __future__ import annotations

import functools
import hashlib
import os
from pathlib import Path

import jax
import numpy as np

_enabled: Path | None = None
_asked: tuple | None = None  # the request that gave _enabled


def enable_cache(path: str | os.PathLike | None = None) -> Path:
    """Turn on JAX's persistent compilation cache and return its folder.

    ``path`` defaults to ``$LV3D_CACHE/jax`` when the environment variable ``LV3D_CACHE`` is set,
    else ``~/.cache/lv3d/jax``. Every program is cached, however small or quick to compile: the
    grounding programs compile in well under JAX's default 1 s threshold, yet a cold compile of
    all of them costs seconds at the first frame of every new process.
    Calling it again with the same folder does nothing; a different folder switches to it.
    """
    global _enabled, _asked
    # a caller may ask again and again: resolving the path takes system calls, so the same request
    # (argument and the environment it depends on) returns the folder it found last time
    asked = (None if path is None else os.fspath(path), os.environ.get("LV3D_CACHE"), os.environ.get("HOME"))
    if _enabled is not None and asked == _asked:
        return _enabled
    if path is None:
        root = os.environ.get("LV3D_CACHE")
        path = Path(root) / "jax" if root else Path.home() / ".cache" / "lv3d" / "jax"
    path = Path(path).expanduser().resolve()
    if _enabled != path:
        path.mkdir(parents=True, exist_ok=True)
        jax.config.update("jax_compilation_cache_dir", str(path))
        jax.config.update("jax_persistent_cache_min_compile_time_secs", 0.0)
        jax.config.update("jax_persistent_cache_min_entry_size_bytes", -1)
        _enabled = path
    _asked = asked
    return path


_programs: dict[str, object] = {}
_keys: dict[tuple, str] = {}

try:  # jax.export needs flatbuffers to serialise; without it programs are traced once per process
    import flatbuffers  # noqa: F401

    _CAN_SAVE = True
except ImportError:
    _CAN_SAVE = False


@functools.cache
def _source_digest() -> str:
    """Digest of this package's sources: a saved program is reused only by the code that wrote it. The
    calibration maps are applied outside traced code, so refitting them keeps the saved programs."""
    h = hashlib.sha256(jax.__version__.encode())
    for p in sorted(Path(__file__).parent.glob("*.py")):
        if p.name.startswith("_calibration"):
            continue
        h.update(p.name.encode())
        h.update(p.read_bytes())
    return h.hexdigest()


_scalars: dict[tuple, jax.Array] = {}


def _leaf(x):
    """A pytree leaf as an array of a fixed dtype (Python scalars become float32 / int32 / bool).

    Scalars (the settings, floors and flags) become device arrays kept per value: a program call moves
    every host argument to the device, ~10 us each, and there are a dozen and a half of them per call."""
    if isinstance(x, bool):
        dtype = np.bool_
    elif isinstance(x, int):
        dtype = np.int32
    elif isinstance(x, float):
        dtype = np.float32
    else:
        return x
    key = (dtype, x)
    arr = _scalars.get(key)
    if arr is None:
        arr = _scalars[key] = jax.device_put(np.asarray(x, dtype))
    return arr


def call_saved(name: str, fn, args: tuple) -> list:
    """``jax.tree.leaves(fn(*args))``, through a program traced once and kept on disk.

    Tracing a program that holds an optimistix solver takes seconds, and JAX's compilation cache keeps
    only what comes after tracing. So the traced program is exported (``jax.export``) to the cache
    folder, keyed by the package's sources, the JAX version and the arguments' structure, shapes and
    dtypes; a new process deserialises it instead of tracing, and its compilation comes from the
    persistent cache. Without :func:`enable_cache`, or without the ``flatbuffers`` package that
    serialisation needs, the program is traced once per process and not saved.
    """
    leaves, treedef = jax.tree.flatten(args)
    leaves = [_leaf(x) for x in leaves]
    # hashing the structure as text costs more than a small program's run: remember each key by its parts
    parts = (name, treedef, tuple((x.shape, x.dtype) for x in leaves))
    key = _keys.get(parts)
    if key is None:
        spec = [(tuple(np.shape(x)), str(x.dtype)) for x in leaves]
        key = _keys[parts] = hashlib.sha256(f"{name}|{_source_digest()}|{treedef}|{spec}".encode()).hexdigest()[:24]
    call = _programs.get(key)
    if call is None and not (_CAN_SAVE and _enabled is not None):
        def flat_jit(*lv):
            return jax.tree.leaves(fn(*jax.tree.unflatten(treedef, lv)))

        call = _programs[key] = jax.jit(flat_jit)
    if call is None:
        path = _enabled / f"{name}-{key}.jaxexport"
        if path.is_file():
            exp = jax.export.deserialize(bytearray(path.read_bytes()))
        else:
            def flat(*lv):
                return jax.tree.leaves(fn(*jax.tree.unflatten(treedef, lv)))

            exp = jax.export.export(jax.jit(flat))(*[jax.ShapeDtypeStruct(np.shape(x), x.dtype) for x in leaves])
            tmp = path.with_suffix(f".tmp{os.getpid()}")
            tmp.write_bytes(exp.serialize())
            tmp.replace(path)  # atomic: a concurrent reader sees the whole file or none
        call = jax.jit(exp.call)
        _programs[key] = call
    return call(*leaves)
