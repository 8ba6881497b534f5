"""benchmarks.compare_real: two bench_real runs side by side."""

import json

from benchmarks.compare_real import direction, main, rows


def _run(path, recall, prism, ms):
    scope = {"depth": {"object_recall": recall, "cylinder_as_prism_frac": prism, "ms_median": ms, "split_frac": None,
                       "stage_ms_median": {"objects": ms / 2, "grounding": ms / 4}}}
    path.write_text(json.dumps({"pooled": scope, "folders": {"osd-learn": scope}}))
    return path


def test_each_change_is_judged_against_its_target():
    assert direction("object_recall", 0.90, 0.95) == "better"      # a target to reach from below
    assert direction("cylinder_as_prism_frac", 0.10, 0.05) == "better"  # and one to stay under
    assert direction("cylinder_as_prism_frac", 0.05, 0.10) == "worse"
    assert direction("object_recall", 0.9641, 0.9643) == "same"
    assert direction("split_frac", 0.1, 0.2) == ""                  # no target: no judgement
    a = {"depth": {"object_recall": 0.9, "split_frac": None}, "rgb": {"object_recall": 0.2}}
    b = {"depth": {"object_recall": 0.8, "split_frac": 0.1}}
    assert rows(a, b) == [("object_recall", "depth", 0.9, 0.8, "worse")]  # what both measured, nothing else


def test_the_comparison_prints_every_figure_and_counts_what_got_worse(tmp_path, capsys):
    a, b = _run(tmp_path / "a.json", 0.96, 0.05, 200.0), _run(tmp_path / "b.json", 0.97, 0.12, 150.0)
    assert main([str(a), str(b), "--folders"]) == 0
    out = capsys.readouterr().out
    assert "== osd-learn" in out
    line = next(l for l in out.splitlines() if l.startswith("cylinder_as_prism_frac"))
    assert "0.050 ok" in line and "0.120 MISS" in line and "worse" in line
    assert "1 worse: cylinder_as_prism_frac (depth)" in out  # time is left out of the count
    assert "median ms by stage, depth (A -> B): objects 100.0 -> 75.0, grounding 50.0 -> 37.5" in out


def test_a_file_that_is_no_bench_real_json_is_one_line(tmp_path, capsys):
    good = _run(tmp_path / "a.json", 0.9, 0.1, 100.0)
    (tmp_path / "bad.json").write_text('{"figures": 1}')
    assert main([str(good), str(tmp_path / "bad.json")]) == 2
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1 and "bad.json" in err and "bench_real --json" in err
    assert main([str(good), str(tmp_path / "missing.json")]) == 2
    assert "missing.json" in capsys.readouterr().err
