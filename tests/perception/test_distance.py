"""The distance transform perception seeds its watersheds and reach tests with: exact and repeatable."""

import cv2
import numpy as np
from scipy import ndimage

from lv3d.perception.distance import euclidean_distance


def _speckled(shape, seed=0):
    return (np.random.default_rng(seed).random(shape) > 0.02).astype(np.uint8)


def test_equals_the_exact_euclidean_transform():
    for shape in [(60, 80), (240, 320)]:
        mask = _speckled(shape)
        np.testing.assert_array_equal(euclidean_distance(mask), ndimage.distance_transform_edt(mask).astype(np.float32))


def test_same_bits_on_every_call_with_one_thread():
    threads = cv2.getNumThreads()
    cv2.setNumThreads(1)  # the set-up where OpenCV's own transform changed in the last bit between calls
    try:
        mask = _speckled((60, 80), seed=1)
        first = euclidean_distance(mask)
        assert all(np.array_equal(first, euclidean_distance(mask)) for _ in range(20))
    finally:
        cv2.setNumThreads(threads)


def test_boolean_mask_and_zero_cells():
    mask = np.ones((9, 9), bool)
    mask[4, 4] = False
    d = euclidean_distance(mask)
    assert d.dtype == np.float32 and d[4, 4] == 0.0
    assert d[0, 0] == np.float32(np.sqrt(32.0))


def test_large_grids_use_the_exact_library_transform():
    mask = np.ones((800, 700), np.uint8)
    mask[0, 0] = 0
    d = euclidean_distance(mask)
    assert d[-1, -1] == np.float32(np.hypot(799, 699))
