"""Calibration maps (see _calibration.py). Empty until ``benchmarks/fit_calibration.py`` writes it."""

TABLE: dict = {}
