"""A study's run folder under trouble: a second run at once, a killed run, corrupt caches, a learner that
finds nothing, workers whose parent dies."""

import json
import os
import signal
import subprocess
import sys
import textwrap
import time
from pathlib import Path


from lv3d.cli import main
from lv3d.experiment.runner import run_study
from lv3d.output import LOCK, claim, clean_stale, lock_folder


def _conftest():
    import importlib.util

    spec = importlib.util.spec_from_file_location("experiment_conftest", Path(__file__).with_name("conftest.py"))
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    return mod


TINY, write_dataset = _conftest().TINY, _conftest().write_dataset


def test_a_second_run_into_a_locked_folder_stops_in_one_line(tmp_path, tiny_config, fake_world, capsys):
    out = claim(tmp_path / "run")
    lock = lock_folder(out, "--out")  # as a first run holds it
    try:
        rc = main(["experiment", "run", str(tiny_config), "--out", str(out), "--quiet"])
        err = capsys.readouterr().err.strip()
        assert rc == 2 and len(err.splitlines()) == 1
        assert f"another lv3d run (process {os.getpid()}) is writing into this folder" in err
        assert not (out / "folds").exists()
    finally:
        lock.release()
    assert run_study(tiny_config, out, ["systems=[lv3d-rgbd]"], progress=False)["ran"] == 3
    assert (out / LOCK).is_file()


def test_what_a_killed_run_left_is_removed_but_not_what_a_live_one_writes(tmp_path):
    dead = subprocess.Popen([sys.executable, "-c", "pass"])
    dead.wait()
    (tmp_path / f".data.partial-{dead.pid}").mkdir()
    (tmp_path / f".data.partial-{dead.pid}" / "s000001").mkdir()
    (tmp_path / f".fold0.json.tmp-{dead.pid}").write_text("{")
    (tmp_path / f".data.partial-{os.getpid()}").mkdir()  # alive: this process
    (tmp_path / ".data.partial-notapid").mkdir()  # not lv3d's naming: left alone
    removed = clean_stale(tmp_path)
    assert sorted(p.name for p in removed) == sorted([f".data.partial-{dead.pid}", f".fold0.json.tmp-{dead.pid}"])
    assert sorted(p.name for p in tmp_path.iterdir()) == sorted([f".data.partial-{os.getpid()}", ".data.partial-notapid"])


def test_corrupt_cache_files_are_computed_again(tmp_path, tiny_config, fake_world):
    out = tmp_path / "run"
    sets = ["systems=[lv3d-rgbd, tree-rgbd]"]
    run_study(tiny_config, out, sets, progress=False)
    first = _records(out)
    facts = sorted((out / "facts").rglob("s*.json"))
    facts[0].write_text('{"facts": {"schema": ')  # cut short
    facts[1].write_text("")
    pixels = next((out / "data").rglob("pixels-*.npz"))
    pixels.write_bytes(b"")  # an empty npz
    for p in (out / "folds").rglob("fold*.json"):
        p.unlink()
    run_study(tiny_config, out, sets, progress=False)
    assert json.loads(facts[0].read_text())["facts"]["schema"] == "lv3d.facts/4" and pixels.stat().st_size > 100
    assert _records(out) == first


def test_a_class_without_a_program_is_recorded_and_reported(tmp_path, tiny_config, fake_world, monkeypatch, capsys):
    original = fake_world.fit.__func__

    def fit(cls, scenes, labels, settings=None, seed=0, classes=None):
        model = original(cls, scenes, labels, settings, seed, classes)
        model.failures = {"cube": "learning cube: time limit of 20 s exceeded"} if "cube" in (classes or []) else {}
        return model

    monkeypatch.setattr(fake_world, "fit", classmethod(fit))
    out = tmp_path / "run"
    rc = main(["experiment", "run", str(tiny_config), "--out", str(out), "--quiet", "--set", "systems=[lv3d-rgbd]"])
    assert rc == 0
    err = capsys.readouterr().err
    assert "in 6 learn calls the learner found no program for a class" in err  # cube and multiclass, 3 folds
    rec = json.loads((out / "folds" / "base" / "lv3d-rgbd" / "fold0.json").read_text())
    why = {"cube": "learning cube: time limit of 20 s exceeded"}
    assert rec["learn_failures"] == {"cube": why, "multiclass": why}
    md = (out / "results.md").read_text()
    assert "- lv3d-rgbd: 6 (fold 0 cube cube: learning cube: time limit of 20 s exceeded" in md


_WORKER_PARENT = textwrap.dedent("""
    import os, sys, time
    from lv3d.experiment.executor import LocalExecutor

    def job(j, shared):
        os.write(1, f"{os.getpid()}\\n".encode())  # one write: two workers' lines never interleave
        time.sleep(120)

    if __name__ == "__main__":
        for _ in LocalExecutor(2).map(job, [0, 1]):
            pass
""")


def test_workers_die_with_their_parent(tmp_path):
    script = tmp_path / "parent.py"
    script.write_text(_WORKER_PARENT)
    parent = subprocess.Popen([sys.executable, str(script)], stdout=subprocess.PIPE, text=True, cwd=tmp_path)
    workers = [int(parent.stdout.readline()) for _ in range(2)]
    os.kill(parent.pid, signal.SIGKILL)
    parent.wait()
    deadline = time.time() + 10
    while time.time() < deadline and any(_alive(w) for w in workers):
        time.sleep(0.1)
    assert not any(_alive(w) for w in workers)


def _alive(pid):
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    try:  # a zombie, not yet reaped by init, is dead
        return Path(f"/proc/{pid}/stat").read_text().split()[2] != "Z"
    except OSError:
        return False


def _baseline_study(tmp_path):
    """TINY with the baselines only and its data set already in a cache (nothing to monkeypatch: runs in a
    process of its own)."""
    from lv3d.experiment import data as data_mod
    from lv3d.experiment.config import load_study

    config = tmp_path / "tiny.yaml"
    config.write_text(TINY)
    sets = ["systems=[tree-rgbd, cnn-rgb, tree-depth]", f"data.cache={tmp_path / 'cache'}"]
    cfg = load_study(config, sets).base
    write_dataset(data_mod.dataset_dir(cfg, tmp_path), cfg.data.classes, cfg.data.per_class, cfg.seed)
    return config, sets


def _records(out):
    """Every fold file, less what depends on time."""
    def strip(obj):
        if isinstance(obj, dict):
            return {k: strip(v) for k, v in obj.items() if k != "seconds"}
        return obj
    return {p.relative_to(out).as_posix(): strip(json.loads(p.read_text())) for p in sorted((out / "folds").rglob("*.json"))}


def test_a_study_killed_and_resumed_gives_the_uninterrupted_results(tmp_path):
    config, sets = _baseline_study(tmp_path)
    args = ["run", str(config), "--quiet"] + [a for s in sets for a in ("--set", s)]
    cmd = [sys.executable, "-m", "lv3d.cli", "experiment"]
    whole = tmp_path / "whole"
    run_study(config, whole, sets, progress=False)  # uninterrupted, in this process
    out = tmp_path / "killed"
    run = subprocess.Popen(cmd + args + ["--out", str(out)], stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    deadline = time.time() + 120
    while time.time() < deadline and run.poll() is None:
        if out.exists() and list((out / "folds").rglob("fold*.json")):
            break
        time.sleep(0.05)
    run.kill()
    run.wait()
    done = len(list((out / "folds").rglob("fold*.json")))
    assert done < 9, "the run ended before it could be killed"
    subprocess.run(cmd + args + ["--out", str(out)], check=True, capture_output=True)
    assert _records(out) == _records(whole) and len(_records(whole)) == 9
    assert (out / "results.md").read_text() == (whole / "results.md").read_text()
