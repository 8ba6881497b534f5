"""experiments/README.md's study tables hold the figures of the committed reports (scripts/readme_tables.py)."""

import pytest


@pytest.fixture(scope="module")
def mod(load_script):
    return load_script("readme_tables")


def test_every_study_table_matches_its_results(mod):
    text = mod.README.read_text()
    assert mod.rewrite(text) == text, "stale tables: run scripts/readme_tables.py --write"


def test_a_changed_figure_is_rewritten_and_labels_are_kept(mod):
    text = mod.README.read_text()
    lines = text.split("\n")
    i = next(k for k, line in enumerate(lines) if line.startswith("| 0.016 |"))  # the depth sweep's last row
    cells = lines[i].split("|")
    cells[3] = " 1.0 / 2.0 "
    lines[i] = "|".join(cells)
    assert mod.rewrite("\n".join(lines)) == text


def test_the_top_level_seed_protocol_table_matches_its_results(mod):
    text = mod.TOP_README.read_text()
    assert mod.rewrite_top(text) == text, "stale README table: run scripts/readme_tables.py --write"


def test_the_top_level_table_picks_the_best_baseline_and_keeps_its_labels(mod):
    text = mod.TOP_README.read_text()
    lines = text.split("\n")
    i = next(k for k, line in enumerate(lines) if line.startswith("| best CNN"))
    label = lines[i].split("|")[1]
    lines[i] = f"|{label}| 1.0 / 2.0 (depth) | 3.0 / 4.0 (rgbd) |"
    assert mod.rewrite_top("\n".join(lines)) == text


def test_a_changed_replicate_figure_is_rewritten(mod):
    text = mod.README.read_text()
    lines = text.split("\n")
    i = next(k for k, line in enumerate(lines) if line.startswith("| 3 | realsense |"))
    cells = lines[i].split("|")
    cells[3] = " 1.0 / 2.0 "
    lines[i] = "|".join(cells)
    assert mod.rewrite("\n".join(lines)) == text


def test_a_changed_ten_class_replicate_figure_is_rewritten(mod):
    text = mod.README.read_text()
    lines = text.split("\n")
    start = lines.index("### Ten classes: replicates")
    i = next(k for k in range(start, len(lines)) if lines[k].startswith("| 2 | realsense |"))
    cells = lines[i].split("|")
    cells[3] = " 1.0 / 2.0 "
    lines[i] = "|".join(cells)
    assert mod.rewrite("\n".join(lines)) == text
