"""The learner's settings: the Python table names every option of mil.pl, and bad values stop before the search."""

import pytest

from lv3d.errors import InputError
from lv3d.learn.settings import METARULES, NOT_MIL, SETTINGS, check_settings


def test_the_table_names_every_option_and_metarule_of_mil():
    engine = pytest.importorskip("lv3d.learn.engine")
    options = {str(r["N"]) for r in engine.query("mil:default(O), functor(O, N, 1)")}
    assert options == set(SETTINGS) - NOT_MIL
    names = {str(r["N"]) for r in engine.query("mil:metarule(N, _, _, _)")}
    assert names == set(METARULES)


@pytest.mark.parametrize("settings, key", [
    ({"time_limit": -1}, "time_limit"), ({"time_limit": 0}, "time_limit"), ({"metarules": ["part", "nope"]}, "nope"),
    ({"label_noise": False}, "label_noise"), ({"size_principle": "no"}, "size_principle"),
    ({"combine": "max"}, "combine"), ({"thresholds": [0.3, 2]}, "thresholds"), ({"samples": 0}, "samples"),
    ({"max_clauses": 1.5}, "max_clauses"), ({"predicate_prior": [["regular"]]}, "predicate_prior"),
])
def test_bad_settings_are_one_line_errors(settings, key):
    with pytest.raises(InputError) as e:
        check_settings(settings, "study.yaml", prefix="lv3d.settings.")
    assert key in str(e.value) and str(e.value).startswith("study.yaml: ") and "\n" not in str(e.value)


def test_good_settings_pass_unchanged():
    s = {"time_limit": 20, "metarules": ["part", "part2"], "size_principle": False, "predicate_prior": [["regular", 0.5]]}
    assert check_settings(s) == s


def test_a_false_setting_reaches_prolog_as_false():
    from lv3d.learn.engine import settings_term

    assert settings_term({"size_principle": False, "samples": 3}) == "[size_principle(false),samples(3)]"
