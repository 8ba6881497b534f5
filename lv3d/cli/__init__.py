"""The command line, the top layer of lv3d: ``lv3d dataset|extract|mil|learn|experiment|demo|calibrate``.
Nothing in lv3d imports it."""

from .app import cli as cli, main as main
