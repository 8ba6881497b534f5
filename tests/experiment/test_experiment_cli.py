"""The command line: bad configs are one line on stderr and exit 2; a tiny study runs end to end."""

from lv3d.cli import main


def test_bad_config_is_one_line_and_exit_2(tmp_path, capsys):
    p = tmp_path / "bad.yaml"
    p.write_text("data: {classes: [cube, blob]}\n")
    assert main(["experiment", "run", str(p), "--out", str(tmp_path / "o")]) == 2
    err = capsys.readouterr().err.strip()
    assert err.count("\n") == 0 and "bad.yaml" in err and "data.classes" in err and "blob" in err
    assert not (tmp_path / "o").exists()  # nothing half-written


def test_run_prints_the_table(tmp_path, tiny_config, fake_world, capsys):
    rc = main(["experiment", "run", str(tiny_config), "--out", str(tmp_path / "o"), "--quiet",
               "--set", "systems=[lv3d-rgbd, tree-rgbd]", "--set", "folds=2"])
    assert rc == 0
    out = capsys.readouterr().out
    assert "4 fold results computed, 0 reused" in out and "| lv3d-rgbd |" in out


def test_report_joins_systems_run_in_parts(tmp_path, tiny_config, fake_world, capsys):
    out = tmp_path / "o"
    common = ["--out", str(out), "--quiet", "--set", "folds=2"]
    assert main(["experiment", "run", str(tiny_config), *common, "--set", "systems=[lv3d-rgbd]"]) == 0
    assert main(["experiment", "run", str(tiny_config), *common, "--set", "systems=[tree-rgbd]"]) == 0
    assert "| lv3d-rgbd |" not in (out / "results.md").read_text()  # the last run reports its own systems
    capsys.readouterr()
    assert main(["experiment", "report", str(tiny_config), "--out", str(out), "--set", "folds=2",
                 "--set", "systems=[lv3d-rgbd, tree-rgbd]"]) == 0
    text = (out / "results.md").read_text()
    assert "| lv3d-rgbd |" in text and "| tree-rgbd |" in text and "| lv3d-rgbd |" in capsys.readouterr().out


def test_report_of_a_folder_no_study_wrote_is_one_line(tmp_path, tiny_config, capsys):
    (tmp_path / "notes").mkdir()
    assert main(["experiment", "report", str(tiny_config), "--out", str(tmp_path / "notes")]) == 2
    err = capsys.readouterr().err.strip()
    assert err.count("\n") == 0 and "notes" in err and "not the work folder of a study" in err
