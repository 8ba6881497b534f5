import pytest

from lv3d.experiment import code_version as cv


def test_digest_follows_file_contents(tmp_path, monkeypatch):
    (tmp_path / "pkg").mkdir()
    src = tmp_path / "pkg" / "a.py"
    src.write_text("x = 1\n")
    (tmp_path / "pkg" / "notes.txt").write_text("ignored")
    monkeypatch.setattr(cv, "_ROOT", tmp_path)
    cv.source_digest.cache_clear()
    before = cv.source_digest(("pkg",))
    (tmp_path / "pkg" / "notes.txt").write_text("still ignored")
    cv.source_digest.cache_clear()
    assert cv.source_digest(("pkg",)) == before
    src.write_text("x = 2\n")
    cv.source_digest.cache_clear()
    assert cv.source_digest(("pkg",)) != before
    cv.source_digest.cache_clear()
    with pytest.raises(FileNotFoundError, match="missing"):
        cv.source_digest(("missing",))
    cv.source_digest.cache_clear()


def test_versions_of_this_checkout():
    facts, learner = cv.facts_version(), cv.learner_version()
    assert len(facts) == len(learner) == 12 and facts != learner


def test_a_data_file_named_as_a_part_counts(tmp_path, monkeypatch):
    (tmp_path / "pkg" / "data").mkdir(parents=True)
    maps = tmp_path / "pkg" / "data" / "maps.json"
    maps.write_text('{"a": 1}')
    monkeypatch.setattr(cv, "_ROOT", tmp_path)
    cv.source_digest.cache_clear()
    before = cv.source_digest(("pkg/data/maps.json",))
    maps.write_text('{"a": 2}')
    cv.source_digest.cache_clear()
    assert cv.source_digest(("pkg/data/maps.json",)) != before
    cv.source_digest.cache_clear()


def test_facts_follow_the_calibration_maps():
    # a refit of the shipped maps changes every confidence, so cached facts must not outlive it
    assert "lv3d/data/calibration.json" in cv.FACT_SOURCES and "lv3d/calibration.py" in cv.FACT_SOURCES
