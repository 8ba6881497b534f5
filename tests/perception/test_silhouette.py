import cv2
import numpy as np

from lv3d.perception.rgb import rgb_faces
from lv3d.perception.rgb.silhouette import foreground, regions_of, silhouette_segments, snap_to_edges

TAN = (170, 135, 90)
PURPLE = (120, 70, 140)


def _floor(seed: int = 0, h: int = 200, w: int = 240, noise: float = 4.0) -> np.ndarray:
    """A tan floor with wavy shading (the texture changes brightness, not hue) and sensor noise."""
    rng = np.random.default_rng(seed)
    v, u = np.mgrid[0:h, 0:w]
    shade = 1.0 + 0.15 * np.sin(u / 7.0 + 2.0 * np.sin(v / 11.0))
    img = np.array(TAN, float)[None, None] * shade[..., None] + rng.normal(0.0, noise, (h, w, 3))
    return np.clip(img, 0, 255).astype(np.uint8)


def _square(img: np.ndarray, x0: int, y0: int, x1: int, y1: int, colour=PURPLE, shade: float = 1.0) -> None:
    img[y0:y1, x0:x1] = np.clip(np.array(colour, float) * shade, 0, 255).astype(np.uint8)


def test_foreground_is_the_solid_not_the_floor_its_shadow_or_specks():
    img = _floor()
    _square(img, 80, 60, 160, 140)
    img[140:180, 90:200] = (img[140:180, 90:200] * 0.45).astype(np.uint8)  # a shadow: the floor darker, same hue
    img[20, 10:230:9] = PURPLE  # specks of another hue
    mask = foreground(img).astype(bool)
    truth = np.zeros(mask.shape, bool)
    truth[60:140, 80:160] = True
    # blur mixes the colours across the outline: the mask holds the square and reaches up to 2 px beyond it
    assert mask[truth].all() and not (mask & ~cv2.dilate(truth.astype(np.uint8), np.ones((5, 5))).astype(bool)).any()
    assert not mask[150:180, 100:200].any() and not mask[15:26].any()


def test_a_dark_face_against_its_shadow_keeps_its_outline():
    # the face is as dark as the shadow beside it, so the grey-level step across their border is faint
    img = _floor(seed=1)
    img[60:160, 60:200] = (img[60:160, 60:200] * 0.4).astype(np.uint8)  # shadow
    _square(img, 80, 80, 150, 150, shade=0.5)
    segs = silhouette_segments(foreground(img))
    right = [s for s in segs if abs(s[0] - s[2]) < 2 and 145 <= s[0] <= 151]
    assert right, segs
    assert abs(right[0][1] - right[0][3]) > 55  # nearly the whole 70 px side


def test_sides_along_the_frame_are_left_out():
    mask = np.zeros((100, 120), np.uint8)
    mask[30:100, 40:90] = 1  # cut off by the bottom of the frame
    segs = silhouette_segments(mask)
    assert len(segs) == 3
    assert not any(min(s[1], s[3]) >= 97 for s in segs)
    assert len(silhouette_segments(np.zeros((50, 50), np.uint8))) == 0


def test_snap_moves_a_side_onto_the_edge():
    grad = np.zeros((100, 100), np.float32)
    grad[:, 50] = 10.0  # the edge runs down u = 50
    out = snap_to_edges(np.array([[48.5, 10.0, 48.5, 90.0], [70.0, 10.0, 70.0, 90.0]]), grad)
    np.testing.assert_allclose(out[0], [50.0, 10.0, 50.0, 90.0], atol=1e-6)
    assert abs(out[1, 0] - 70.0) <= 2.5  # no edge within reach: it stays within the reach
    assert snap_to_edges(np.zeros((0, 4)), grad).shape == (0, 4)


def test_regions_of_names_the_region_holding_most_of_each_polygon():
    mask = np.zeros((100, 200), np.uint8)
    mask[20:80, 20:80] = 1
    mask[20:80, 120:180] = 1
    sq = lambda x0, y0, x1, y1: np.array([[x0, y0], [x1, y0], [x1, y1], [x0, y1]], float)  # noqa: E731
    a, b, c, d = regions_of([sq(25, 25, 75, 75), sq(125, 25, 170, 70), sq(85, 30, 115, 70), sq(50, 30, 100, 70)],
                            mask)
    assert a > 0 and b > 0 and a != b
    assert c == 0 and d == a


def test_faces_of_two_solids_that_nearly_touch_are_two_objects():
    img = _floor(seed=2)
    # two boxes of two faces each (top lighter than front), 8 px of floor between them: the graph joins the two
    _square(img, 40, 50, 110, 90, shade=1.2)
    _square(img, 40, 90, 110, 150, shade=0.7)
    _square(img, 118, 60, 190, 100, shade=1.2)  # of one colour: their hue does not part them
    _square(img, 118, 100, 190, 150, shade=0.7)
    res = rgb_faces(img)
    assert len(res.faces) == 4 and len(res.groups) == 2
    for group in res.groups:
        xs = [float(res.faces[i].polygon[:, 0].mean()) for i in group]
        assert all(x < 114 for x in xs) or all(x > 114 for x in xs)


def test_solids_of_two_colours_that_touch_are_two_objects():
    img = _floor(seed=3)
    # a purple box and a teal box side by side, touching: one region, but two colours
    _square(img, 40, 50, 110, 90, shade=1.2)
    _square(img, 40, 90, 110, 150, shade=0.7)
    _square(img, 110, 60, 190, 100, colour=(60, 130, 150), shade=1.2)
    _square(img, 110, 100, 190, 150, colour=(60, 130, 150), shade=0.7)
    res = rgb_faces(img)
    assert len(res.faces) == 4 and len(res.groups) == 2
    for group in res.groups:
        xs = [float(res.faces[i].polygon[:, 0].mean()) for i in group]
        assert all(x < 110 for x in xs) or all(x > 110 for x in xs)
