import cv2
import numpy as np

from lv3d.perception.polygons import area
from lv3d.perception.step_edge import smoothed_gradients, step_cut

# a cube's top and front faces traced as one outline: their shared edge runs from the outline's corner (40, 80)
# to a point in the middle of its right side, (160, 80), not to a corner
OUTLINE = np.array([[40.0, 30.0], [160.0, 30.0], [160.0, 170.0], [40.0, 170.0], [40.0, 80.0]])
TOP = np.array([[40.0, 30.0], [160.0, 30.0], [160.0, 80.0], [40.0, 80.0]])


def _grads(top_level: float, rest_level: float, noise: float = 4.0, ramp: float = 0.0, seed: int = 3):
    rng = np.random.default_rng(seed)
    img = np.full((200, 200), rest_level, np.float64)
    mask = np.zeros((200, 200), np.uint8)
    cv2.fillPoly(mask, [np.round(TOP).astype(np.int32)], 1)
    img[mask.astype(bool)] = top_level
    img += ramp * np.arange(200)[:, None] + rng.normal(0.0, noise, img.shape)
    chan = cv2.GaussianBlur(np.clip(img, 0, 255).astype(np.uint8), (3, 3), 0)
    return smoothed_gradients([chan, chan, chan])


def test_a_faint_step_under_noise_is_cut_from_a_corner_to_a_side():
    # 5 grey levels apart under sensor noise of 4 levels: no pixel tells them apart, the line's mean does
    parts = step_cut(OUTLINE, _grads(125.0, 120.0), min_area_px=150.0)
    assert parts is not None
    assert sorted(round(area(p) / 100) for p in parts) == sorted([round(area(TOP) / 100),
                                                                 round((area(OUTLINE) - area(TOP)) / 100)])


def test_noise_alone_or_a_smooth_shading_ramp_is_not_cut():
    assert step_cut(OUTLINE, _grads(120.0, 120.0), min_area_px=150.0) is None
    # shading that changes by 1.2 levels a pixel steps across every line, but as much on the shifted lines
    ramp = _grads(20.0, 20.0, ramp=1.2)
    assert step_cut(OUTLINE, ramp, min_area_px=150.0, rel_step=0.0) is not None
    assert step_cut(OUTLINE, ramp, min_area_px=150.0) is None
