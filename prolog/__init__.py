"""The learner's SWI-Prolog sources, shipped inside the installed package.

Find them with ``importlib.resources.files("prolog")`` (see :func:`source`), never by a path relative
to the checkout.
"""

from importlib.resources import as_file, files
from pathlib import Path


def source(name: str) -> Path:
    """Path of a shipped Prolog file, e.g. ``source("mil.pl")``."""
    ref = files(__name__).joinpath(name)
    with as_file(ref) as p:
        return Path(p)
