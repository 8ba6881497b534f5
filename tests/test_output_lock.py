"""One run at a time per --out: a second one stops in one line naming the first; the lock goes with the run."""

import os
import subprocess
import sys

import pytest

from lv3d.cli import main
from lv3d.errors import InputError
from lv3d.output import LOCK, lock_beside, lock_folder, replacing, write_atomic


def test_a_held_lock_stops_a_second_taker_and_names_the_holder(tmp_path):
    first = lock_folder(tmp_path, "--out x")
    with pytest.raises(InputError, match=rf"--out x: another lv3d run \(process {os.getpid()}\) is writing"):
        lock_folder(tmp_path, "--out x")
    first.release()
    lock_folder(tmp_path, "--out x").release()
    assert (tmp_path / LOCK).is_file()


def test_a_lock_dies_with_its_process(tmp_path):
    code = f"from lv3d.output import lock_folder; lock_folder({str(tmp_path)!r}, 'x'); import os; os._exit(0)"
    subprocess.run([sys.executable, "-c", code], check=True)
    lock_folder(tmp_path, "--out x").release()  # free again: the kernel dropped it with the process


def test_the_lock_beside_an_output_is_removed_after(tmp_path):
    out = tmp_path / "out"
    lock = lock_beside(out, "--out out")
    with pytest.raises(InputError, match="another lv3d run"):
        with replacing(out):
            pass
    lock.release()
    with replacing(out) as tmp:
        (tmp / "a.txt").write_text("a")
    assert sorted(p.name for p in tmp_path.iterdir()) == ["out"]


def test_dataset_make_into_a_folder_being_made_stops(tmp_path, capsys):
    out = tmp_path / "data"
    lock = lock_beside(out, "--out data")
    try:
        rc = main(["dataset", "make", "--classes", "cube", "--per-class", "1", "--out", str(out)])
    finally:
        lock.release()
    err = capsys.readouterr().err.strip()
    assert rc == 2 and "another lv3d run" in err and len(err.splitlines()) == 1 and not out.exists()


def test_write_atomic_leaves_the_old_file_or_the_new_one(tmp_path):
    p = tmp_path / "f.json"
    write_atomic(p, "old")

    with pytest.raises(Exception):
        write_atomic(p, object())  # not text nor bytes: fails while writing
    assert p.read_text() == "old" and sorted(x.name for x in tmp_path.iterdir()) == ["f.json"]
