"""scripts/compare_facts.py: whether two code versions wrote the same facts files."""

import pytest


@pytest.fixture(scope="module")
def compare(load_script):
    return load_script("compare_facts")


def _write(root, key, version, variant, files):
    d = root / "cache" / "facts" / key / version / variant
    d.mkdir(parents=True)
    for name, text in files.items():
        (d / f"{name}.json").write_text(text)


def test_alike_files_pass_and_a_moved_real_folder_is_paired_by_its_file_names(tmp_path, compare, capsys):
    _write(tmp_path, "k1", "old", "rgbd-refine1", {"s0": "a", "s1": "b"})
    _write(tmp_path, "k1", "new", "rgbd-refine1", {"s0": "a", "s1": "b"})
    _write(tmp_path, "real-p1", "old", "depth-refine1", {"f0": "x"})  # the same folder read from another path
    _write(tmp_path, "real-p2", "new", "depth-refine1", {"f0": "x"})
    assert compare.main([str(tmp_path), "old", "new"]) == 0
    assert "3 facts files alike, 0 differ, 0 without a counterpart of old" in capsys.readouterr().out


def test_a_file_that_differs_is_named_and_fails(tmp_path, compare, capsys):
    _write(tmp_path, "k1", "old", "rgb-refine1", {"s0": "a", "s1": "b"})
    _write(tmp_path, "k1", "new", "rgb-refine1", {"s0": "a", "s1": "c", "s2": "d"})
    assert compare.main([str(tmp_path), "old", "new"]) == 1
    out = capsys.readouterr().out
    assert "1 facts files alike, 1 differ, 1 without a counterpart of old" in out and "s1.json" in out


def test_no_facts_of_the_new_version_is_an_error(tmp_path, compare, capsys):
    _write(tmp_path, "k1", "old", "rgb-refine1", {"s0": "a"})
    assert compare.main([str(tmp_path), "old", "new"]) == 2
    assert "no facts of version new" in capsys.readouterr().err
