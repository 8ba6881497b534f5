"""The perception benchmark's --set KNOB=VALUE: parsed as the study's --set is, bad knobs and values named."""

import pytest

from benchmarks.bench_perception import main


@pytest.mark.parametrize("bad, says", [("foo=1", "unknown noise knob 'foo'"), ("clutter", "expected key=value"),
                                        ("shadows=maybe", "knob 'shadows' takes true or false"),
                                        ("clutter=2.5", "knob 'clutter' takes a whole number"),
                                        ("preset=hard", "unknown noise knob 'preset'")])
def test_bad_overrides_stop_before_any_work(bad, says, capsys):
    with pytest.raises(SystemExit) as e:
        main(["--per-class", "1", "--presets", "clean", "--set", bad])
    assert e.value.code == 2 and says in capsys.readouterr().err


def test_the_curved_benchmark_takes_depth_settings_and_names_a_bad_one(capsys, monkeypatch):
    import benchmarks.bench_curved as curved

    assert curved.main(["--quick", "--set", "quadrics.nope=1"]) == 2
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1 and "quadrics.nope" in err and "unknown setting 'nope'" in err
    seen = []

    def perceive(frame, modality, scene_id="s000000", depth_settings=None):
        seen.append(depth_settings)
        raise RuntimeError("stop after the first frame")

    monkeypatch.setattr(curved, "perceive", perceive)
    with pytest.raises(RuntimeError):
        curved.main(["--quick", "--presets", "clean", "--set", "quadrics.max_step_deg=65.0"])
    assert seen[0].quadrics.max_step_deg == 65.0
