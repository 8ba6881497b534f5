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


# imported by fact sources, but only for error messages and size bounds, which never change a fact
NOT_FACTS = {"lv3d/errors.py", "lv3d/limits.py"}


def _imported_and_not_covered(sources: tuple[str, ...]) -> set[str]:
    """The lv3d modules the files of ``sources`` import (relative imports) that are not among them."""
    import ast

    covered = {p for part in sources for p in cv._files(part)}
    missing = set()
    for f in sorted(p for p in covered if p.suffix == ".py"):
        for node in ast.walk(ast.parse(f.read_text())):
            if not (isinstance(node, ast.ImportFrom) and node.level > 0):
                continue
            base = f.parents[node.level - 1]
            if node.module:
                mod = base.joinpath(*node.module.split("."))
                targets = [mod.with_suffix(".py"), mod / "__init__.py"]
            else:
                targets = [base / f"{a.name}.py" for a in node.names]
            missing |= {t.relative_to(cv._ROOT).as_posix() for t in targets if t.is_file() and t not in covered}
    return missing


def test_every_module_a_fact_source_imports_is_a_fact_source():
    # a helper the fact writer calls (lv3d/interval.py, lv3d/outline_ellipse.py) changes facts as surely as the
    # fact writer does; a module outside FACT_SOURCES would leave cached facts of its old code in place
    assert _imported_and_not_covered(cv.FACT_SOURCES) - NOT_FACTS == set()


def test_every_module_the_learner_imports_is_learning_code():
    # an lv3d fold result is kept while its facts and the learning code are the same: a module the learner reads
    # facts with (lv3d/facts.py) and not in LEARNING_SOURCES would keep results of its old code
    assert _imported_and_not_covered(cv.LEARNING_SOURCES) - NOT_FACTS == set()
    assert cv.learning_version() != cv.learner_version()
