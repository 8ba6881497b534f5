"""Real frames in ../shared/data/real: pcl-kinect (its README says what must be found) and osd-learn (masks)."""

import numpy as np
import pytest

from lv3d.perception import perceive
from lv3d.plane import dihedral_deg
from lv3d.rgbd import load_real
from tests.conftest import REAL_DIR

pytestmark = pytest.mark.real


def _tilt(face, support):
    """Angle (degrees) between a face's plane and the support plane."""
    return float(np.degrees(np.arccos(np.clip(abs(face.plane.n @ support.n), 0, 1))))


def _object_at(scene, u_range, v_range):
    for o in scene.objects:
        u, v = o.centroid_px
        if u_range[0] <= u <= u_range[1] and v_range[0] <= v <= v_range[1]:
            return o
    return None


def test_desk_box_is_its_own_object_with_a_top_and_a_side(real_dir):
    frame = load_real(real_dir, "frame_20121214T142255.814212")
    scene = perceive(frame, "depth")
    assert scene.support_plane is not None and -scene.support_plane.normal[1] > 0.5  # the desk faces up
    box = _object_at(scene, (380, 510), (170, 320))  # the small white box right of the laptop
    laptop = _object_at(scene, (130, 370), (140, 320))
    assert box is not None and laptop is not None and box.id != laptop.id
    tilts = [_tilt(f, scene.support_plane) for f in box.faces]
    assert min(tilts) < 8.0                      # top face parallel to the desk
    assert any(abs(t - 90) < 8.0 for t in tilts)  # a side face perpendicular to it


def test_milk_carton_body_faces_are_square_to_each_other_and_the_floor(real_dir):
    frame = load_real(real_dir, "milk_cartoon_all_small_clorox")
    scene = perceive(frame, "depth")
    sp = scene.support_plane
    assert sp is not None and -sp.normal[1] > 0.5
    carton = _object_at(scene, (230, 330), (80, 230))
    assert carton is not None
    others = [o for o in scene.objects if o.id != carton.id and o.pixel_count > 5000]
    assert len(others) >= 2  # the two bottles are objects of their own
    body = [f for f in carton.faces if abs(_tilt(f, sp) - 90) < 8.0]
    assert len(body) >= 2
    centroid = np.concatenate([f.points for f in carton.faces]).mean(axis=0)
    out = {f.id: (f.plane.n if f.plane.n @ (f.points.mean(0) - centroid) > 0 else -f.plane.n) for f in body}
    pairs = [(a, b) for a, b in carton.adjacency if a in out and b in out]
    assert pairs
    for a, b in pairs:
        assert abs(dihedral_deg(out[a], out[b]) - 90) < 8.0


@pytest.mark.parametrize("name", ["frame_20121214T142255.814212", "milk_cartoon_all_small_clorox"])
def test_rgbd_on_real_frames_fuses_some_faces(real_dir, name):
    scene = perceive(load_real(real_dir, name), "rgbd")
    provenances = {f.provenance for o in scene.objects for f in o.faces}
    assert "rgbd" in provenances


OSD = REAL_DIR.parent / "osd-learn"


def _osd_objects(frame_names):
    """(ground-truth objects, those matched at IoU >= 0.5 by a perceived object's segment, labelled objects whose
    segment also holds a fifth of another's mask) over the named osd-learn frames, depth alone."""
    import cv2

    from lv3d.rgbd import load_real

    if not OSD.is_dir():
        pytest.skip(f"osd-learn frames not found at {OSD}")
    n = matched = merged = 0
    for name in frame_names:
        frame = load_real(OSD, name)
        lab = cv2.imread(str(OSD / f"{name}_label.png"), cv2.IMREAD_UNCHANGED)
        masks = [o.mask for o in perceive(frame, "depth").objects]
        gts = [lab == g for g in np.unique(lab) if g]
        for gt in gts:
            n += 1
            ious = [np.count_nonzero(gt & m) / np.count_nonzero(gt | m) for m in masks]
            matched += bool(ious) and max(ious) >= 0.5
            holder = [m for m in masks if np.count_nonzero(gt & m) >= 0.5 * np.count_nonzero(gt)]
            merged += any(np.count_nonzero(o & holder[0]) >= 0.2 * np.count_nonzero(o) for o in gts if o is not gt) \
                if holder else 0
    return n, matched, merged


def test_stacked_and_touching_boxes_on_real_kinect_frames_come_apart():
    # osd-learn's stacked boxes (frames 17-24) and occluded boxes (25-32): a box on a box and boxes side by side
    n, matched, merged = _osd_objects([f"learn{i}" for i in range(17, 33)])
    assert matched >= 0.85 * n
    assert merged <= 0.15 * n
