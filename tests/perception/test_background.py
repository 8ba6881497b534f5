import numpy as np

from lv3d.perception.rgb.background import (background_faces, border_chromaticity, chromaticity, face_chromaticity,
                                        log_gradient, smooth_faces)
from lv3d.perception.polygons import rasterize
from lv3d.perception.rgb import rgb_faces

FLOOR = np.array([200.0, 140.0, 90.0])    # sandy floor
OBJECT = np.array([90.0, 160.0, 100.0])   # a green solid
SQUARE = np.array([[50.0, 50.0], [130.0, 50.0], [130.0, 130.0], [50.0, 130.0]])
SHADOW = np.array([[130.0, 70.0], [175.0, 90.0], [175.0, 150.0], [130.0, 130.0]])


def _scene(seed: int = 0, noise: float = 3.0) -> np.ndarray:
    """200 x 200: a green square on a sandy floor, its shadow (the floor at 45% brightness) to its right."""
    img = np.tile(FLOOR, (200, 200, 1))
    img[50:130, 50:130] = OBJECT
    u, v = np.meshgrid(np.arange(200), np.arange(200))
    in_shadow = (u >= 130) & (u < 175) & (v >= 70 + (u - 130) * 20 / 45) & (v < 130 + (u - 130) * 20 / 45)
    img[in_shadow] = 0.45 * FLOOR
    img = img + np.random.default_rng(seed).normal(0.0, noise, img.shape)
    return np.clip(img, 0, 255).astype(np.uint8)


def test_chromaticity_ignores_brightness():
    img = np.array([[FLOOR, 0.45 * FLOOR, OBJECT]], np.uint8)
    c = chromaticity(img)
    assert c.shape == (1, 3, 2)
    np.testing.assert_allclose(c[0, 0], c[0, 1], atol=0.01)
    assert np.hypot(*(c[0, 0] - c[0, 2])) > 0.1
    assert border_chromaticity(chromaticity(_scene())).shape[1] == 2


def test_a_shadow_and_a_floor_strip_are_background_the_object_is_not():
    strip = np.array([[20.0, 150.0], [120.0, 150.0], [120.0, 160.0], [20.0, 160.0]])
    chroma = chromaticity(_scene())
    hues = [face_chromaticity(p, chroma) for p in (SQUARE, SHADOW, strip)]
    assert background_faces(hues, chroma) == [False, True, True]


def test_colour_alone_drops_the_shadow_beside_a_solid():
    img = _scene()

    def shadow_found(faces):
        return any(abs(f.area_px - 2700) < 300 and f.polygon[:, 0].min() > 125 for f in faces)

    faces = rgb_faces(img).faces
    assert not shadow_found(faces)
    assert any(abs(f.area_px - 80 * 80) < 300 for f in faces)


def _grained() -> np.ndarray:
    """200 x 200: a plain square of the floor's own hue (a little brighter) on a floor with wood grain, and a
    shadow on that floor (its grain goes on under it)."""
    u, v = np.meshgrid(np.arange(200), np.arange(200))
    grain = 1.0 - 0.2 * (0.5 + 0.5 * np.sin(2 * np.pi * (v + 4 * np.sin(u / 9.0)) / 11.0))
    img = FLOOR[None, None, :] * grain[..., None]
    img[50:130, 50:130] = 1.1 * FLOOR
    in_shadow = (u >= 130) & (u < 175) & (v >= 70) & (v < 130)
    img[in_shadow] *= 0.45
    return np.clip(img, 0, 255).astype(np.uint8)


def test_a_plain_face_of_the_floors_hue_is_told_from_the_floor_by_its_texture():
    img = _grained()
    chroma = chromaticity(img)
    shadow = np.array([[130.0, 70.0], [175.0, 70.0], [175.0, 130.0], [130.0, 130.0]])
    polys = [SQUARE, shadow]
    hues = [face_chromaticity(p, chroma) for p in polys]
    assert background_faces(hues, chroma) == [True, True]  # both of the floor's hue
    smooth = smooth_faces(polys, hues, [True, True], chroma, log_gradient(img))
    assert smooth == [True, False]
    # a face not asked about is not judged
    assert smooth_faces(polys, hues, [False, False], chroma, log_gradient(img)) == [False, False]


def test_colour_alone_keeps_a_solid_of_the_floors_hue():
    square = rasterize(SQUARE, (200, 200))
    ious = [np.count_nonzero(square & m) / np.count_nonzero(square | m)
            for m in (rasterize(f.polygon, (200, 200)) for f in rgb_faces(_grained(), ).faces)]
    assert max(ious, default=0.0) >= 0.8
