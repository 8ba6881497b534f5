"""A picture of what perception found: face polygons over the colour image, filled with a colour per plane
orientation (rgb-only faces outlined in white), labelled with their ids. Outlines, corners and labels sit on
a dark halo, so they read on a white or light background as well as on a dark one."""

from __future__ import annotations

import cv2
import numpy as np

from ..scene import Scene

_PROVENANCE_BGR = {"rgb": (255, 255, 255), "depth": (255, 160, 0), "rgbd": (0, 220, 255)}
_HALO_BGR = (20, 20, 20)  # under every line, dot and label


def plane_colour(normal: np.ndarray) -> tuple[int, int, int]:
    """A BGR colour from a unit normal, so that parallel planes share a colour."""
    n = np.asarray(normal, float)
    return tuple(int(c) for c in np.clip((np.abs(n[::-1]) * 0.8 + 0.2) * 255, 0, 255))


def draw_overlay(color: np.ndarray, scene: Scene) -> np.ndarray:
    """(H, W, 3) uint8 RGB picture of ``scene`` over the frame's colour image ``color`` (H, W, 3) RGB."""
    bgr = cv2.cvtColor(color, cv2.COLOR_RGB2BGR)
    fill = bgr.copy()
    target = scene.target()
    for obj in scene.objects:
        for f in obj.faces:
            pts = np.round(f.polygon).astype(np.int32)
            if f.plane is not None:
                cv2.fillPoly(fill, [pts], plane_colour(f.plane.n))
    out = cv2.addWeighted(fill, 0.45, bgr, 0.55, 0)
    faces = [(f, 2 if target is not None and obj.id == target.id else 1) for obj in scene.objects for f in obj.faces]
    polys = [np.round(f.polygon).astype(np.int32) for f, _ in faces]
    # every line and dot is drawn over a dark halo, every label on a dark box: they read on light and dark images
    for (f, thick), pts in zip(faces, polys):
        cv2.polylines(out, [pts], True, _HALO_BGR, thick + 2)
    for (f, thick), pts in zip(faces, polys):
        cv2.polylines(out, [pts], True, _PROVENANCE_BGR[f.provenance], thick, cv2.LINE_AA)
    for pts in polys:
        for p in pts:
            cv2.circle(out, tuple(int(x) for x in p), 3, _HALO_BGR, -1)
            cv2.circle(out, tuple(int(x) for x in p), 2, (0, 0, 255), -1)
    for f, _ in faces:
        c = f.polygon.mean(axis=0)
        label = f.id.split("_", 1)[-1]
        org = (int(c[0]) - 14, int(c[1]) + 4)
        (w, h), base = cv2.getTextSize(label, cv2.FONT_HERSHEY_SIMPLEX, 0.33, 1)
        cv2.rectangle(out, (org[0] - 2, org[1] - h - 2), (org[0] + w + 1, org[1] + base), _HALO_BGR, -1)
        cv2.putText(out, label, org, cv2.FONT_HERSHEY_SIMPLEX, 0.33, (255, 255, 255), 1)
    return cv2.cvtColor(out, cv2.COLOR_BGR2RGB)
