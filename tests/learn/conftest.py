"""Fixtures of rendered clean scenes, made once per test run (see learn_scenes.py)."""

import pytest
from learn_scenes import SHAPES, rendered_facts


@pytest.fixture(scope="session")
def shape_train():
    """Five clean scenes per class (seeds 0-4): each class learns from its first and the others'."""
    return rendered_facts(SHAPES, range(5), "tr")


@pytest.fixture(scope="session")
def shape_heldout():
    """Fifteen held-out clean scenes per class (seeds 1000-1014)."""
    return rendered_facts(SHAPES, range(1000, 1015), "te")
