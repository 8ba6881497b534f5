"""The crease-seed benchmark's command line, and its check on one real frame."""

from pathlib import Path

import pytest

import benchmarks.bench_creases as bench

OSD = Path(__file__).resolve().parents[3] / "shared" / "data" / "real" / "osd-learn"


def test_bad_counts_stop_at_the_command_line_and_a_folder_without_its_files_is_named(tmp_path, capsys):
    for bad in (["--limit", "0"], ["--repeats", "0"]):
        with pytest.raises(SystemExit) as e:
            bench.main([str(tmp_path), *bad])
        assert e.value.code == 2
    capsys.readouterr()
    assert bench.main([str(tmp_path)]) == 2
    assert str(tmp_path) in capsys.readouterr().err


@pytest.mark.real
def test_on_one_osd_frame_both_mark_the_same_cells(capsys):
    if not (OSD / "objects.csv").is_file():
        pytest.skip(f"real OSD frames not found at {OSD} (../shared/data/real/osd-learn)")
    assert bench.main([str(OSD), "--limit", "1", "--repeats", "1"]) == 0
    out = capsys.readouterr().out
    assert out.startswith("osd-learn: ") and "over 1 frames" in out
    calls = int(out.split(": ")[1].split()[0])
    assert f"same cells in {calls} of {calls}" in out
