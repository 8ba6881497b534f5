"""How alike two objects' facts are: the answer of a multi-class model that no program proves.

When no class's program proves an object, its facts still say much: a single triangle face seen head-on proves
neither the tetrahedron's "a face with an acute neighbour" nor the prism's "a rectangle with a triangle
neighbour", and a near proof (absent facts counted at a low confidence) can only be made of programs whose facts need no other
face, such as "a conical face". So a model keeps a **profile** of each training object and answers such an
object with the class of the training object whose profile is nearest (docs/learner.md, "Classifying").

A profile is, per fact predicate, the highest confidence of its facts on the object's own faces (a face's
property, or a relation of two of its faces), with ``face_of`` and ``object`` left out (every object has them)
and ``horizontal`` / ``vertical`` too (how a solid happens to rest, not what it is: settings.EXCLUDED), and the
number of faces the object shows, as a share of ``FACES_FULL``. The distance of two profiles is the sum of
their absolute differences, a predicate one lacks counting 0 there.

Such an answer's confidence is :func:`closeness` (:class:`Resemblance`): how much nearer the object lies to the answered class's
training objects than to any other class's, a ratio of two distances and so free of their scale.
"""

from __future__ import annotations

from dataclasses import dataclass

from ..facts import SceneFacts
from .settings import EXCLUDED

# Faces (count): a profile's face count saturates here, as a share of it. A solid shows at most four faces at
# once from a table-top view (a box three, a prism or a pyramid up to four), so counts beyond are noise.
FACES_FULL = 4
FACES = "faces"  # the profile's key of the face count
# Predicates no profile holds: the structure every object has (face_of, object) and how a solid rests
NOT_PROFILED = ("face_of", *EXCLUDED)
# Confidence: an explanation names a fact as shown by an object at this confidence or more (the learner's
# default coverage threshold, mil's threshold option)
SHOWN = 0.5


@dataclass(frozen=True)
class Reference:
    """A training object as a model remembers it: its id, its class and its :func:`profile`."""

    object: str
    label: str
    profile: dict[str, float]


def profile(scene: SceneFacts) -> dict[str, float]:
    """The profile of ``scene``'s target object (module docstring); empty where the scene has no target."""
    target = scene.target
    faces = {f.args[1] for f in scene.facts if f.pred == "face_of" and len(f.args) == 2 and f.args[0] == target}
    out: dict[str, float] = {}
    for f in scene.facts:
        if f.pred in NOT_PROFILED or not f.args or not all(a in faces for a in f.args):
            continue
        out[f.pred] = max(out.get(f.pred, 0.0), float(f.conf))
    if target is not None:
        out[FACES] = min(len(faces), FACES_FULL) / FACES_FULL
    return out


def distance(a: dict[str, float], b: dict[str, float]) -> float:
    """The sum over every key of either profile of the absolute difference (an absent key: 0)."""
    return sum(abs(a.get(k, 0.0) - b.get(k, 0.0)) for k in a.keys() | b.keys())


def nearest(prof: dict[str, float], references: list[Reference]) -> tuple[Reference, float] | None:
    """The reference whose profile is nearest ``prof`` and its distance (ties: the first by class, then object);
    None without references."""
    if not references:
        return None
    return min(((r, distance(prof, r.profile)) for r in references), key=lambda rd: (rd[1], rd[0].label, rd[0].object))


def closeness(d_class: float, d_other: float | None) -> float:
    """The confidence of naming a class by resemblance: d_o / (d_c + d_o), where ``d_class`` (d_c) is the distance
    to the nearest training object of the class and ``d_other`` (d_o) to the nearest of any other class. 0.5 where
    the two are equal (the object lies as near one class as another), rising to 1 as the object comes to equal a
    training object of the class and no other's; 1 where no other class has a training object (``d_other`` None)."""
    if d_other is None:
        return 1.0
    return 0.5 if d_class + d_other == 0 else d_other / (d_class + d_other)


@dataclass(frozen=True)
class Resemblance:
    """A near answer's grounds: the training object nearest the answered object (``ref``, whose class is the
    answer) at ``distance``, and the nearest training object of another class (``other``, None where no other
    class has one) at ``other_distance`` (None with it)."""

    ref: Reference
    distance: float
    other: Reference | None
    other_distance: float | None

    @property
    def confidence(self) -> float:
        """:func:`closeness` of the two distances."""
        return closeness(self.distance, self.other_distance)


def resemble(prof: dict[str, float], references: list[Reference]) -> Resemblance | None:
    """The :class:`Resemblance` of an object of profile ``prof`` to the training objects; None without any."""
    found = nearest(prof, references)
    if found is None:
        return None
    ref, dist = found
    other = nearest(prof, [r for r in references if r.label != ref.label])
    return Resemblance(ref, dist, *(other if other is not None else (None, None)))


def contrast(prof: dict[str, float], ref: Reference) -> tuple[list[tuple[str, float, float]], list[tuple[str, float, float]]]:
    """What an object and the reference it resembles share and where they differ: (predicate, the object's
    confidence, the reference's) for the predicates both show (>= ``SHOWN``), and for those one of them shows,
    the largest difference first; the face count is left out of both."""
    keys = sorted((prof.keys() | ref.profile.keys()) - {FACES})
    pairs = [(k, prof.get(k, 0.0), ref.profile.get(k, 0.0)) for k in keys]
    shared = [p for p in pairs if p[1] >= SHOWN and p[2] >= SHOWN]
    differ = sorted((p for p in pairs if (p[1] >= SHOWN) != (p[2] >= SHOWN)), key=lambda p: -abs(p[1] - p[2]))
    return shared, differ
