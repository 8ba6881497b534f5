"""Benchmarks that print figures beside their targets; run from the repository root as
``python -m benchmarks.NAME`` (``python -m benchmarks.run_all --quick`` runs them all: ``make bench``)."""
