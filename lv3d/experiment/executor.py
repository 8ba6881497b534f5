"""Where a study's independent jobs run: its cells (condition, system, fold) and the facts of its images.

- :class:`LocalExecutor` (the default): ``workers`` processes of this machine (started by spawn, each dying
  with this process: lv3d.workers); one worker runs the jobs in this process, one after another.
- :class:`DaskExecutor`: the workers of a Dask distributed cluster, at ``address`` (``tcp://host:8786``,
  started with ``dask scheduler`` and ``dask worker ... --nthreads 1``) or, without one, a cluster of
  ``workers`` processes on this machine. The workers must have lv3d installed and see the study's data
  folder at the same path (a shared file system); what they compute comes back to this process, which
  alone writes into ``--out``.

A job is ``fn(job, shared)``: ``shared`` (the facts or pixels every cell of a system reads) is sent once
per map to a Dask cluster, with each job to local processes. Each job computes from its own seeds only,
so the results are the same, bit for bit, wherever and in whatever order the jobs run.
"""

from __future__ import annotations

import json
import os
from collections.abc import Callable, Iterator
from pathlib import Path
from typing import Any

from tqdm import tqdm

from .. import compile_cache
from ..errors import InputError
from ..output import write_atomic

EXECUTORS = ("local", "dask")


def start_worker() -> None:
    """A local worker process's start: it dies with its parent, and keeps compiled programs on disk when the
    entry point that started it does (lv3d.compile_cache)."""
    from ..workers import die_with_parent

    die_with_parent()
    compile_cache.enable_if_asked()


class LocalExecutor:
    name = "local"

    def __init__(self, workers: int = 1):
        self.workers = max(1, int(workers))
        self._pool = None

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.close()
        return False

    def map(self, fn: Callable, jobs: list, shared: Any = None, workers: int | None = None
            ) -> Iterator[tuple[int, Any]]:
        """(index of the job, its result), as jobs finish. ``workers``: at most this many processes for this
        map (default: the executor's, whose processes are kept for its next map until :meth:`close`)."""
        n = min(self.workers if workers is None else max(1, workers), len(jobs))
        if n <= 1:
            for i, job in enumerate(jobs):
                yield i, fn(job, shared)
            return
        from concurrent.futures import as_completed

        own = workers is not None and workers != self.workers
        pool = self._new_pool(n) if own else self._shared_pool()
        futures = {pool.submit(fn, job, shared): i for i, job in enumerate(jobs)}
        try:
            for f in as_completed(futures):
                yield futures[f], _result(f)
        except BaseException:
            for f in futures:
                f.cancel()
            if not own:
                self.close()
            raise
        finally:
            if own:
                pool.shutdown(cancel_futures=True)

    def _new_pool(self, n: int):
        from concurrent.futures import ProcessPoolExecutor
        from multiprocessing import get_context

        return ProcessPoolExecutor(n, mp_context=get_context("spawn"), initializer=start_worker)

    def _shared_pool(self):
        if self._pool is None:
            self._pool = self._new_pool(self.workers)
        return self._pool

    def close(self) -> None:
        pool, self._pool = self._pool, None
        if pool is not None:
            pool.shutdown(cancel_futures=True)


def _result(future):
    from concurrent.futures.process import BrokenProcessPool

    try:
        return future.result()
    except BrokenProcessPool as e:
        raise RuntimeError(f"a worker process died ({e}); rerun to resume") from None


class DaskExecutor:
    """Jobs on a Dask distributed cluster: ``address`` of its scheduler, or (None) a local cluster of
    ``workers`` processes (``processes=False``: threads of this process, for tests)."""

    name = "dask"

    def __init__(self, address: str | None = None, workers: int = 1, processes: bool = True, timeout: str = "20s"):
        try:
            from distributed import Client, LocalCluster
        except ImportError:
            raise InputError("--executor", "dask needs the 'distributed' package (pip install distributed)") from None
        self._cluster = None
        try:
            if address:
                self.client = Client(address, timeout=timeout)
            else:
                self._cluster = LocalCluster(n_workers=max(1, int(workers)), threads_per_worker=1,
                                             processes=processes, dashboard_address=":0",
                                             worker_dashboard_address=":0")  # any free port
                self.client = Client(self._cluster)
        except (OSError, TimeoutError) as e:
            self.close()
            raise InputError("--address", f"cannot reach the Dask scheduler at {address}: {e}") from None
        if os.environ.get(compile_cache.ASK) == "1":  # the entry point keeps compiled programs: so do the workers
            self.client.run(compile_cache.enable)

    def map(self, fn: Callable, jobs: list, shared: Any = None, workers: int | None = None
            ) -> Iterator[tuple[int, Any]]:
        from distributed import as_completed

        if not jobs:
            return
        # one object under one key of its own (a dict would be scattered item by item; hash=False: two maps of
        # the same data must not share, and release, one key)
        handle = self.client.scatter(_Shared(shared), broadcast=True, hash=False)
        futures = [self.client.submit(_call, fn, job, handle, pure=False) for job in jobs]
        index = {f.key: i for i, f in enumerate(futures)}
        try:
            for f in as_completed(futures):
                yield index[f.key], f.result()
        except BaseException:
            self.client.cancel(futures)
            raise
        finally:
            del handle

    def close(self) -> None:
        client, self.client = getattr(self, "client", None), None
        if client is not None:
            client.close()
        if self._cluster is not None:
            self._cluster.close()
            self._cluster = None


class _Shared:
    """What every job of a map reads, sent to the workers as one object."""

    def __init__(self, value):
        self.value = value


def _call(fn: Callable, job, shared: _Shared):
    return fn(job, shared.value)


def cache_missing(dest: Path, names: list[str], fn: Callable, jobs: list, desc: str, workers: int = 1,
                  executor=None) -> Iterator[tuple[str, dict]]:
    """Compute the cache records a folder lacks: ``jobs[i]`` gives the JSON record of ``names[i]``, written to
    ``dest/<name>.json`` as it comes back (so that an interrupted run resumes), then yielded as (name, record).
    The jobs run on ``executor``, default ``workers`` local processes, with a progress bar labelled ``desc``;
    nothing runs (and no bar shows) when there is no job."""
    if not jobs:
        return
    own = executor is None
    executor = LocalExecutor(workers) if own else executor
    try:
        for i, record in tqdm(executor.map(fn, jobs, workers=None if own else workers), total=len(jobs), desc=desc):
            write_atomic(Path(dest) / f"{names[i]}.json", json.dumps(record))
            yield names[i], record
    finally:
        if own:
            executor.close()


def make_executor(kind: str = "local", workers: int = 1, address: str | None = None):
    """The executor named ``kind`` (:data:`EXECUTORS`); InputError for an unknown name or a bad pairing."""
    if kind not in EXECUTORS:
        raise InputError("--executor", f"unknown executor {kind!r}; known: {', '.join(EXECUTORS)}")
    if address and kind != "dask":
        raise InputError("--address", "an address needs --executor dask")
    if kind == "dask":
        return DaskExecutor(address, workers)
    return LocalExecutor(workers)
