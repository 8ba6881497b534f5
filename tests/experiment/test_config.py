"""Study configs: unknown keys, classes, presets and systems are errors naming the file and the key."""

import pytest
import yaml

from lv3d.errors import InputError
from lv3d.experiment.config import conditions, load_config, parse_override


def _write(tmp_path, text):
    p = tmp_path / "study.yaml"
    p.write_text(text)
    return p


def test_defaults_fill_a_minimal_config(tmp_path):
    cfg = load_config(_write(tmp_path, "name: x\n"))
    assert cfg["folds"] == 5 and cfg["train"]["positives"] == 40 and "lv3d-rgbd" in cfg["systems"]


@pytest.mark.parametrize("text,key", [
    ("epochs: 3\n", "'epochs'"),
    ("train: {positive: 3}\n", "'train.positive'"),
    ("data: {classes: [cube, dodecahedron]}\n", "data.classes"),
    ("data: {noise: foggy}\n", "data.noise"),
    ("data: {noise_overrides: {fog: 1}}\n", "data.noise_overrides"),
    ("data: {noise_overrides: {shadows: maybe}}\n", "data.noise_overrides"),
    ("data: {noise_overrides: {preset: hard}}\n", "data.noise_overrides"),
    ("systems: [lv3d-rgb, svm]\n", "systems"),
    ("folds: 1\n", "folds"),
    ("data: {per_class: 3}\n", "data.per_class"),
])
def test_bad_config_names_file_and_key(tmp_path, text, key):
    p = _write(tmp_path, text)
    with pytest.raises(InputError) as e:
        load_config(p)
    assert str(p) in str(e.value) and key in str(e.value)


def test_overrides_are_parsed_as_yaml_and_checked(tmp_path):
    p = _write(tmp_path, "name: x\n")
    cfg = load_config(p, ["train.positives=8", "systems=[lv3d-rgbd, cnn-rgbd]", "lv3d.settings.label_noise=false",
                          "data.noise_overrides.clutter=2"])
    assert cfg["train"]["positives"] == 8 and cfg["systems"] == ["lv3d-rgbd", "cnn-rgbd"]
    assert cfg["lv3d"]["settings"] == {"label_noise": False} and cfg["data"]["noise_overrides"] == {"clutter": 2}
    with pytest.raises(InputError, match="train.nope"):
        load_config(p, ["train.nope=1"])


def test_sweep_and_conditions_expand(tmp_path):
    p = _write(tmp_path, "sweep: {param: train.positives, values: [1, 4]}\n")
    conds = conditions(load_config(p), p)
    assert list(conds) == ["positives=1", "positives=4"] and conds["positives=4"]["train"]["positives"] == 4
    p = _write(tmp_path, "conditions: {full: {}, no_refinement: {lv3d.refine: false}}\n")
    conds = conditions(load_config(p), p)
    assert conds["full"]["lv3d"]["refine"] is True and conds["no_refinement"]["lv3d"]["refine"] is False
    p = _write(tmp_path, "conditions: {bad: {lv3d.refin: false}}\n")
    with pytest.raises(InputError, match="conditions.bad.*lv3d.refin"):
        load_config(p)


def test_shipped_study_configs_are_valid():
    from pathlib import Path

    root = Path(__file__).resolve().parents[2] / "experiments"
    configs = sorted(root.glob("*.yaml"))
    assert configs, "experiments/*.yaml missing"
    for p in configs:
        cfg = load_config(p)
        assert conditions(cfg, p)
        assert p.read_text().startswith("#"), f"{p.name} lacks its header comment"
        assert yaml.safe_load(p.read_text())["name"]


@pytest.mark.parametrize("text, value", [("k=1e-3", 0.001), ("k=-2.5E+2", -250.0), ("k=0.008", 0.008), ("k=2", 2),
                                         ("k=true", True), ("k=e5", "e5")])
def test_override_values_read_as_yaml_and_exponents_as_numbers(text, value):
    key, got = parse_override(text)
    assert key == "k" and got == value and type(got) is type(value)
