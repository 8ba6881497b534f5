"""The presets clean, mild, realsense and hard, which use none of the realism knobs (printed faces, multi-hue
solids, contacts, small tables), render as they always have whatever knobs exist beside them: colour, depth,
face mask and ground truth of fixed scenes are pinned (tests/render/pinned_frames.py: block sums and metadata,
within what differs from one CPU to another)."""

import numpy as np
import pytest

from tests.render.pinned_frames import PLAIN, differences, key, load, render_fingerprint


@pytest.fixture(scope="module")
def pins():
    return load()


@pytest.mark.parametrize("case", PLAIN, ids=[key(*c) for c in PLAIN])
def test_presets_without_realism_knobs_render_as_pinned(case, pins):
    got = render_fingerprint(*case)
    assert differences(got, pins[key(*case)]) == []
    truth = got["meta"]["truth"]
    # no contacts, and the target stands on the table
    assert truth["contacts"] == [] and truth["table_plane"] == truth["support_plane"]


def test_the_comparison_catches_what_a_change_to_the_renderer_moves(pins):
    # the tolerances take a few values one step apart, never a scene drawn anew or noise added to every pixel
    from lv3d.render import render_scene
    from tests.render.pinned_frames import fingerprint

    case = ("mild", "hexagonal_prism", 1, 160, 120)
    frame, faces = render_scene(case[1], case[2], case[0], case[3], case[4])
    pinned = pins[key(*case)]
    rng = np.random.default_rng(0)

    def flipped(a: np.ndarray, share: float) -> np.ndarray:
        out = a.astype(np.int16).ravel()
        idx = rng.choice(out.size, int(share * out.size), replace=False)
        out[idx] += rng.choice([-1, 1], len(idx))
        return np.clip(out, 0, 255).astype(np.uint8).reshape(a.shape)

    assert differences(fingerprint(flipped(frame.color, 1e-4), frame.depth, faces, frame.meta), pinned) == []
    assert differences(fingerprint(flipped(frame.color, 0.01), frame.depth, faces, frame.meta), pinned)
    noisy = np.where(frame.depth > 0, frame.depth + rng.normal(0, 0.001, frame.depth.shape), 0).astype(np.float32)
    assert differences(fingerprint(frame.color, noisy, faces, frame.meta), pinned)
    assert differences(render_fingerprint("mild", "hexagonal_prism", 2, 160, 120), pinned)
    assert differences(render_fingerprint("clean", "hexagonal_prism", 1, 160, 120), pinned)
