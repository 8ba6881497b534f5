"""Fusion (rgbd): each depth object with its faces as depth has them, colour confirming them and adding only the
faces depth could not read.

Depth gives the object and its faces: one per plane, and its cylindrical faces (depth.py). Colour never cuts a
depth face and never adds a face on a plane depth has: on real frames printed packaging draws edges across every
face, and colour faces there are print, not faces. Colour's part is

- to confirm: a depth face whose outline lies on colour edges is a face both sensors see (provenance 'rgbd'), one
  that does not keeps provenance 'depth' (grounding then fits it to depth's edges where colour has none near,
  lv3d.describe.edge_field); a face depth infers beside the object from a hole in its readings
  (holes.unread_faces) is kept only where colour edges run along its outline (a sensor's occlusion shadow has none
  where it crosses the table);
- to add the faces depth has no reading of: holes along the object whose outline lies on colour edges
  (holes.add_hole_faces), or that extend a face the sensor read only part of, at a grazing angle;
- to refine: grounding fits every outline to the colour image's edges (lv3d.describe), which places corners more
  sharply than the planes' cells do.

Colour faces are not traced here (rgb.rgb_faces): matched to the planes, their outlines give no better figure on
the real dev frames than depth's outlines refined by grounding, fewer right side counts on rendered scenes, and cost
more than the depth stage itself.
"""

from __future__ import annotations

import time

import numpy as np

from ..rgbd import RGBD
from ..scene import Face
from .edges import channel_edges, channels, edge_distance, edge_support
from .depth.holes import HOLES, HoleSettings, UnreadFace, add_hole_faces
from .depth.quadrics import surface_fields
from .polygons import area, rasterize

# a depth outline lying on colour edges (within edges.edge_support's 2 px) for at least this fraction of its
# length is confirmed by colour: it is where the colour image has an edge too (fraction of the perimeter,
# scale-free; the same fraction admits an unread face, holes.add_hole_faces)
CONFIRMED_SUPPORT = 0.5


def colour_edge_distance(color: np.ndarray, box: tuple[int, int, int, int]) -> np.ndarray:
    """Distance (px, (v1 - v0, u1 - u0) float32) from each pixel of ``box`` = (u0, v0, u1, v1) to the nearest
    colour edge (edges.channel_edges of each channel of ``color`` (H, W, 3) uint8, combined)."""
    u0, v0, u1, v1 = box
    chans = channels(np.ascontiguousarray(color[v0:v1, u0:u1]))
    return edge_distance(np.maximum.reduce([channel_edges(c).edges for c in chans]))


def fused_faces(frame: RGBD, o, object_px: np.ndarray, box: tuple[int, int, int, int], unread: list[UnreadFace],
                timings: dict[str, float], holes: HoleSettings = HOLES) -> tuple[list[Face], list[tuple[int, int]]]:
    """The faces of depth object ``o`` (depth.DepthObjectResult) under rgbd, and the pairs of them (indices) that
    share an edge: its planes and its cylindrical faces (each where its cells gave an outline), 'rgbd' where colour
    edges confirm the outline (``CONFIRMED_SUPPORT``) and 'depth' where not, then the faces depth could not read
    (holes.add_hole_faces, from ``unread``, the faces depth infers from holes beside the object, and colour's).
    ``object_px``: the object's pixels in ``box`` = (u0, v0, u1, v1), the crop the colour edges are searched in;
    ``holes``: which regions without depth readings may be faces (holes.HoleSettings).
    The colour edges' time is added to ``timings['edges']``."""
    t0 = time.perf_counter()
    dist = colour_edge_distance(frame.color, box)
    timings["edges"] = timings.get("edges", 0.0) + (time.perf_counter() - t0) * 1e3
    off = np.array([box[0], box[1]], float)
    faces: list[Face] = []

    def add(poly: np.ndarray, **kw) -> int:
        sup = edge_support(poly - off, dist)
        faces.append(Face("", poly, "rgbd" if sup >= CONFIRMED_SUPPORT else "depth", edge_support=sup, **kw))
        return len(faces) - 1

    index = {j: add(poly, plane=p.plane, points=p.points, plane_rms_m=p.rms_m)
             for j, (p, poly) in enumerate(zip(o.planes, o.polygons)) if poly is not None}
    curved = {j: add(poly, points=c.points, plane_rms_m=c.rms_m, **surface_fields(c))
              for j, (c, poly) in enumerate(zip(o.curved, o.curved_polygons)) if poly is not None}
    pairs = {(index[a], index[b]) for a, b in o.adjacency if a in index and b in index}
    pairs |= {(index[i], curved[j]) for i, j in o.curved_adjacency if i in index and j in curved}
    masks = {i: rasterize(f.polygon - off, dist.shape) for i, f in enumerate(faces)}
    add_hole_faces(faces, pairs, list(masks), frame, box, object_px, dist, masks=masks, unread=unread,
                   min_unread_support=CONFIRMED_SUPPORT, settings=holes)  # appends to faces and pairs
    return faces, sorted({tuple(sorted(p)) for p in pairs})


def largest_first(faces: list[Face]) -> list[int]:
    """Indices of ``faces`` ordered by polygon area, largest first (ties by the first vertex's u): stable ids."""
    return sorted(range(len(faces)), key=lambda i: (-area(faces[i].polygon), float(faces[i].polygon[0, 0])))

