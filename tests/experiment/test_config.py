"""Study configs: unknown keys, classes, presets and systems are errors naming the file and the key."""

import pytest
import yaml

from lv3d.errors import InputError
from lv3d.experiment.config import StudyConfig, load_study, parse_override


def _write(tmp_path, text):
    p = tmp_path / "study.yaml"
    p.write_text(text)
    return p


def test_defaults_fill_a_minimal_config(tmp_path):
    cfg = load_study(_write(tmp_path, "name: x\n")).base
    assert isinstance(cfg, StudyConfig) and cfg.name == "x"
    assert cfg.folds == 5 and cfg.train.positives == 40 and "lv3d-rgbd" in cfg.systems


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
        load_study(p)
    assert str(p) in str(e.value) and key in str(e.value)


def test_overrides_are_parsed_as_yaml_and_checked(tmp_path):
    p = _write(tmp_path, "name: x\n")
    cfg = load_study(p, ["train.positives=8", "systems=[lv3d-rgbd, cnn-rgbd]", "lv3d.settings.size_principle=false",
                         "data.noise_overrides.clutter=2"]).base
    assert cfg.train.positives == 8 and cfg.systems == ("lv3d-rgbd", "cnn-rgbd")
    assert cfg.lv3d.settings == {"size_principle": False} and cfg.data.noise_overrides == {"clutter": 2}
    with pytest.raises(InputError, match="train.nope"):
        load_study(p, ["train.nope=1"])


def test_sweep_and_conditions_expand(tmp_path):
    p = _write(tmp_path, "sweep: {param: train.positives, values: [1, 4]}\n")
    conds = load_study(p).conditions
    assert list(conds) == ["positives=1", "positives=4"] and conds["positives=4"].train.positives == 4
    # either half of a sweep can be overridden alone; a sweep without its param is named as such
    conds = load_study(p, ["sweep.values=[2, 8]"]).conditions
    assert list(conds) == ["positives=2", "positives=8"] and conds["positives=8"].train.positives == 8
    conds = load_study(p, ["sweep.param=train.draws"]).conditions
    assert list(conds) == ["draws=1", "draws=4"] and conds["draws=4"].train.draws == 4
    with pytest.raises(InputError, match="sweep.valus"):
        load_study(p, ["sweep.valus=[2]"])
    with pytest.raises(InputError, match="sweep: must be"):
        load_study(_write(tmp_path, "name: x\n"), ["sweep.values=[2]"])
    p = _write(tmp_path, "conditions: {full: {}, no_refinement: {lv3d.refine: false}}\n")
    conds = load_study(p).conditions
    assert conds["full"].lv3d.refine is True and conds["no_refinement"].lv3d.refine is False
    p = _write(tmp_path, "conditions: {bad: {lv3d.refin: false}}\n")
    with pytest.raises(InputError, match="conditions.bad.*lv3d.refin"):
        load_study(p)


def test_shipped_study_configs_are_valid():
    from pathlib import Path

    root = Path(__file__).resolve().parents[2] / "experiments"
    configs = sorted(root.glob("*.yaml"))
    assert configs, "experiments/*.yaml missing"
    for p in configs:
        assert load_study(p).conditions
        assert p.read_text().startswith("#"), f"{p.name} lacks its header comment"
        assert yaml.safe_load(p.read_text())["name"]


@pytest.mark.parametrize("text, value", [("k=1e-3", 0.001), ("k=-2.5E+2", -250.0), ("k=0.008", 0.008), ("k=2", 2),
                                         ("k=true", True), ("k=e5", "e5")])
def test_override_values_read_as_yaml_and_exponents_as_numbers(text, value):
    key, got = parse_override(text)
    assert key == "k" and got == value and type(got) is type(value)


@pytest.mark.parametrize("text,key", [
    # every bad value of the issue: type, range and known names, each one line naming the file and the key
    ("lv3d: {settings: {time_limit: -5}}\n", "lv3d.settings.time_limit"),
    ("lv3d: {settings: {metarules: [part, pyramid_rule]}}\n", "lv3d.settings.metarules"),
    ("lv3d: {settings: {label_noise: false}}\n", "lv3d.settings.label_noise"),
    ("train: {multiclass: 'no'}\n", "train.multiclass"),
    ("data: {noise_overrides: {depth_sigma_k: -0.1}}\n", "data.noise_overrides.depth_sigma_k"),
    ("data: {noise_overrides: {clutter: -2}}\n", "data.noise_overrides.clutter"),
    ("baselines: {epochs: -1}\n", "baselines.epochs"),
    ("baselines: {threads: -4}\n", "baselines.threads"),
    ("data: {per_class: 1e8}\n", "data.per_class"),
    ("data: {per_class: 100000000}\n", "data.per_class"),
    ("baselines: {tree_cells: 0}\n", "baselines.tree_cells"),
    ("baselines: {tree_cells: 5}\n", "baselines.tree_cells"),
    ("baselines: {batch_size: 0}\n", "baselines.batch_size"),
    ("baselines: {image_size: 0}\n", "baselines.image_size"),
    ("lv3d: {refine: maybe}\n", "lv3d.refine"),
    ("baselines: {lr: fast}\n", "baselines.lr"),
    ("seed: -1\n", "seed"),
    ("folds: 2.5\n", "folds"),
    ("systems: []\n", "systems"),
    ("systems: [lv3d-rgb, lv3d-rgb]\n", "systems"),
    ("data: {classes: [cube]}\n", "data.classes"),
    ("data: 5\n", "data"),
    ("lv3d: {workers: 0}\n", "lv3d.workers"),
    ("stats: {pairs: [[lv3d-rgb, cnn-rgb], [lv3d-rgb]]}\n", "stats.pairs"),
    ("conditions: {'../../x': {}}\n", "condition name"),
    ("sweep: {param: data.noise_overrides.clutter, values: [1, 99]}\n", "data.noise_overrides.clutter"),
    ("sweep: {param: train.positives, values: []}\n", "sweep"),
])
def test_every_bad_value_is_one_line_naming_file_and_key(tmp_path, text, key):
    p = _write(tmp_path, text)
    with pytest.raises(InputError) as e:
        load_study(p)
    msg = str(e.value)
    assert str(p) in msg and key in msg and "\n" not in msg


def test_the_typed_config_keeps_the_cache_keys_of_the_yaml_form(tmp_path):
    """A result's key digests the config's YAML form: typed, it is the same mapping as before."""
    from lv3d.experiment.config import digest

    st = load_study(_write(tmp_path, "train: {negatives_per_positive: 1}\nlv3d: {settings: {sample_pos: 9}}\n"))
    d = st.base.to_dict()
    assert d["train"] == {"positives": 40, "negatives_per_positive": 1, "multiclass": True, "draws": 1}
    assert type(d["train"]["negatives_per_positive"]) is int and d["lv3d"]["settings"] == {"sample_pos": 9}
    assert digest(st.base) == digest(d) and isinstance(d["data"]["classes"], list)
