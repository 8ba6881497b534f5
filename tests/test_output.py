"""lv3d.output: lv3d writes only into folders of its own and removes only what it wrote."""

import os

import pytest

from lv3d.errors import InputError
from lv3d.output import MARKER, check_out, claim, is_own, replacing


def _user_folder(path):
    path.mkdir(parents=True, exist_ok=True)
    (path / "thesis.tex").write_text("years of work")
    return path


def _no_leftovers(folder):
    return [p.name for p in folder.iterdir() if ".partial-" in p.name or ".old-" in p.name]


def test_a_new_folder_is_written_and_marked(tmp_path):
    out = tmp_path / "a" / "b" / "out"
    with replacing(out) as tmp:
        (tmp / "x.txt").write_text("1")
    assert (out / "x.txt").read_text() == "1" and is_own(out)
    assert not _no_leftovers(out.parent)


def test_lv3d_output_is_replaced_on_a_rerun(tmp_path):
    out = tmp_path / "out"
    with replacing(out) as tmp:
        (tmp / "old.txt").write_text("1")
    with replacing(out) as tmp:
        (tmp / "new.txt").write_text("2")
    assert sorted(p.name for p in out.iterdir()) == [MARKER, "new.txt"]
    assert not _no_leftovers(tmp_path)


def test_an_empty_folder_is_taken(tmp_path):
    out = tmp_path / "out"
    out.mkdir()
    with replacing(out) as tmp:
        (tmp / "x.txt").write_text("1")
    assert (out / "x.txt").is_file()


@pytest.mark.parametrize("how", ["replacing", "claim"])
def test_a_folder_lv3d_did_not_write_is_refused_and_kept(tmp_path, how):
    out = _user_folder(tmp_path / "mine")
    with pytest.raises(InputError, match=f"--out .*mine: is a folder with files lv3d did not write .*{MARKER}"):
        if how == "claim":
            claim(out)
        else:
            with replacing(out):
                pytest.fail("must not start writing")
    assert (out / "thesis.tex").read_text() == "years of work" and not is_own(out)
    assert sorted(p.name for p in tmp_path.iterdir()) == ["mine"]


@pytest.mark.parametrize("rel", [".", ".."])
def test_dot_and_dot_dot_are_refused(tmp_path, monkeypatch, rel):
    here = _user_folder(tmp_path / "work")
    monkeypatch.chdir(here)
    with pytest.raises(InputError, match="lv3d did not write"):
        check_out(rel)
    assert (here / "thesis.tex").is_file()


def test_a_regular_file_is_refused_and_kept(tmp_path):
    f = tmp_path / "notes.txt"
    f.write_text("keep me")
    for call in (lambda: check_out(f), lambda: claim(f)):
        with pytest.raises(InputError, match="notes.txt: exists and is not a folder"):
            call()
    assert f.read_text() == "keep me"


def test_an_out_holding_or_equal_to_an_input_is_refused(tmp_path):
    out = tmp_path / "run"
    with replacing(out) as tmp:  # even lv3d's own output is not replaced when it holds an input
        (tmp / "frame.png").write_text("pixels")
    inp = out / "frame.png"
    for o in (out, tmp_path):
        with pytest.raises(InputError, match="holds the input .*frame.png"):
            check_out(o, (inp,))
    with pytest.raises(InputError, match="is the input"):
        check_out(out, (out,))
    assert inp.read_text() == "pixels"
    check_out(tmp_path / "elsewhere", (inp, None))  # a sibling is fine


def test_a_symbolic_link_to_lv3d_output_is_replaced_through(tmp_path):
    real = tmp_path / "real"
    with replacing(real) as tmp:
        (tmp / "a").write_text("1")
    link = tmp_path / "link"
    link.symlink_to(real)
    with replacing(link) as tmp:
        (tmp / "b").write_text("2")
    assert link.is_symlink() and (real / "b").is_file() and not (real / "a").exists()


def test_an_error_while_writing_leaves_the_earlier_output_and_nothing_else(tmp_path):
    out = tmp_path / "out"
    with replacing(out) as tmp:
        (tmp / "good.txt").write_text("1")
    with pytest.raises(RuntimeError):
        with replacing(out) as tmp:
            (tmp / "half.txt").write_text("2")
            raise RuntimeError("boom")
    assert sorted(p.name for p in out.iterdir()) == [MARKER, "good.txt"]
    assert sorted(p.name for p in tmp_path.iterdir()) == ["out"]


@pytest.fixture
def read_only(monkeypatch):
    """Make folders read-only (chmod 555); as root, who may write anyway, lv3d.output is also told so."""
    import lv3d.output

    made, real_access = [], os.access

    def access(path, mode):
        if mode & os.W_OK and os.path.realpath(path) in made:
            return False
        return real_access(path, mode)

    if os.geteuid() == 0:
        monkeypatch.setattr(lv3d.output.os, "access", access)

    def make(folder):
        folder.chmod(0o555)
        made.append(os.path.realpath(folder))

    yield make
    for f in made:
        os.chmod(f, 0o755)


def test_a_read_only_out_is_refused_before_anything_is_made(tmp_path, read_only):
    out = tmp_path / "out"
    with replacing(out) as tmp:
        (tmp / "x.txt").write_text("1")
    read_only(out)
    with pytest.raises(InputError, match="read-only"):
        with replacing(out):
            pytest.fail("must not start writing")
    with pytest.raises(InputError, match="read-only"):
        claim(out)
    assert sorted(p.name for p in tmp_path.iterdir()) == ["out"]
    assert (out / "x.txt").is_file()


def test_a_read_only_parent_is_refused(tmp_path, read_only):
    parent = tmp_path / "ro"
    parent.mkdir()
    read_only(parent)
    with pytest.raises(InputError, match="read-only"):
        with replacing(parent / "out"):
            pytest.fail("must not start writing")
    with pytest.raises(InputError, match="read-only"):
        claim(parent / "deeper" / "out")
    assert not any(parent.iterdir())


def test_claim_marks_and_keeps_what_is_there(tmp_path):
    out = claim(tmp_path / "run")
    (out / "fold0.json").write_text("{}")
    assert claim(tmp_path / "run") == out and (out / "fold0.json").is_file() and is_own(out)
    legacy = tmp_path / "legacy"
    (legacy / "folds").mkdir(parents=True)
    (legacy / "config.yaml").write_text("seed: 0\n")
    claim(legacy, own=lambda p: (p / "config.yaml").is_file())
    assert is_own(legacy) and (legacy / "config.yaml").is_file()
