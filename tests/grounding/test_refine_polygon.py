"""Polygon refinement: vertices move onto the image edges of a synthetic rendering with known corners."""

import numpy as np

import grounding

from grounding_synth import render_polygons


def test_vertices_move_onto_the_true_corners():
    truth = np.array([[212.3, 140.6], [430.8, 171.2], [401.1, 355.7], [190.4, 322.9]])
    field = grounding.edge_distance_field(render_polygons([truth], [(200, 170, 120)]))
    start = truth + np.random.default_rng(0).normal(0, 2.5, truth.shape)
    refined, cov, status = grounding.refine_polygon(start, field)
    before = np.linalg.norm(start - truth, axis=1)
    after = np.linalg.norm(refined - truth, axis=1)
    assert status == 0
    assert after.max() < 0.6, (before, after)
    assert after.mean() < 0.35 * before.mean()
    std = np.sqrt(np.linalg.eigvalsh(cov).max(-1))
    assert np.all(np.isfinite(std)) and np.all(std < 1.0) and np.all(std > 0.01)


def test_a_polygon_already_on_its_edges_stays_put():
    truth = np.array([[250.0, 200.0], [380.0, 210.0], [320.0, 330.0]])
    field = grounding.edge_distance_field(render_polygons([truth], [(90, 200, 90)]))
    refined, _, status = grounding.refine_polygon(truth, field)
    assert status == 0
    assert np.abs(refined - truth).max() < 0.6


def test_edge_field_is_a_signed_sub_pixel_distance():
    img = np.zeros((480, 640, 3), np.uint8)
    img[:, 320:] = 200  # a vertical step whose true position is u = 319.5
    field = grounding.edge_distance_field(img)
    assert field.shape == (480, 640) and field.dtype == np.float32
    row = field[240]
    assert row[300] < 0 < row[340]  # the bright side is positive
    assert abs(row[319] + 0.5) < 0.15 and abs(row[320] - 0.5) < 0.15
    assert abs(row[300] + 19.5) < 0.2
    assert row[0] == -30.0  # clipped far from any edge
