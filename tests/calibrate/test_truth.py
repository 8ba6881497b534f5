from types import SimpleNamespace

import numpy as np

from lv3d.calibrate.truth import truth_labels


def _scene():
    """A 40x40 image with two true faces: a vertical one on the left (id 0), a horizontal one on the right (id 1);
    perceived faces f1 and f2 lie on them, f3 on neither (a spurious face of the same object)."""
    mask = np.zeros((40, 40), np.int32)
    mask[5:35, 2:18] = 1   # true face 0
    mask[5:35, 22:38] = 2  # true face 1
    truth = {"support_plane": {"normal": [0.0, -1.0, 0.0]}, "adjacency": [{"faces": [0, 1], "dihedral_deg": 90.0}],
             "faces": [{"id": 0, "sides": 4, "plane": {"normal": [1.0, 0.0, -1.0], "offset": 0.5},
                        "polygon": [[2, 5], [17, 5], [17, 34], [2, 34]]},
                       {"id": 1, "sides": 4, "plane": {"normal": [0.0, -1.0, 0.0], "offset": 0.1},
                        "polygon": [[22, 30], [37, 30], [37, 34], [22, 34]]}]}

    def face(fid, u0, u1, v0=6, v1=34):
        return SimpleNamespace(face=SimpleNamespace(id=fid, polygon=np.array([[u0, v0], [u1, v0], [u1, v1], [u0, v1]],
                                                                             float)))

    results = [SimpleNamespace(faces=[face("f1", 3, 17), face("f2", 23, 37), face("f3", 19, 21, 0, 3)])]
    return results, mask, truth


def test_known_predicates_are_labelled_and_others_are_not():
    # the curved and regular-corner facts have no truth rule: no label, on a true face or a spurious one
    results, mask, truth = _scene()
    cands = [("vertical", ("f1",), 0.9, None), ("horizontal", ("f2",), 0.9, None),
             ("vertical", ("f2",), 0.9, None), ("vertical", ("f3",), 0.9, None),
             ("perpendicular", ("f1", "f2"), 0.9, None), ("adjacent", ("f1", "f2"), 0.9, None),
             ("cylindrical", ("f1",), 0.9, 0.04), ("circular", ("f3",), 0.9, 3.0),
             ("pentagonal_dihedral", ("f1", "f2"), 0.1, 90.0), ("hexagonal_dihedral", ("f1", "f3"), 0.1, 120.0),
             ("object", ("o1",), 0.9, None)]
    got = truth_labels(cands, results, mask, truth, SimpleNamespace(fx=50.0, fy=50.0, cx=20.0, cy=20.0))
    assert got == [True, True, False, False, True, True, None, None, None, None, None]
