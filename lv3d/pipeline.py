"""The whole path from one RGB-D frame to the facts the learner sees:
perception (lv3d.perception) -> grounding (lv3d.describe over the `grounding` package) -> facts.

Experiments and the CLI call :func:`scene_facts`; nothing below them imports this module.
"""

from __future__ import annotations

from collections.abc import Mapping

from .facts import SceneFacts
from .rgbd import RGBD


def scene_facts(frame: RGBD, scene_id: str, modality: str, *, refine: bool = True,
                confidences: bool = True, seed: int = 0, depth: Mapping[str, object] | None = None) -> SceneFacts:
    """Facts of one frame as a system that sees ``modality`` ('rgb', 'depth', 'rgbd') gets them.

    ``refine=False`` skips the JAX refinement (perception's first guesses go straight to facts);
    ``confidences=False`` sets every emitted fact's confidence to 1 (the ablations of the study); ``seed``:
    perception's (lv3d.perception.perceive); ``depth``: depth settings other than the defaults, ``{key: value}``
    (lv3d.perception.depth.with_overrides: ``{"sensor.base_m": 0.006}``).
    """
    from .describe import describe
    from .perception import perceive
    from .perception.depth import with_overrides

    settings = with_overrides(depth or {})
    scene = perceive(frame, modality, scene_id=scene_id, seed=seed, depth_settings=settings)
    facts = describe(scene, frame, refine=refine)
    if not confidences:
        facts = SceneFacts(facts.scene, facts.modality,
                           [type(f)(f.pred, f.args, 1.0, f.value) for f in facts.facts], facts.target)
    return facts.for_modality(modality)
