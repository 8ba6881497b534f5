"""Shared setup of the grounding tests. JAX runs in its default float32 (as in production): the
tolerances are set for it. Helpers that make synthetic data live in grounding_synth.py."""

import pytest

import grounding


@pytest.fixture(scope="session", autouse=True)
def _cache():
    grounding.enable_cache()
