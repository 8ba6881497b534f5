"""Rendered clean scenes for the learner's tests: facts from the ground truth (lv3d.truth_facts)."""

from lv3d.truth_facts import truth_facts

SHAPES = ("cube", "square_pyramid", "triangular_prism", "pentagonal_prism")


def rendered_facts(classes, seeds, tag, modality="rgbd"):
    """(scenes, labels): one clean 320x240 render per class and seed, facts from its ground truth."""
    from lv3d.render.frame import render_scene

    scenes, labels = [], []
    for c in classes:
        for s in seeds:
            frame, _ = render_scene(c, s, "clean", 320, 240)
            scenes.append(truth_facts(frame.meta, f"{tag}_{c}_{s}", modality))
            labels.append(c)
    return scenes, labels
