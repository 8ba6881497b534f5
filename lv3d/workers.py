"""Worker processes die with the process that started them.

A worker of lv3d (rendering, facts, a study's cells) is a child process. Were its parent killed (SIGKILL,
the machine's out-of-memory killer), an orphaned worker would go on computing and writing into a folder
that a rerun is filling again. So every worker asks the kernel to kill it when its parent dies (Linux:
``prctl(PR_SET_PDEATHSIG, SIGKILL)``) and, if the parent is already gone by then, exits at once. Elsewhere
a thread in the worker polls the parent instead.

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
        time.sleep(1.0)
        if os.getppid() != parent:
            os._exit(1)


def die_with_parent(parent: int | None = None) -> None:
    """Make this process end when ``parent`` (default: its parent now) ends."""
    parent = os.getppid() if parent is None else parent
    if not _prctl_pdeathsig():
        threading.Thread(target=_watch, args=(parent,), daemon=True, name="lv3d-parent-watch").start()
    if os.getppid() != parent:  # the parent died before the request took hold
        os._exit(1)


def _before_fork() -> None:
    _parent_at_fork[:] = [os.getpid()]


def _after_fork_in_child() -> None:
    die_with_parent(_parent_at_fork[0] if _parent_at_fork else None)


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
