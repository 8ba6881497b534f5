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
