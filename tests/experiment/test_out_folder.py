"""A study's --out: marked as lv3d's, resumed in place, and never a folder of the user's."""

import pytest

from lv3d.errors import InputError
from lv3d.experiment.runner import run_study
from lv3d.output import MARKER


def test_a_study_folder_is_marked_and_resumed(tmp_path, tiny_config, fake_world):
    out = tmp_path / "run"
    run_study(tiny_config, out, ["systems=[lv3d-rgbd]"], progress=False)
    assert (out / MARKER).is_file()
    (out / MARKER).unlink()  # a study folder without the marker is still recognised by its layout
    res = run_study(tiny_config, out, ["systems=[lv3d-rgbd]"], progress=False)
    assert res["ran"] == 0 and res["skipped"] == 3 and (out / MARKER).is_file()


def test_a_folder_of_the_users_is_refused_before_any_work(tmp_path, tiny_config, fake_world):
    mine = tmp_path / "mine"
    mine.mkdir()
    (mine / "config.yaml").write_text("my own\n")  # config.yaml alone is not a study's layout
    with pytest.raises(InputError, match="lv3d did not write"):
        run_study(tiny_config, mine, progress=False)
    assert [p.name for p in mine.iterdir()] == ["config.yaml"] and (mine / "config.yaml").read_text() == "my own\n"
    with pytest.raises(InputError, match="holds the input"):
        run_study(tiny_config, tmp_path, progress=False)
