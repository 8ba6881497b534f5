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


def _box(img: np.ndarray, x0: int, x1: int, top: int, mid: int, bottom: int, lean: int, colour=PURPLE) -> None:
    """A box drawn in perspective, each face a shade of one colour: its top (lightest), front and right side, the
    top and side leaning ``lean`` px to the right as they recede."""
    rise = mid - top
    for poly, shade in ((((x0 + lean, top), (x1 + lean, top), (x1, mid), (x0, mid)), 1.2),
                        (((x0, mid), (x1, mid), (x1, bottom), (x0, bottom)), 0.8),
                        (((x1, mid), (x1 + lean, top), (x1 + lean, bottom - rise), (x1, bottom)), 0.5)):
        cv2.fillPoly(img, [np.array(poly, np.int32)], tuple(int(c) for c in np.clip(np.array(colour) * shade, 0, 255)))


def _apart(res, u: float) -> bool:
    """Each object of ``res`` (two) lies on one side of the column ``u``."""
    sides = [{float(res.faces[i].polygon[:, 0].mean()) < u for i in group} for group in res.groups]
    return len(res.groups) == 2 and all(len(s) == 1 for s in sides) and sides[0] != sides[1]


def test_faces_of_two_solids_that_nearly_touch_are_two_objects():
    img = _floor(seed=2)
    # two boxes of one colour, 8 px of floor between them: the graph joins the two, the silhouettes part them
    _box(img, 30, 90, 50, 80, 150, 14)
    _box(img, 112, 172, 60, 90, 150, 14)
    res = rgb_faces(img)
    assert len(res.faces) == 6 and _apart(res, 108)


def test_solids_that_touch_are_two_objects_whatever_their_colours():
    # two boxes of one colour side by side, touching: one silhouette. The smaller one's top and front end on the
    # larger one's side, which runs on straight past them (T junctions): two objects, though of one colour
    img = _floor(seed=3)
    _box(img, 30, 100, 40, 70, 150, 14)
    _box(img, 114, 180, 80, 105, 160, 14)
    res = rgb_faces(img)
    assert len(res.faces) == 6 and _apart(res, 110)
    # the three faces of one box, each of its own colour, are one object
    img = _floor(seed=3)
    _box(img, 60, 140, 50, 85, 170, 16)
    cv2.fillPoly(img, [np.array([(60, 85), (140, 85), (140, 170), (60, 170)], np.int32)], (60, 130, 150))
    res = rgb_faces(img)
    assert len(res.faces) == 3 and res.groups == [[0, 1, 2]]
