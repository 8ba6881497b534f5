"""``--depth-set KEY=VALUE``: depth settings other than the defaults for the commands that perceive frames
(``extract``, ``label``, ``learn fit|predict|explain``), the keys bench_real's ``--set`` and a study's
``lv3d.depth`` take: a field of lv3d.perception.depth.DepthSettings (``max_objects``) or of one of its parts
(``sensor.base_m``), docs/perception.md's settings table. The usual one is the noise model of a sensor other than
a Kinect or a RealSense (docs/perception.md, "The sensor's noise is a model, not a measurement")."""

from __future__ import annotations

import json
from pathlib import Path

import click

from ..errors import read_json

OPTION = "--depth-set"
# what ``lv3d learn fit`` writes beside a model's programs: the depth settings its facts were made with
MODEL_FILE = "depth_settings.json"

depth_set_option = click.option(
    OPTION, "depth_set", multiple=True, metavar="KEY=VALUE",
    help="A depth-stage setting other than its default, e.g. --depth-set sensor.base_m=0.006 (repeatable; "
         "the keys of docs/perception.md's settings table).")


def depth_overrides(texts, option: str = OPTION) -> dict:
    """The depth settings ``KEY=VALUE`` of each text (the value read as YAML; a later key over an earlier one) as
    one flat mapping, sorted: InputError naming ``option`` and the key for a text that is not KEY=VALUE, an
    unknown key or a value the settings refuse (lv3d.perception.depth.with_overrides)."""
    from ..experiment.config import check_depth_settings, parse_override

    given = dict(parse_override(t, option) for t in texts)
    return check_depth_settings(given, option, prefix="")


def depth_settings(texts, option: str = OPTION):
    """lv3d.perception.depth.DEFAULT with the settings of :func:`depth_overrides` applied."""
    from ..perception.depth import with_overrides

    return with_overrides(depth_overrides(texts, option))


def shown(depth: dict) -> str:
    """The settings as the command line gives them: ``sensor.base_m=0.006 stride=2``, or ``the defaults``."""
    return " ".join(f"{k}={json.dumps(v)}" for k, v in depth.items()) or "the defaults"


def save_with_model(model_dir: Path, depth: dict) -> None:
    """Write the depth settings a model's facts were made with into its folder (:data:`MODEL_FILE`)."""
    (Path(model_dir) / MODEL_FILE).write_text(json.dumps(depth, indent=1, sort_keys=True) + "\n")


def model_depth(model_dir: Path) -> dict | None:
    """The depth settings the model of ``model_dir`` learned from facts made with, None where it does not say (a
    model of ground-truth facts, or one written without the file); InputError naming the file where it is not a
    mapping of settings the depth stage takes."""
    path = Path(model_dir) / MODEL_FILE
    if not path.is_file():
        return None
    from ..experiment.config import check_depth_settings

    return check_depth_settings(read_json(path, MODEL_FILE), path, prefix="")
