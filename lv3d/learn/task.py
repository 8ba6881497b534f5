"""Task files (Metagol's example files unchanged, and lv3d's own form; prolog/mil_task.pl and
docs/learner.md): learn them and get the programs back.

A task file is read as data by ``prolog/mil_main.pl`` in a SWI-Prolog process of its own, under a
time and a memory limit that this module enforces from outside: whatever the file's own Prolog
does (mil_safe checks it before it runs), the process ends, and its end is reported in one line.
"""

from __future__ import annotations

import os
import selectors
import shutil
import signal
import subprocess
import time
from dataclasses import dataclass, field
from pathlib import Path

import psutil

from ..errors import InputError
from . import engine
from .engine import LearnError

MODES = ("exact", "noisy", "validate")
# A file another part of lv3d reads in its own (embedded) Prolog is first read here: at most this size.
MAX_VALIDATE_BYTES = 1 << 20
# Memory for one task's process, in MB: the Prolog stacks get this much (--stack-limit), the whole
# process this and 512 MB more (its address space, RLIMIT_AS).
MEMORY_MB = 2048
# Seconds of CPU the process may use past a goal's limits (reading the file, starting up) before it is
# stopped from outside.
GRACE_S = 10.0
# The stop from outside counts the process's CPU time, so that a machine busy with other work, which slows
# the process without it doing more, does not stop a search that would have ended by itself. A process
# that uses its CPU allowance this many times over in wall time without spending it (blocked) is stopped
# all the same.
WALL_FACTOR = 4.0


@dataclass(frozen=True)
class GoalResult:
    """One learning goal of a task file: its program (clauses as Metagol prints them), or None when
    no program is within the bounds, or the reason it could not be learned (``error``, with
    ``kind``: time_limit, memory, input, error)."""

    name: str
    clauses: tuple[str, ...] | None = None
    error: str | None = None
    kind: str | None = None
    cpu_s: float = 0.0
    wall_s: float = 0.0


@dataclass(frozen=True)
class TaskRun:
    path: Path
    goals: tuple[GoalResult, ...] = ()
    warnings: tuple[str, ...] = field(default_factory=tuple)


def swipl() -> str:
    """The SWI-Prolog executable: $LV3D_SWIPL, else ``swipl`` on PATH."""
    exe = os.environ.get("LV3D_SWIPL") or shutil.which("swipl")
    if not exe:
        raise LearnError("SWI-Prolog's swipl is not on PATH (or set LV3D_SWIPL)")
    return exe


def run_task(path: str | Path, *, time_limit: float | None = None, settings: dict | None = None,
             goal: str | None = None, mode: str = "exact", memory_mb: int = MEMORY_MB) -> TaskRun:
    """Learn every goal of the task file (or ``goal``) with the exact search (Metagol's) or the
    noise-tolerant one (``mode="noisy"``). InputError for a missing or unusable file; a goal that
    runs out of time or memory is a GoalResult with its error."""
    import prolog as sources

    path = Path(path)
    if not path.is_file():
        raise InputError(path, "no such task file")
    if mode not in MODES:
        raise InputError("mode", f"must be one of {', '.join(MODES)}, got {mode!r}")
    opts = dict(settings or {})
    if time_limit is not None:
        if not time_limit > 0:
            raise InputError("--time-limit", f"must be positive, got {time_limit}")
        opts["time_limit"] = float(time_limit)
    if not (isinstance(memory_mb, int) and 64 <= memory_mb <= 1 << 20):
        raise InputError("--memory-limit", f"must be a whole number of MB from 64, got {memory_mb!r}")
    main = str(sources.source("mil_main.pl"))
    # the address space is bounded by the shell that execs swipl (no preexec_fn: this process may have
    # threads); a process group of its own (start_new_session), so that stopping it stops everything it started
    cmd = ["/bin/sh", "-c", f'ulimit -v {(memory_mb + 512) * 1024} && exec "$0" "$@"', swipl(),
           f"--stack-limit={memory_mb}m", "-q", main, "--", str(path), engine.settings_term(opts), mode, goal or ""]
    limit = float(opts.get("time_limit", 10.0))
    per_goal = 2 * limit + GRACE_S  # running the goal up to its learning call, then the search
    proc = subprocess.Popen(cmd, stdout=subprocess.PIPE, stderr=subprocess.PIPE, stdin=subprocess.DEVNULL,
                            start_new_session=True)
    records = _Records()
    allowance = _Allowance(proc, limit + GRACE_S)
    sel = selectors.DefaultSelector()
    sel.register(proc.stdout, selectors.EVENT_READ)
    stopped = False
    try:
        while True:
            if sel.select(timeout=1.0):
                chunk = os.read(proc.stdout.fileno(), 65536)
                if not chunk:
                    break
                if records.read(chunk):
                    allowance.restart(per_goal)
            elif proc.poll() is not None:
                break
            if allowance.spent() and proc.poll() is None:
                _stop(proc)
                stopped = True
                break
        records.read(proc.stdout.read() or b"")  # what it wrote before it ended or was stopped
    finally:
        sel.close()
        err = b""
        try:
            _, err = proc.communicate(timeout=5)
        except subprocess.TimeoutExpired:
            _stop(proc)
    goals, warnings, current, fatal = records.goals, records.warnings, records.current, records.fatal
    if fatal:
        kind, where, msg = (fatal + ["", "", ""])[:3]
        if kind == "input":
            raise InputError(where or path, msg)
        raise LearnError(f"{path}: {msg}")
    if current is not None:  # the process ended, or was stopped, inside a goal
        why = _ended(proc, stopped, limit, err)
        goals.append(GoalResult(current["name"], None, why[1], why[0]))
    elif not goals and (stopped or proc.returncode not in (0, None)):
        kind, msg = _ended(proc, stopped, limit, err)
        raise LearnError(f"{path}: {msg}")
    elif stopped:  # between two goals: those not begun have no result
        warnings.append(f"the learner was stopped after {len(goals)} goals: "
                        + _ended(proc, stopped, limit, err)[1])
    return TaskRun(path, tuple(goals), tuple(warnings))


class _Records:
    """The records mil_main.pl writes, read as they come: the goals learned, the warnings, the goal under
    way (None between goals) and a fatal error."""

    def __init__(self) -> None:
        self.goals: list[GoalResult] = []
        self.warnings: list[str] = []
        self.current: dict | None = None
        self.fatal: list[str] | None = None
        self._buf = b""

    def read(self, chunk: bytes) -> bool:
        """Take in the output's next bytes; True when a goal started in them."""
        *lines, self._buf = (self._buf + chunk).split(b"\n")
        started = False
        for raw in lines:
            rec = raw.decode("utf-8", "replace").split("\t")
            tag = rec[0]
            if tag == "warning":
                self.warnings.append(rec[1] if len(rec) > 1 else "")
            elif tag == "goal":
                self.current = {"name": rec[1], "clauses": [], "none": False, "error": None, "kind": None}
                started = True
            elif tag == "clause" and self.current is not None:
                self.current["clauses"].append(rec[1])
            elif tag == "none" and self.current is not None:
                self.current["none"] = True
            elif tag == "failed" and self.current is not None:
                self.current["kind"], self.current["error"] = rec[1], rec[2]
            elif tag == "time" and self.current is not None:
                self.goals.append(_result(self.current, float(rec[1]), float(rec[2])))
                self.current = None
            elif tag == "fatal":
                self.fatal = rec[1:]
        return started


class _Allowance:
    """The CPU seconds a process may use from now on (and WALL_FACTOR times as many of wall time)."""

    def __init__(self, proc: subprocess.Popen, seconds: float) -> None:
        self._last = 0.0
        try:
            self._process: psutil.Process | None = psutil.Process(proc.pid)
        except psutil.Error:  # ended already: it uses no more
            self._process = None
        self.restart(seconds)

    def _cpu(self) -> float:
        """The process's CPU seconds so far; once it has ended, the last it was seen to have used."""
        if self._process is not None:
            try:
                t = self._process.cpu_times()
                self._last = t.user + t.system
            except psutil.Error:  # ended since: its time no longer grows
                self._process = None
        return self._last

    def restart(self, seconds: float) -> None:
        self._seconds, self._cpu0, self._wall0 = seconds, self._cpu(), time.monotonic()

    def spent(self) -> bool:
        return (self._cpu() - self._cpu0 > self._seconds
                or time.monotonic() - self._wall0 > WALL_FACTOR * self._seconds)


def _result(cur: dict, cpu: float, wall: float) -> GoalResult:
    if cur["error"] is not None:
        return GoalResult(cur["name"], None, cur["error"], cur["kind"], cpu, wall)
    if cur["none"]:
        return GoalResult(cur["name"], None, None, None, cpu, wall)
    return GoalResult(cur["name"], tuple(cur["clauses"]), None, None, cpu, wall)


def _stop(proc: subprocess.Popen) -> None:
    try:
        os.killpg(proc.pid, signal.SIGKILL)
    except (ProcessLookupError, PermissionError):
        pass
    proc.wait()


def _ended(proc: subprocess.Popen, stopped: bool, limit: float, err: bytes) -> tuple[str, str]:
    text = (err or b"").decode("utf-8", "replace")
    if stopped:
        return "time_limit", f"the learner did not stop at its time limit of {limit:g} s and was stopped"
    if "memory" in text.lower() or "resource" in text.lower():
        return "memory", "the learner ran out of memory"
    rc = proc.returncode
    if rc is not None and rc < 0:
        return "error", f"the learner process ended with signal {-rc}"
    return "error", f"the learner process ended (exit code {rc})" + (f": {' '.join(text.split())[:200]}" if text else "")


def learn_task(path: str | Path, *, time_limit: float | None = None, settings: dict | None = None,
               goal: str | None = None, mode: str = "exact") -> list[str]:
    """The clauses (as Metagol prints them) of the program of the task file's one goal (or
    ``goal``): the smallest that proves every positive and no negative (mode exact), or the best
    scored (mode noisy). InputError for a missing or malformed file; LearnError when the search
    reaches its time limit or finds no program within the bounds, or the file has several goals
    and none is named."""
    run = run_task(path, time_limit=time_limit, settings=settings, goal=goal, mode=mode)
    if len(run.goals) != 1:
        names = ", ".join(g.name for g in run.goals)
        raise LearnError(f"{path}: the file learns {len(run.goals)} goals ({names}); name one")
    g = run.goals[0]
    if g.error is not None:
        raise LearnError(f"{path}: {g.error}")
    if g.clauses is None:
        raise LearnError(f"{path}: no program within the task's bounds proves every positive and no negative")
    return list(g.clauses)


def validate_file(path: str | Path) -> None:
    """InputError unless the file reads as Prolog terms nested at most 100 deep (read in a process of
    its own, so that no file can crash this one's embedded Prolog). For program files."""
    path = Path(path)
    if not path.is_file():
        raise InputError(path, "no such file")
    if path.stat().st_size > MAX_VALIDATE_BYTES:
        raise InputError(path, f"larger than {MAX_VALIDATE_BYTES} bytes; not a program lv3d wrote")
    run_task(path, mode="validate", time_limit=10, memory_mb=256)
