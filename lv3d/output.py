"""Output folders: lv3d writes only into folders of its own and never removes what it did not write.

Every folder a command writes (``--out``) carries the marker file :data:`MARKER`. An ``--out`` is taken
when it does not exist, is an empty folder, or carries the marker; it is refused, with a one-line
:class:`InputError` and before any work, when it is a regular file, a non-empty folder without the marker,
or a folder that is or holds one of the command's inputs.

Two ways to write:

- :func:`replacing` (``lv3d extract``, ``lv3d learn fit``): everything is written into a temporary folder
  beside ``--out``, which then takes ``--out``'s place; the folder it replaces is removed only when it
  carries the marker (or is empty). An error at any point leaves ``--out`` as it was and no temporary
  folder behind.
- :func:`claim` (``lv3d experiment run``, ``lv3d demo``): the folder is checked, made and marked, then
  filled in place, one complete file at a time (:func:`write_atomic`), so that a rerun resumes from what is
  there.

One run at a time: :func:`locked` holds a lock on a folder (``flock`` on its :data:`LOCK` file, released
by the kernel when the process ends, however it ends) while a run writes into it; a second run into the
same folder stops with a one-line error naming the first run's process. What a killed run left half-made
(temporary folders ``.NAME.partial-PID...``, ``.NAME.old-PID-...`` and files ``.NAME.tmp-PID``) is removed
by :func:`clean_stale` on the next run, once no process PID is alive.
"""

from __future__ import annotations

import errno
import os
import re
import secrets
import shutil
import tempfile
from collections.abc import Callable, Iterable, Iterator
from contextlib import contextmanager
from pathlib import Path

from .errors import InputError

MARKER = ".lv3d-output"
LOCK = ".lv3d-lock"
_MARKER_TEXT = "This folder was written by lv3d; lv3d may replace or add to it when run with this --out again.\n"


def is_own(path: Path) -> bool:
    """Whether ``path`` is a folder written by lv3d (it carries :data:`MARKER`)."""
    return (Path(path) / MARKER).is_file()


def check_out(out: Path, inputs: Iterable[Path | None] = (), option: str = "--out",
              own: Callable[[Path], bool] | None = None) -> Path:
    """``out`` resolved (symbolic links followed), or an InputError when lv3d must not write there.
    ``inputs``: the paths the command reads (files or folders; None is skipped). ``own``: recognises a folder
    of this command's output that carries no marker (its layout is lv3d's own)."""
    target = Path(out).expanduser().resolve()
    where = f"{option} {out}"
    if target.parent == target:
        raise InputError(where, "is the root of the file system; choose a folder of its own")
    for p in inputs:
        if p is None:
            continue
        rp = Path(p).expanduser().resolve()
        if rp == target or target in rp.parents:
            what = "is" if rp == target else "holds"
            raise InputError(where, f"{what} the input {p}; choose a folder of its own for the output")
    _refuse_foreign(target, where, own)
    return target


def _refuse_foreign(target: Path, where: str, own: Callable[[Path], bool] | None = None) -> None:
    if target.exists() or target.is_symlink():
        if not target.is_dir():
            raise InputError(where, "exists and is not a folder; lv3d writes a folder here and will not "
                                    "overwrite it")
        if not (is_own(target) or _is_empty(target) or (own is not None and own(target))):
            raise InputError(where, f"is a folder with files lv3d did not write (no {MARKER} file in it); "
                                    "choose a new or empty folder")


def _is_empty(folder: Path) -> bool:
    try:
        return not any(folder.iterdir())
    except OSError as e:
        raise InputError(folder, f"cannot read the folder: {e.strerror}") from None


def _writable_tree(folder: Path) -> str | None:
    """The first folder at or under ``folder`` that this process cannot change (None when all can be)."""
    for root, dirs, _ in os.walk(folder):
        if not os.access(root, os.W_OK | os.X_OK):
            return root
    return None


def _existing_parent(path: Path) -> Path:
    p = path.parent
    while not p.exists():
        p = p.parent
    return p


def _make_parent(target: Path, where: str) -> None:
    parent = _existing_parent(target)
    if not parent.is_dir():
        raise InputError(where, f"{parent} is not a folder")
    if not os.access(parent, os.W_OK | os.X_OK):
        raise InputError(where, f"cannot write in {parent} (read-only)")
    try:
        target.parent.mkdir(parents=True, exist_ok=True)
    except OSError as e:
        raise InputError(where, f"cannot create {target.parent}: {e.strerror}") from None


def claim(out: Path, inputs: Iterable[Path | None] = (), option: str = "--out",
          own: Callable[[Path], bool] | None = None) -> Path:
    """Check ``out`` (:func:`check_out`), make it and mark it as lv3d's, for a command that fills it in place.
    Returns the resolved folder."""
    target = check_out(out, inputs, option, own)
    where = f"{option} {out}"
    if target.is_dir():
        if not os.access(target, os.W_OK | os.X_OK):
            raise InputError(where, "is read-only")
    else:
        _make_parent(target, where)
        try:
            target.mkdir()
        except OSError as e:
            raise InputError(where, f"cannot create the folder: {e.strerror}") from None
    if not is_own(target):
        try:
            (target / MARKER).write_text(_MARKER_TEXT)
        except OSError as e:
            raise InputError(where, f"cannot write in the folder: {e.strerror}") from None
    return target


@contextmanager
def replacing(out: Path, inputs: Iterable[Path | None] = (), option: str = "--out") -> Iterator[Path]:
    """Yield a new, empty temporary folder beside ``out`` to write the outputs into; when the block ends
    without an error the folder gets the marker and takes ``out``'s place. On any error ``out`` is left as it
    was and the temporary folder is removed."""
    target = check_out(out, inputs, option)
    where = f"{option} {out}"
    if target.is_dir():
        blocked = _writable_tree(target)
        if blocked is not None:
            raise InputError(where, f"cannot replace it: {blocked} is read-only")
    _make_parent(target, where)
    lock = lock_beside(target, where)  # a second run writing the same --out stops here
    try:
        clean_stale(target.parent, target.name)
        tmp = Path(tempfile.mkdtemp(prefix=f".{target.name}.partial-{os.getpid()}-", dir=target.parent))
    except OSError as e:
        lock.release()
        raise InputError(where, f"cannot write beside it: {e.strerror}") from None
    try:
        yield tmp
        (tmp / MARKER).write_text(_MARKER_TEXT)
        _swap_in(tmp, target, where)
    except BaseException:
        shutil.rmtree(tmp, ignore_errors=True)
        raise
    finally:
        lock.release()


def _swap_in(new: Path, target: Path, where: str) -> None:
    """Move the folder ``new`` to ``target``; an earlier ``target`` (lv3d's own or empty) is removed after."""
    if not (target.exists() or target.is_symlink()):
        try:
            os.rename(new, target)
        except OSError as e:
            raise InputError(where, f"cannot move the output into place: {e.strerror}") from None
        return
    _refuse_foreign(target, where)  # still lv3d's own or empty: nothing else is ever moved aside
    old = target.parent / f".{target.name}.old-{os.getpid()}-{secrets.token_hex(4)}"
    try:
        os.rename(target, old)  # within one folder: needs no write access to the folder moved
    except OSError as e:
        raise InputError(where, f"cannot replace it: {e.strerror}") from None
    try:
        os.rename(new, target)
    except BaseException as e:
        os.rename(old, target)  # put the earlier output back
        if isinstance(e, OSError):
            raise InputError(where, f"cannot move the output into place: {e.strerror}") from None
        raise
    try:
        shutil.rmtree(old)
    except OSError as e:
        raise InputError(where, f"written, but the earlier output moved to {old} could not be removed: "
                                f"{e.strerror}; remove it by hand") from None


# ---- one run at a time, complete files, and what killed runs left behind --------------------------------

class _Lock:
    def __init__(self, fd: int, path: Path, remove: bool = False):
        self.fd, self.path, self.remove = fd, path, remove

    def release(self) -> None:
        if self.fd >= 0:
            if self.remove:  # removed while still held: a waiting run then finds it gone and takes a new one
                try:
                    os.unlink(self.path)
                except OSError:
                    pass
            os.close(self.fd)  # closing the descriptor drops the flock
            self.fd = -1


def lock_folder(folder: Path, where: str, wait: bool = False) -> _Lock:
    """Take the lock of ``folder`` (an existing folder lv3d writes into). Held: an InputError naming the
    process holding it, or with ``wait`` block until it is free."""
    return _lock_file(Path(folder) / LOCK, where, wait, remove=False)


def lock_beside(target: Path, where: str, wait: bool = False) -> _Lock:
    """The lock of an output that is made beside ``target`` and moved into its place (``.NAME.lock`` in its
    folder, removed when released)."""
    target = Path(target).expanduser().absolute()
    try:
        target.parent.mkdir(parents=True, exist_ok=True)
    except OSError as e:
        raise InputError(where, f"cannot create {target.parent}: {e.strerror}") from None
    return _lock_file(target.parent / f".{target.name}.lock", where, wait, remove=True)


def _lock_file(path: Path, where: str, wait: bool, remove: bool) -> _Lock:
    while True:
        lock = _try_lock(path, where, wait)
        if not remove:
            return lock
        try:  # the file a run released and removed while we waited for it: take the new one instead
            same = os.path.samestat(os.fstat(lock.fd), os.stat(path))
        except OSError:
            same = False
        if same:
            lock.remove = True
            return lock
        lock.release()


def _try_lock(path: Path, where: str, wait: bool) -> _Lock:
    import fcntl

    try:
        fd = os.open(path, os.O_RDWR | os.O_CREAT | getattr(os, "O_CLOEXEC", 0), 0o644)
    except OSError as e:
        raise InputError(where, f"cannot create the lock file {path.name}: {e.strerror}") from None
    try:
        fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
    except OSError as e:
        if e.errno not in (errno.EWOULDBLOCK, errno.EAGAIN, errno.EACCES):
            os.close(fd)
            raise InputError(where, f"cannot lock the folder: {e.strerror}") from None
        holder = _read_pid(fd)
        if not wait:
            os.close(fd)
            raise InputError(where, f"another lv3d run{f' (process {holder})' if holder else ''} is writing into "
                                    "this folder; wait for it to end or choose another --out")
        fcntl.flock(fd, fcntl.LOCK_EX)
    os.ftruncate(fd, 0)
    os.write(fd, f"{os.getpid()}\n".encode())
    return _Lock(fd, path)


def _read_pid(fd: int) -> int | None:
    try:
        text = os.pread(fd, 32, 0).decode().strip()
        return int(text) if text else None
    except (OSError, ValueError):
        return None


@contextmanager
def locked(folder: Path, where: str | None = None, wait: bool = False) -> Iterator[Path]:
    """Hold the lock of ``folder`` for the block (see :func:`lock_folder`)."""
    lock = lock_folder(folder, where or f"--out {folder}", wait)
    try:
        yield Path(folder)
    finally:
        lock.release()


def _alive(pid: int) -> bool:
    if pid == os.getpid():
        return True
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except PermissionError:
        return True
    return True


_STALE = re.compile(r"^\.(?P<name>.+)\.(?:partial-|old-|tmp-)(?P<pid>\d+)(?:-.*)?$")


def clean_stale(folder: Path, name: str | None = None) -> list[Path]:
    """Remove the temporary folders and files a killed lv3d process left in ``folder`` (of the output
    ``name`` only, when given): those whose process is no longer alive. Returns what it removed."""
    removed = []
    try:
        entries = list(Path(folder).iterdir())
    except OSError:
        return removed
    for p in entries:
        m = _STALE.match(p.name)
        if not m or (name is not None and m["name"] != name) or _alive(int(m["pid"])):
            continue
        try:
            if p.is_dir() and not p.is_symlink():
                shutil.rmtree(p)
            else:
                p.unlink()
            removed.append(p)
        except OSError:
            continue
    return removed


def write_atomic(path: Path, data: str | bytes) -> None:
    """Write ``path`` whole or not at all: into ``.NAME.tmp-PID`` beside it, then renamed over it."""
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    tmp = path.with_name(f".{path.name}.tmp-{os.getpid()}")
    try:
        if isinstance(data, str):
            tmp.write_text(data)
        else:
            tmp.write_bytes(data)
        os.replace(tmp, path)
    except BaseException:
        try:
            tmp.unlink()
        except OSError:
            pass
        raise
