"""Colour alone groups faces into solids by the edges they share and the silhouettes they lie in, never by hue."""

import cv2
import numpy as np

from lv3d.perception.polygons import rasterize
from lv3d.perception.rgb import rgb_faces
from lv3d.perception.rgb.solids import group_solids, one_face_parts
from lv3d.render import noise_config, render_scene

from .conftest import mask_iou

SHAPE = (240, 320)


def _target_groups(res, faces_mask: np.ndarray, min_px: int = 200) -> list[int | None]:
    """For each visible face of the rendered target (``faces_mask``: face id + 1 per pixel, at least ``min_px``
    pixels), the group of ``res`` holding the found face that matches it (IoU >= 0.5), or None."""
    out = []
    for fid in np.unique(faces_mask):
        truth = faces_mask == fid
        if fid == 0 or np.count_nonzero(truth) < min_px:
            continue
        best, group = 0.0, None
        for g, idx in enumerate(res.groups):
            for i in idx:
                iou = mask_iou(rasterize(res.faces[i].polygon, truth.shape), truth)
                if iou > best:
                    best, group = iou, g
        out.append(group if best >= 0.5 else None)
    return out


def test_a_rendered_cube_with_faces_of_three_hues_is_one_object():
    frame, faces_mask = render_scene("cube", 1000, noise=noise_config("clean", face_hues=1.0))
    hues = []
    for fid in np.unique(faces_mask)[1:]:
        rgb = np.median(frame.color[faces_mask == fid], axis=0)
        hues.append(rgb / rgb.sum())
    assert len(hues) == 3 and min(np.hypot(*(a - b)[:2]) for a in hues for b in hues if a is not b) > 0.1
    groups = _target_groups(rgb_faces(frame.color), faces_mask)
    assert len(groups) == 3 and None not in groups and len(set(groups)) == 1


def test_a_rendered_single_hue_pentagonal_prism_is_one_object():
    frame, faces_mask = render_scene("pentagonal_prism", 1000, noise=noise_config("clean"))
    groups = _target_groups(rgb_faces(frame.color), faces_mask)
    assert len(groups) >= 3 and None not in groups and len(set(groups)) == 1


def _prism(black_level: float = 20.0, noise: float = 3.0) -> tuple[np.ndarray, list[np.ndarray]]:
    """An upright pentagonal prism of one blue, drawn from above the front: its top and three side faces, shaded
    from bright to near black (on the darkest face a camera's black level, ``black_level``, is most of the signal,
    and its hue drifts towards grey)."""
    h, w = SHAPE
    img = np.full((h, w, 3), (200.0, 190.0, 170.0))
    ang = np.radians(np.arange(5) * 72 + 18)
    top = np.stack([160 + 70 * np.cos(ang), 80 - 30 * np.sin(ang)], 1)
    chain = [2, 3, 4, 0]  # from the leftmost vertex round the front to the rightmost
    sides = [np.array([top[a], top[b], top[b] + (0, 100), top[a] + (0, 100)]) for a, b in zip(chain, chain[1:])]
    blue = np.array((40.0, 110.0, 200.0))
    for poly, shade in zip([top] + sides, (1.0, 0.95, 0.75, 0.05)):
        cv2.fillPoly(img, [np.round(poly).astype(np.int32)], tuple(blue * shade + black_level))
    img += np.random.default_rng(0).normal(0.0, noise, img.shape)
    return np.clip(img, 0, 255).astype(np.uint8), [top] + sides


def test_the_darkest_face_of_a_shaded_prism_stays_with_its_solid():
    img, faces = _prism()
    res = rgb_faces(img)
    found = [max(range(len(res.faces)), key=lambda i: mask_iou(rasterize(res.faces[i].polygon, SHAPE),
                                                               rasterize(f, SHAPE))) for f in faces]
    assert all(mask_iou(rasterize(res.faces[i].polygon, SHAPE), rasterize(f, SHAPE)) > 0.8
               for i, f in zip(found, faces))
    # the darkest face's chromaticity is far from its neighbour's: a rule by hue would part them
    chroma = [np.median(img[rasterize(f, SHAPE)].astype(float), axis=0) for f in faces]
    chroma = [c / c.sum() for c in chroma]
    assert np.hypot(*(chroma[3] - chroma[2])[:2]) > 0.1
    assert len(res.groups) == 1 and sorted(res.groups[0]) == sorted(found)


def _square(x0, y0, x1, y1):
    return np.array([(x0, y0), (x1, y0), (x1, y1), (x0, y1)], float)


def test_a_side_ending_on_another_outline_parts_two_solids():
    # a box's front and top (a Y junction where they meet the silhouette: both outlines turn) and, behind it, a
    # face whose sides end on the top's outline, which runs on straight past them (T junctions)
    front = _square(100, 120, 200, 200)
    top = np.array([(120, 90), (220, 90), (200, 120), (100, 120)], float)
    behind = np.array([(140, 40), (190, 40), (185, 90), (145, 90)], float)
    pairs = [(0, 1), (1, 2)]
    assert sorted(group_solids([front, top, behind], pairs, SHAPE)) == [[0, 1], [2]]
    # faces on two silhouettes are two solids, whatever their edges; a face that may lie in any (region 0) joins
    assert sorted(group_solids([front, top, behind], pairs, SHAPE, region=[1, 2, 2])) == [[0], [1], [2]]
    assert sorted(group_solids([front, top, behind], pairs, SHAPE, region=[1, 0, 2])) == [[0, 1], [2]]
    # the same face behind, drawn as the box's back: its sides run on from the top's corners (Y junctions)
    back = np.array([(120, 40), (220, 40), (220, 90), (120, 90)], float)
    assert sorted(group_solids([front, top, back], pairs, SHAPE)) == [[0, 1, 2]]


def test_a_face_split_by_a_printed_line_joins_its_neighbour_and_is_one_face():
    # the front of a box printed with a band: the band's lines end on the front's sides, mid-side of the top's
    # outline; once the front's parts are one, the top shares a whole side with it
    top = np.array([(120, 60), (230, 60), (210, 100), (100, 100)], float)
    upper, band, lower = _square(100, 100, 210, 130), _square(100, 130, 210, 150), _square(100, 150, 210, 200)
    side = np.array([(210, 100), (230, 60), (230, 160), (210, 200)], float)
    polys = [top, upper, band, lower, side]
    pairs = [(0, 1), (1, 2), (2, 3), (0, 4), (1, 4), (2, 4), (3, 4)]
    groups = group_solids(polys, pairs, SHAPE)
    assert groups == [[0, 1, 2, 3, 4]]
    assert sorted(one_face_parts(polys, groups, pairs, SHAPE)) == [[0], [1, 2, 3], [4]]
    # unless the lines are cuts made where the image steps (a cube's top and front seen with its sides edge-on)
    assert sorted(one_face_parts(polys, groups, pairs, SHAPE, apart={(1, 2), (2, 3)})) == [[0], [1], [2], [3], [4]]


def test_a_label_inside_a_face_is_one_face_with_the_parts_around_it():
    label = _square(130, 110, 170, 140)
    ring = [np.array(p, float) for p in ([(100, 100), (200, 100), (170, 110), (130, 110)],
                                         [(200, 100), (200, 150), (170, 140), (170, 110)],
                                         [(200, 150), (100, 150), (130, 140), (170, 140)],
                                         [(100, 150), (100, 100), (130, 110), (130, 140)])]
    polys = [label] + ring
    pairs = [(0, 1), (0, 2), (0, 3), (0, 4), (1, 2), (2, 3), (3, 4), (1, 4)]
    assert one_face_parts(polys, [[0, 1, 2, 3, 4]], pairs, SHAPE) == [[0, 1, 2, 3, 4]]
