"""The whole path from one RGB-D frame to the facts the learner sees:
perception (lv3d.perception) -> grounding (lv3d.describe over the `grounding` package) -> facts.

Experiments and the CLI call :func:`scene_facts`; nothing below them imports this module.
"""

from __future__ import annotations

from .facts import SceneFacts
from .rgbd import RGBD


def scene_facts(frame: RGBD, scene_id: str, modality: str, *, refine: bool = True,
                confidences: bool = True, seed: int = 0) -> SceneFacts:
    """Facts of one frame as a system that sees ``modality`` ('rgb', 'depth', 'rgbd') gets them.

    ``refine=False`` skips the JAX refinement (perception's first guesses go straight to facts);
    ``confidences=False`` sets every emitted fact's confidence to 1 (the ablations of the study); ``seed``:
    perception's (lv3d.perception.perceive).
    """
    from .describe import describe
    from .perception import perceive

    scene = perceive(frame, modality, scene_id=scene_id, seed=seed)
    facts = describe(scene, frame, refine=refine)
    if not confidences:
        facts = SceneFacts(facts.scene, facts.modality,
                           [type(f)(f.pred, f.args, 1.0, f.value) for f in facts.facts], facts.target)
    return facts.for_modality(modality)
