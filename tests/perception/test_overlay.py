import numpy as np

from lv3d.camera import Intrinsics
from lv3d.perception.overlay import draw_overlay
from lv3d.scene import Face, Scene, SceneObject


def _scene(provenance: str) -> Scene:
    square = np.array([[40, 30], [120, 30], [120, 100], [40, 100]], float)
    face = Face(id="o0_f0", polygon=square, provenance=provenance)
    obj = SceneObject(id="o0", faces=[face], pixel_count=5600, centroid_px=(80.0, 65.0))
    return Scene(id="s000000", modality=provenance, intrinsics=Intrinsics.nominal(160, 120), objects=[obj])


def test_outlines_and_labels_read_on_a_white_image():
    white = np.full((120, 160, 3), 255, np.uint8)
    for provenance in ("rgb", "depth", "rgbd"):
        img = draw_overlay(white, _scene(provenance))
        dark = img.max(axis=2) < 80
        # a dark halo along each side of the outline (white for rgb faces, which alone would vanish)
        for row in (30, 100):
            assert dark[row - 2:row + 3, 60:100].any(axis=0).all(), (provenance, row)
        for col in (40, 120):
            assert dark[45:85, col - 2:col + 3].any(axis=1).all(), (provenance, col)
        # and under the label at the centre
        assert dark[55:75, 60:90].sum() > 20, provenance
    # a white outline keeps its colour inside the halo
    img = draw_overlay(white, _scene("rgb"))
    assert (img[30, 60:100] > 200).all() and (img[28, 60:100].max(axis=1) < 80).all()
