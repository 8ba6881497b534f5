"""Synthetic RGB-D scenes of simple solids on a table, with exact ground truth, and data sets of them."""

from .dataset import make_dataset as make_dataset
from .frame import render_scene as render_scene
from .noise import PRESETS as PRESETS
from .noise import NoiseConfig as NoiseConfig
from .noise import noise_config as noise_config
from .solids import CLASSES as CLASSES

__all__ = ["CLASSES", "PRESETS", "NoiseConfig", "make_dataset", "noise_config", "render_scene"]
