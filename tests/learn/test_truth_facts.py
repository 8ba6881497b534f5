"""Facts from hand-made ground truth (docs/dataset.md layout)."""

import numpy as np
import pytest

from lv3d.errors import InputError
from lv3d.truth_facts import truth_facts

K = {"fx": 500.0, "fy": 500.0, "cx": 160.0, "cy": 120.0, "width": 320, "height": 240}


def project(points):
    p = np.asarray(points, float)
    return (np.stack([K["fx"] * p[:, 0] / p[:, 2] + K["cx"], K["fy"] * p[:, 1] / p[:, 2] + K["cy"]], 1)).tolist()


def cube_meta():
    """A 0.1 m cube 1 m in front of the camera, seen from above-front: top and front faces."""
    top = [[-0.05, -0.05, 0.95], [0.05, -0.05, 0.95], [0.05, -0.05, 1.05], [-0.05, -0.05, 1.05]]
    front = [[-0.05, -0.05, 0.95], [0.05, -0.05, 0.95], [0.05, 0.05, 0.95], [-0.05, 0.05, 0.95]]
    return {"intrinsics": K, "truth": {
        "class": "cube", "support_plane": {"normal": [0, -1, 0], "offset": 0.05},
        "faces": [{"id": 1, "sides": 4, "visible": True, "polygon": project(top),
                   "plane": {"normal": [0, -1, 0], "offset": -0.05}},
                  {"id": 2, "sides": 4, "visible": True, "polygon": project(front),
                   "plane": {"normal": [0, 0, -1], "offset": 0.95}}],
        "adjacency": [{"faces": [1, 2], "dihedral_deg": 90.0}]}}


def atoms(sf):
    return {f.atom() for f in sf.facts}


def test_cube_faces_are_squares_meeting_at_right_angles():
    a = atoms(truth_facts(cube_meta(), "s1", "rgbd"))
    assert {"object(s1_o1)", "face_of(s1_o1,s1_o1_f1)", "square(s1_o1_f1)", "square(s1_o1_f2)",
            "horizontal(s1_o1_f1)", "vertical(s1_o1_f2)", "adjacent(s1_o1_f1,s1_o1_f2)",
            "perpendicular(s1_o1_f2,s1_o1_f1)", "quadrilateral(s1_o1_f2)"} <= a
    assert not any(x.startswith(("acute", "obtuse", "triangle", "pentagonal_dihedral", "hexagonal_dihedral"))
                   for x in a)


def test_modality_keeps_only_its_predicates():
    rgb = atoms(truth_facts(cube_meta(), "s1", "rgb"))
    assert "quadrilateral(s1_o1_f1)" in rgb and "adjacent(s1_o1_f1,s1_o1_f2)" in rgb
    assert not any(x.startswith(("perpendicular", "horizontal")) for x in rgb)
    # colour alone: the image polygon's shape, a front face a square, a foreshortened top face not
    assert {"square(s1_o1_f2)", "has_right_angle(s1_o1_f2)", "has_acute_angle(s1_o1_f1)"} <= rgb
    assert "square(s1_o1_f1)" not in rgb and "has_right_angle(s1_o1_f1)" not in rgb
    assert not any(x.startswith("has_") for x in atoms(truth_facts(cube_meta(), "s1", "rgbd")))


def test_perturb_is_seeded_and_spoils_confidences():
    a = truth_facts(cube_meta(), "s1", "rgbd", perturb=0.6, seed=3)
    b = truth_facts(cube_meta(), "s1", "rgbd", perturb=0.6, seed=3)
    assert [f.to_prolog() for f in a.facts] == [f.to_prolog() for f in b.facts]
    assert any(f.conf < 1 for f in a.facts) and all(0 < f.conf <= 1 for f in a.facts)
    assert "object(s1_o1)" in atoms(a)


def test_malformed_truth_is_an_input_error():
    meta = cube_meta()
    del meta["truth"]["faces"][0]["plane"]
    with pytest.raises(InputError, match="ground truth is malformed"):
        truth_facts(meta, "s1", "rgbd")


def test_logical_vision_concepts_are_learnable_from_colour_alone():
    # 2D polygons facing the camera, as Logical Vision's scenes: a right-angled triangle and a regular
    # polygon, each told from the others by image-plane facts alone
    import numpy as np

    from lv3d.facts import Fact, SceneFacts
    from lv3d.image_shape import exact_image_shape
    from lv3d.learn import fit

    def scene(i, poly):
        o, f = f"p{i}_o1", f"p{i}_o1_f1"
        sides = {3: "triangle", 4: "quadrilateral", 5: "pentagon", 6: "hexagon"}[len(poly)]
        facts = [Fact("object", (o,), 1.0), Fact("face_of", (o, f), 1.0), Fact(sides, (f,), 1.0)]
        facts += [Fact(p, (f,), 1.0) for p in exact_image_shape(np.array(poly, float))]
        return SceneFacts(f"p{i}", "rgb", facts, o)

    def ngon(n, r=1.0):
        return [(r * np.cos(2 * np.pi * k / n), r * np.sin(2 * np.pi * k / n)) for k in range(n)]

    polys = {"right": [[(0, 0), (3, 0), (0, 2)], [(0, 0), (2, 0), (0, 2)], [(0, 0), (4, 0), (0, 1)]],
             "regular": [ngon(3), ngon(5), ngon(6)],
             "other": [[(0, 0), (4, 0), (1, 3)], [(0, 0), (3, 0), (4, 2), (0, 1)], [(0, 0), (5, 0), (1, 1)]]}
    scenes, labels = [], []
    for label, ps in polys.items():
        for p in ps:
            scenes.append(scene(len(scenes), p))
            labels.append(label)
    right = fit(scenes, labels, "right", settings={"disjunctions": 0})
    assert "has_right_angle(B)" in right.clauses[0] and right.score["tp"] == 3 and right.score["fp"] == 0
    regular = fit(scenes, labels, "regular", settings={"disjunctions": 0})
    assert "regular(B)" in regular.clauses[0] and regular.score["tp"] == 3 and regular.score["fp"] == 0


def test_elliptical_is_in_the_colour_vocabulary_only():
    from lv3d.learn.model import body_preds

    assert ("elliptical", 1) in body_preds("rgb")
    assert ("elliptical", 1) not in body_preds("depth") and ("elliptical", 1) not in body_preds("rgbd")


def test_sides_meeting_at_a_hexagons_corner_angle_are_hexagonal_dihedral():
    meta = cube_meta()
    meta["truth"]["adjacency"] = [{"faces": [1, 2], "dihedral_deg": 120.0}]
    a = atoms(truth_facts(meta, "s1", "depth"))
    assert {"obtuse(s1_o1_f1,s1_o1_f2)", "hexagonal_dihedral(s1_o1_f1,s1_o1_f2)",
            "hexagonal_dihedral(s1_o1_f2,s1_o1_f1)"} <= a
    assert not any(x.startswith("pentagonal_dihedral") for x in a)
    meta["truth"]["adjacency"] = [{"faces": [1, 2], "dihedral_deg": 108.0}]
    assert "pentagonal_dihedral(s1_o1_f1,s1_o1_f2)" in atoms(truth_facts(meta, "s1", "depth"))
