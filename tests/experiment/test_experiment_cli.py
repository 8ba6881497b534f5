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
