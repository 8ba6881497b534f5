"""Worker processes die with the process that started them.

A worker of lv3d (rendering, facts, a study's cells) is a child process. Were its parent killed (SIGKILL,
the machine's out-of-memory killer), an orphaned worker would go on computing and writing into a folder
that a rerun is filling again. So every worker watches its parent: a thread of the worker checks twice a
second that its parent is still the process that started it, and ends the worker when it is not. A child
forked from the main thread also asks the kernel to kill it with its parent (Linux:
``prctl(PR_SET_PDEATHSIG, SIGKILL)``), which is immediate; the kernel ties that request to the thread that
started the child, so a child started from any other thread (a pool's, a Dask nanny's) relies on the
watching thread alone. A worker whose parent is gone already when it starts exits at once.

:func:`die_with_parent` does this in the calling process; :func:`install` makes every child forked from
this process do it (the entry points call it); a child started by ``spawn`` does it when it imports
lv3d (``lv3d/__init__.py``) or runs :func:`die_with_parent` as its pool's initializer.
"""

from __future__ import annotations

import os
import signal
import sys
import threading
import time

_PR_SET_PDEATHSIG = 1
_installed = False
_parent_at_fork: list[int] = []


def _prctl_pdeathsig() -> bool:
    if not sys.platform.startswith("linux"):
        return False
    try:
        import ctypes

        libc = ctypes.CDLL(None, use_errno=True)
        return libc.prctl(_PR_SET_PDEATHSIG, signal.SIGKILL, 0, 0, 0) == 0
    except (OSError, AttributeError):
        return False


def _watch(parent: int) -> None:
    while True:
        time.sleep(0.5)
        if os.getppid() != parent:
            os._exit(1)


def die_with_parent(parent: int | None = None, kernel: bool = False) -> None:
    """Make this process end when ``parent`` (default: its parent now) ends. ``kernel``: also ask the kernel
    (only for a child started from its parent's main thread)."""
    parent = os.getppid() if parent is None else parent
    if kernel:
        _prctl_pdeathsig()
    threading.Thread(target=_watch, args=(parent,), daemon=True, name="lv3d-parent-watch").start()
    if os.getppid() != parent:  # the parent died before the watch began
        os._exit(1)


def _before_fork() -> None:
    _parent_at_fork[:] = [os.getpid(), threading.current_thread() is threading.main_thread()]


def _after_fork_in_child() -> None:
    parent, main = _parent_at_fork if _parent_at_fork else (None, False)
    die_with_parent(parent, kernel=main)


def install() -> None:
    """Every child forked from this process from now on dies with it (idempotent)."""
    global _installed
    if not _installed and hasattr(os, "register_at_fork"):
        os.register_at_fork(before=_before_fork, after_in_child=_after_fork_in_child)
        _installed = True


def in_worker() -> None:
    """Called when lv3d is imported: in a child of the multiprocessing module (a spawned worker), die with
    the parent."""
    mp = sys.modules.get("multiprocessing")
    if mp is None:
        return
    try:
        parent = mp.parent_process()
    except AttributeError:
        return
    if parent is not None and parent.pid is not None:
        die_with_parent(parent.pid)
