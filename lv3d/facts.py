"""The fact contract between grounding and the learner (docs/facts.md is its readable form).

A fact is a ground Prolog atom with a confidence in (0, 1]. Facts the image cannot support are
absent, never present with confidence 0. The learner sees nothing else.
"""

from __future__ import annotations

import json
import math
import re
from dataclasses import dataclass, field
from pathlib import Path

from .errors import InputError

SCHEMA = "lv3d.facts/4"

# predicate name -> (arity, modalities that may emit it). The same table drives the learner's
# body predicates, so all three systems share one vocabulary and differ only in what they see.
PREDICATES: dict[str, tuple[int, frozenset[str]]] = {
    # objects and faces
    "object": (1, frozenset({"rgb", "depth", "rgbd"})),
    "face_of": (2, frozenset({"rgb", "depth", "rgbd"})),
    # side count of a face's polygon (image polygon for rgb, plane boundary for depth)
    "triangle": (1, frozenset({"rgb", "depth", "rgbd"})),
    "quadrilateral": (1, frozenset({"rgb", "depth", "rgbd"})),
    "pentagon": (1, frozenset({"rgb", "depth", "rgbd"})),
    "hexagon": (1, frozenset({"rgb", "depth", "rgbd"})),
    # the face is a curved surface: the side of a cylinder (a can, a tin, a cup); needs depth
    "cylindrical": (1, frozenset({"depth", "rgbd"})),
    # the side of a cone, and a sphere's surface; needs depth
    "conical": (1, frozenset({"depth", "rgbd"})),
    "spherical": (1, frozenset({"depth", "rgbd"})),
    # a planar face bounded by a circle (an ellipse in the image): a can's lid, a cone's base
    "circular": (1, frozenset({"rgb", "depth", "rgbd"})),
    # colour alone: the face's outline in the image is an ellipse rather than a polygon (a lid, a ball)
    "elliptical": (1, frozenset({"rgb"})),
    # 2D shape of the image polygon
    "parallelogram": (1, frozenset({"rgb", "rgbd"})),
    # metric shape of the face on its plane (depth, rgbd); for colour alone, the same tests on the image
    # polygon: image-plane shape (lv3d.image_shape)
    "square": (1, frozenset({"rgb", "depth", "rgbd"})),
    "rectangle": (1, frozenset({"rgb", "depth", "rgbd"})),
    "regular": (1, frozenset({"rgb", "depth", "rgbd"})),
    # the kinds of corner of the image polygon (colour alone: lv3d.image_shape)
    "has_right_angle": (1, frozenset({"rgb"})),
    "has_acute_angle": (1, frozenset({"rgb"})),
    "has_obtuse_angle": (1, frozenset({"rgb"})),
    # orientation relative to the support plane (needs depth)
    "horizontal": (1, frozenset({"depth", "rgbd"})),
    "vertical": (1, frozenset({"depth", "rgbd"})),
    # pairs of faces of one object
    "adjacent": (2, frozenset({"rgb", "depth", "rgbd"})),
    "perpendicular": (2, frozenset({"depth", "rgbd"})),
    "parallel": (2, frozenset({"depth", "rgbd"})),
    "acute": (2, frozenset({"depth", "rgbd"})),
    "obtuse": (2, frozenset({"depth", "rgbd"})),
    "pentagonal_dihedral": (2, frozenset({"depth", "rgbd"})),
    "hexagonal_dihedral": (2, frozenset({"depth", "rgbd"})),
}

# two adjacent faces meet at the interior angle of a regular N-gon's corner, 180 - 360 / N deg (the sides of a
# regular N-gonal prism): N = 5, 108 deg; N = 6, 120 deg
REGULAR_CORNERS = {"pentagonal_dihedral": 5, "hexagonal_dihedral": 6}


def regular_corner_range(n: int) -> tuple[float, float]:
    """The interior dihedrals (degrees, low, high) nearer a regular ``n``-gon's corner angle than any other
    regular polygon's: those for which 360 / (180 - dihedral) rounds to ``n`` (5: 100.0-114.5, 6: 114.5-124.6)."""
    return 180.0 - 360.0 / (n - 0.5), 180.0 - 360.0 / (n + 0.5)


MODALITIES = ("rgb", "depth", "rgbd")
_ATOM = re.compile(r"^[a-z][a-zA-Z0-9_]*$")


@dataclass(frozen=True)
class Fact:
    """``pred(args...)`` holds with ``conf``; ``value`` is the measured quantity behind it, if any
    (degrees, metres, a side count), kept for inspection and calibration, not seen by the learner."""

    pred: str
    args: tuple[str, ...]
    conf: float
    value: float | None = None

    def __post_init__(self):
        if self.pred not in PREDICATES:
            raise ValueError(f"unknown predicate {self.pred!r}")
        arity = PREDICATES[self.pred][0]
        if len(self.args) != arity:
            raise ValueError(f"{self.pred} takes {arity} arguments, got {self.args}")
        for a in self.args:
            if not _ATOM.match(a):
                raise ValueError(f"{a!r} is not a Prolog atom of the form [a-z][a-zA-Z0-9_]*")
        if not (0.0 < self.conf <= 1.0) or math.isnan(self.conf):
            raise ValueError(f"confidence {self.conf} of {self.pred}{self.args} is not in (0, 1]")

    def atom(self) -> str:
        return f"{self.pred}({','.join(self.args)})"

    def to_prolog(self) -> str:
        return f"fact({self.atom()}, {self.conf:.4f})."

    def to_dict(self) -> dict:
        d = {"pred": self.pred, "args": list(self.args), "conf": round(self.conf, 6)}
        if self.value is not None:
            d["value"] = self.value
        return d


@dataclass
class SceneFacts:
    """All facts of one scene for one modality; ``target`` is the object the label speaks of."""

    scene: str
    modality: str
    facts: list[Fact] = field(default_factory=list)
    target: str | None = None

    def for_modality(self, modality: str) -> "SceneFacts":
        """The facts a system that sees ``modality`` may use."""
        if modality not in MODALITIES:
            raise InputError("--modality", f"unknown modality {modality!r}; choose one of {', '.join(MODALITIES)}")
        kept = [f for f in self.facts if modality in PREDICATES[f.pred][1]]
        return SceneFacts(self.scene, modality, kept, self.target)

    def objects(self) -> list[str]:
        return [f.args[0] for f in self.facts if f.pred == "object"]

    def to_json(self) -> dict:
        return {"schema": SCHEMA, "scene": self.scene, "modality": self.modality, "target": self.target,
                "facts": [f.to_dict() for f in self.facts]}

    @classmethod
    def from_json(cls, d: dict, where: str = "facts") -> "SceneFacts":
        if d.get("schema") != SCHEMA:
            raise InputError(where, f"schema is {d.get('schema')!r}, expected {SCHEMA!r}")
        try:
            facts = [Fact(f["pred"], tuple(f["args"]), float(f["conf"]), f.get("value")) for f in d["facts"]]
        except (KeyError, TypeError, ValueError) as e:
            raise InputError(where, f"malformed fact: {e}") from None
        return cls(d["scene"], d["modality"], facts, d.get("target"))

    def to_prolog(self) -> str:
        lines = [f"% {SCHEMA} scene={self.scene} modality={self.modality} target={self.target}"]
        lines += [f.to_prolog() for f in self.facts]
        return "\n".join(lines) + "\n"

    def write(self, out_dir: Path) -> None:
        out_dir = Path(out_dir)
        out_dir.mkdir(parents=True, exist_ok=True)
        (out_dir / "facts.json").write_text(json.dumps(self.to_json(), indent=1))
        (out_dir / "facts.pl").write_text(self.to_prolog())


def face_id(scene: str, obj: int, face: int) -> str:
    return f"{scene}_o{obj}_f{face}"


def object_id(scene: str, obj: int) -> str:
    return f"{scene}_o{obj}"
