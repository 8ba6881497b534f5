import cv2
import numpy as np

from lv3d.perception.rgb.gaps import close_gaps
from lv3d.perception.rgb import rgb_faces
from lv3d.perception.rgb.step_edge import smoothed_gradients


def _grads(img: np.ndarray) -> np.ndarray:
    g = cv2.GaussianBlur(np.clip(img, 0, 255).astype(np.uint8), (3, 3), 0)
    return smoothed_gradients([g, g, g])


def _step_image(left: float, right: float, noise: float = 3.0, seed: int = 0) -> np.ndarray:
    """200 x 200 grey: ``left`` for u < 100, ``right`` beyond, with sensor noise."""
    img = np.full((200, 200), left)
    img[:, 100:] = right
    return img + np.random.default_rng(seed).normal(0.0, noise, img.shape)


# the edge u = 100 found in two pieces, v 20-80 and v 120-180 (LSD stopped where its contrast dipped), and a
# segment crossing the edge's line at v = 195 beyond its lower end
PIECES = np.array([[100.0, 20.0, 100.0, 80.0], [100.0, 120.0, 100.0, 180.0]])


def test_two_pieces_of_one_edge_are_joined_across_a_faint_stretch():
    img = _step_image(120.0, 150.0)
    img[80:120, 100:] = 126.0  # the gap: 6 grey levels of contrast under noise of 3
    out = close_gaps(PIECES, _grads(img))
    assert len(out) == 1
    v = sorted([out[0, 1], out[0, 3]])
    np.testing.assert_allclose(v, [20.0, 180.0], atol=0.5)
    np.testing.assert_allclose(out[0, [0, 2]], [100.0, 100.0], atol=0.5)


def test_no_step_in_the_gap_or_a_step_the_other_way_leaves_it_open():
    flat = _step_image(120.0, 150.0)
    flat[78:122, :] = 135.0  # no edge there at all: only noise
    assert len(close_gaps(PIECES, _grads(flat))) == 2
    flipped = _step_image(120.0, 150.0)
    flipped[78:122, 100:] = 90.0  # an edge, but darker on the right where the pieces are lighter
    assert len(close_gaps(PIECES, _grads(flipped))) == 2


def test_an_end_is_carried_to_the_segment_its_line_meets():
    img = _step_image(120.0, 150.0)
    img[150:, :] = 60.0  # a horizontal edge at v = 150 crossing the vertical one
    segs = np.array([[100.0, 20.0, 100.0, 110.0], [20.0, 150.0, 180.0, 150.0]])
    out = close_gaps(segs, _grads(img))
    vertical = out[np.argmax(np.abs(out[:, 3] - out[:, 1]))]
    np.testing.assert_allclose(max(vertical[1], vertical[3]), 150.0, atol=0.5)
    # without the step down there the end stays where it was
    img[110:150, 100:] = 120.0
    out = close_gaps(segs, _grads(img))
    vertical = out[np.argmax(np.abs(out[:, 3] - out[:, 1]))]
    np.testing.assert_allclose(max(vertical[1], vertical[3]), 110.0, atol=0.5)


def test_short_segments_and_empty_input_pass_through():
    g = _grads(_step_image(120.0, 150.0))
    assert close_gaps(np.zeros((0, 4)), g).shape == (0, 4)
    short = np.array([[100.0, 20.0, 100.0, 26.0], [100.0, 40.0, 100.0, 46.0]])
    np.testing.assert_array_equal(close_gaps(short, g), short)


def test_colour_alone_closes_a_square_whose_side_fades_into_the_background():
    # the lower part of the green square's right side borders a band of nearly its colour on a bluish floor: LSD
    # finds the side only down to the band, so without gap closing the graph has no cycle around the square
    square = np.array([150.0, 190.0, 110.0])
    for seed, darker in [(0, 8.0), (1, 10.0), (2, 12.0)]:
        img = np.tile(np.array([110.0, 100.0, 150.0]), (200, 200, 1))
        img[50:150, 50:150] = square
        img[95:150, 150:] = square - darker
        img = np.clip(img + np.random.default_rng(seed).normal(0.0, 3.0, img.shape), 0, 255).astype(np.uint8)
        faces = rgb_faces(img).faces
        assert [len(f.polygon) for f in faces] == [4]
        assert abs(faces[0].area_px - 100 * 100) < 0.02 * 100 * 100
