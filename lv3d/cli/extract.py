"""``lv3d extract``: perceive one frame and write scene.json and overlay.png (and facts with --facts)."""

from __future__ import annotations

import json
from pathlib import Path

import click
import cv2

from .. import compile_cache
from ..errors import InputError
from ..output import check_out, replacing
from .depth_set import depth_set_option, depth_settings


@click.command()
@click.argument("color", type=click.Path(path_type=Path))
@click.option("--depth", type=click.Path(path_type=Path), default=None, help="16-bit depth image (PNG or TIFF).")
@click.option("--intrinsics", type=click.Path(path_type=Path), default=None,
              help="Intrinsics JSON (plain, a data set's meta.json, or the real-data layout with 'frames'); needed "
              "with depth only: colour alone works in pixels.")
@click.option("--depth-scale", type=click.FloatRange(0, 1, min_open=True), default=None,
              help="Metres per 16-bit depth unit (default: from the intrinsics file, else 0.001); float depth is "
              "read as metres.")
@click.option("--modality", type=click.Choice(["rgb", "depth", "rgbd"]), default="rgbd", show_default=True)
@click.option("--scene-id", default=None,
              help="Scene id, a Prolog atom like s000123 (default: the frame's name, made an atom: lv3d.frame_folder."
                   "scene_atom).")
@click.option("--out", "out_dir", type=click.Path(path_type=Path), required=True, help="Output folder.")
@click.option("--facts", is_flag=True, help="Also ground the scene and write facts.json and facts.pl.")
@click.option("--max-objects", type=click.IntRange(min=1), default=None,
              help="Describe at most this many objects found by depth, the largest (default 24); the output says "
              "how many were left out.")
@depth_set_option
def extract(color: Path, depth: Path | None, intrinsics: Path | None, depth_scale: float | None, modality: str,
            scene_id: str | None, out_dir: Path, facts: bool, max_objects: int | None,
            depth_set: tuple[str, ...]) -> None:
    """Find objects, faces and planes in one frame COLOR; write OUT/scene.json and OUT/overlay.png."""
    compile_cache.enable()  # an entry point: grounding's compiled programs are kept on disk
    from ..rgbd import load_frame, read_intrinsics
    from ..perception.overlay import draw_overlay
    from ..perception.perceive import perceive

    import re

    from ..frame_folder import scene_atom

    if scene_id is not None and not re.fullmatch(r"[a-z][a-zA-Z0-9_]*", scene_id):
        raise InputError("--scene-id", f"must be a Prolog atom like s000123 (a lower-case letter, then letters, "
                                       f"digits or _), got {scene_id!r}")
    if modality in ("depth", "rgbd") and depth is None:
        raise InputError("--depth", f"modality {modality!r} needs a depth image")
    if intrinsics is None and modality != "rgb":
        raise InputError("--intrinsics", f"modality {modality!r} needs an intrinsics JSON file")
    for image in (color, depth if modality != "rgb" else None):
        if image is not None and not Path(image).is_file():
            raise InputError(image, "image not found")
    settings = depth_settings(depth_set)
    inputs = (color, depth, intrinsics)
    check_out(out_dir, inputs)  # before any work: a file, a folder lv3d did not write or one holding an input
    frame_name = Path(color).stem.removesuffix("_rgb")
    scene_id = scene_id if scene_id is not None else scene_atom(frame_name)
    # colour alone reads no depth: without a file, load_frame fills in nominal intrinsics
    k, scale = read_intrinsics(intrinsics, frame_name) if intrinsics is not None else (None, 0.001)
    frame = load_frame(color, depth if modality != "rgb" else None, k,
                       depth_scale if depth_scale is not None else scale, name=frame_name)
    scene = perceive(frame, modality, scene_id=scene_id, max_objects=max_objects, depth_settings=settings)
    if not scene.objects:
        raise InputError(color, "no object found in this frame")
    facts_obj = None
    if facts:
        from ..describe import describe  # grounding (JAX) is imported only when asked for

        facts_obj = describe(scene, frame)
    _write(Path(out_dir), inputs, scene, draw_overlay(frame.color, scene), facts_obj)
    dropped = f" ({scene.dropped_objects} smaller objects left out by --max-objects)" if scene.dropped_objects else ""
    read_at = (f"; read at 1/{frame.scale} size, {frame.shape[1]}x{frame.shape[0]}: scene.json and overlay.png are in "
               "its pixels" if frame.scale > 1 else "")
    click.echo(f"{out_dir}: {len(scene.objects)} objects{dropped}, "
               f"{sum(len(o.faces) for o in scene.objects)} faces, target {scene.target().id}{read_at}")


def _write(out_dir: Path, inputs, scene, overlay_rgb, facts_obj) -> None:
    """Write everything into a temporary folder beside ``out_dir``, then move it into place
    (:func:`lv3d.output.replacing`), so that an error never leaves half the outputs behind."""
    with replacing(out_dir, inputs) as tmp:
        (tmp / "scene.json").write_text(json.dumps(scene.to_dict(), indent=1, default=float))
        if not cv2.imwrite(str(tmp / "overlay.png"), cv2.cvtColor(overlay_rgb, cv2.COLOR_RGB2BGR)):
            raise InputError(out_dir, "cannot write overlay.png")
        if facts_obj is not None:
            facts_obj.write(tmp)
