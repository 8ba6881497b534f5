"""``lv3d label FOLDER --out DIR``: a first objects.csv for a folder of frames that has none yet.

Every frame of FOLDER (the layout of docs/real_frames.md: ``<frame>_rgb.*``, its depth, ``intrinsics.json``) is
perceived with depth, and every object perception finds becomes one row of ``DIR/objects.csv``: the frame, the
object's number in it (1 = the largest), a pixel well inside the object (the point of its segment farthest from
the segment's edge, in the pixels of the frame's files) and an empty ``shape`` for you to fill in; ``notes`` says
what perception made of it (its faces by surface, its size). ``DIR/overlays/<frame>.png`` outlines each object and
writes its number at that pixel. Fill in each row's class, delete the rows of objects you do not want to label,
and put the file in FOLDER as its objects.csv; a row whose shape stays empty is left out, with a warning naming
its line. FOLDER itself is only read.

With ``--model MODEL`` (a model ``lv3d learn fit`` wrote, from frames labelled before), each object's class is
proposed too: the model's answer on the object's facts, as ``lv3d learn predict`` would give it on the file
(``notes`` adds the answer and its confidence); where the answer is no class the model holds a program for (no
object under the pixel, "unknown", or the class of the training object it resembles most, which it was not
asked to learn), the shape stays empty. Each frame is perceived once: a model of rgbd facts reads the frame as
rgbd perceives it, whose objects are depth's with their faces fused with colour's (so the rows are those depth
gives, and ``notes`` counts rgbd's faces; where depth finds no object, rgbd's are colour's); a model of colour alone
reads the frame perceived a second time, as colour sees it.
"""

from __future__ import annotations

import csv
import io
import sys
from collections import Counter
from pathlib import Path

import click
import cv2
import numpy as np
from tqdm import tqdm

from ..errors import InputError
from ..output import check_out, replacing
from .depth_set import depth_overrides, depth_set_option

COLUMNS = ("frame", "object", "u", "v", "shape", "partial", "stacked", "notes")
_PALETTE_BGR = ((0, 220, 255), (255, 160, 0), (80, 255, 80), (255, 80, 255), (80, 80, 255), (255, 255, 80))


def inner_pixel(mask: np.ndarray) -> tuple[int, int]:
    """(u, v) of the cell of ``mask`` (H, W bool) farthest from its edge (the first such cell in row order): a
    pixel well inside the object however it is shaped, where a centroid may lie outside a ring or a crescent."""
    from ..perception.distance import euclidean_distance

    padded = np.pad(mask, 1)  # the image's border is the segment's edge too
    dist = euclidean_distance(padded)[1:-1, 1:-1]
    v, u = np.unravel_index(int(np.argmax(dist)), dist.shape)
    return int(u), int(v)


def _count(n: int, what: str) -> str:
    return f"{n} {what}" if n == 1 else f"{n} {what}s"


def surfaces_note(obj) -> str:
    """What perception made of an object, for the notes column: its faces by surface and its size."""
    kinds = Counter(f.surface or "plane" for f in obj.faces)
    faces = " + ".join(_count(n, kind) for kind, n in sorted(kinds.items())) or "no face"
    return f"perceived: {faces}; {obj.pixel_count} px"


def proposed_rows(name: str, frame, scene) -> list[dict]:
    """One row per object of ``scene`` (perceived on ``frame``), its pixel in the frame's files: pixel (u, v) of a
    frame read at 1/s of its size is pixel (s u, s v) of the file (lv3d.rgbd.to_working)."""
    rows = []
    for k, obj in enumerate(scene.objects, start=1):
        if obj.mask is not None and obj.mask.any():
            u, v = inner_pixel(obj.mask)
        else:
            u, v = (int(round(c)) for c in obj.centroid_px)
        s = frame.scale
        rows.append({"frame": name, "object": k, "u": u * s, "v": v * s, "shape": "", "partial": "", "stacked": "",
                     "notes": surfaces_note(obj)})
    return rows


def model_answers(model, modality: str, frame, scene, rows: list[dict], seed: int, depth: dict | None = None
                  ) -> None:
    """Fill in each row's shape with ``model``'s answer on its object's facts and add the answer to its notes; a
    row whose answer is no class the model holds a program for keeps an empty shape. The facts are those lv3d
    learn predict reads: ``scene`` (the frame perceived as the model's modality sees it, the rows' objects among
    its objects) grounded (lv3d.object_facts.labelled_facts); for a model of colour alone, whose objects are not
    depth's, the frame is perceived as colour sees it (lv3d.object_facts.frame_facts, with ``seed`` and the depth
    settings ``depth``). ``modality``: the one the model's programs were learned from."""
    from ..object_facts import example_facts, example_id, frame_facts, labelled_facts

    if not rows:
        return
    s = frame.scale
    labels = [(r["object"], r["u"] // s, r["v"] // s) for r in rows]
    ff = labelled_facts(scene, frame, labels) if scene.modality == modality else \
        frame_facts(frame, scene.id, modality, labels, seed=seed, depth=depth)
    for r in rows:
        facts = example_facts(ff, r["object"], example_id(scene.id, r["object"]))
        label, conf = model.predict(facts) if facts.target is not None else ("unknown", 0.0)
        if label in model.programs:
            r["shape"] = label
        r["notes"] += f"; model: {label} {conf:.2f}"


def numbered_overlay(frame, scene, rows: list[dict]) -> np.ndarray:
    """(H, W, 3) uint8 BGR: the frame's colour (as read) with each object's segment outlined and its number
    written at its row's pixel."""
    out = cv2.cvtColor(frame.color, cv2.COLOR_RGB2BGR)
    for k, (obj, row) in enumerate(zip(scene.objects, rows)):
        colour = _PALETTE_BGR[k % len(_PALETTE_BGR)]
        if obj.mask is not None:
            contours, _ = cv2.findContours(obj.mask.astype(np.uint8), cv2.RETR_EXTERNAL, cv2.CHAIN_APPROX_SIMPLE)
            cv2.drawContours(out, contours, -1, (20, 20, 20), 3)
            cv2.drawContours(out, contours, -1, colour, 1, cv2.LINE_AA)
        u, v, label = row["u"] // frame.scale, row["v"] // frame.scale, str(row["object"])
        (w, h), base = cv2.getTextSize(label, cv2.FONT_HERSHEY_SIMPLEX, 0.5, 1)
        org = (int(u) - w // 2, int(v) + h // 2)
        cv2.rectangle(out, (org[0] - 2, org[1] - h - 2), (org[0] + w + 2, org[1] + base), (20, 20, 20), -1)
        cv2.putText(out, label, org, cv2.FONT_HERSHEY_SIMPLEX, 0.5, colour, 1, cv2.LINE_AA)
    return out


def frame_names(folder: Path) -> list[str]:
    """The frames of ``folder`` in natural order; an InputError naming the folder when it cannot be labelled."""
    from ..frame_folder import frame_files, natural_key

    return sorted(frame_files(folder, labelled=False), key=natural_key)


@click.command()
@click.argument("folder", type=click.Path(path_type=Path))
@click.option("--out", "out_dir", type=click.Path(path_type=Path), required=True,
              help="Output folder: objects.csv (the proposal) and overlays/<frame>.png.")
@click.option("--seed", type=click.IntRange(min=0), default=0, show_default=True,
              help="Perception's seed (its sample consensus).")
@click.option("--max-objects", type=click.IntRange(min=1), default=None,
              help="At most this many objects a frame, the largest (default 24).")
@click.option("--model", "model_dir", type=click.Path(path_type=Path), default=None,
              help="A model lv3d learn fit wrote: propose each object's class as its answer.")
@depth_set_option
def label(folder: Path, out_dir: Path, seed: int, max_objects: int | None, model_dir: Path | None,
          depth_set: tuple[str, ...]) -> None:
    """Propose objects.csv for the frames of FOLDER: a row per object depth perception finds, its class to fill in."""
    from .. import compile_cache
    from ..frame_folder import scene_atom
    from ..perception.depth import with_overrides
    from ..perception.perceive import perceive
    from ..rgbd import load_real

    names = frame_names(folder)
    depth = depth_overrides(depth_set)
    settings = with_overrides(depth)
    check_out(out_dir, (folder, model_dir))  # before any work
    model = modality = None
    if model_dir is not None:
        from .learn import load_model

        compile_cache.enable()  # an entry point that grounds: grounding's compiled programs are kept on disk
        model, learned = load_model(model_dir)
        modality = learned[0] if learned else "rgbd"
    rows, overlays, unread, empty = [], {}, [], []
    for name in tqdm(names, desc="frames", unit="frame", disable=None, leave=False):
        try:
            frame = load_real(folder, name)
        except InputError as e:  # one frame that cannot be read: said, and the others labelled
            unread.append(name)
            tqdm.write(f"lv3d: warning: {' '.join(str(e).split())} (frame {name!r} left out)", file=sys.stderr)
            continue
        # rgbd's objects are depth's (its faces fused with colour's), so a model of rgbd facts reads the same scene
        scene = perceive(frame, modality if modality in ("depth", "rgbd") else "depth", scene_id=scene_atom(name),
                         seed=seed, max_objects=max_objects, depth_settings=settings)
        mine = proposed_rows(name, frame, scene)
        if model is not None:
            model_answers(model, modality, frame, scene, mine, seed, depth)
        if not mine:
            empty.append(name)
        rows += mine
        overlays[name] = numbered_overlay(frame, scene, mine)
    text = io.StringIO()
    writer = csv.DictWriter(text, fieldnames=COLUMNS, lineterminator="\n")
    writer.writeheader()
    writer.writerows(rows)
    with replacing(out_dir, (folder, model_dir)) as tmp:
        (tmp / "objects.csv").write_text(text.getvalue())
        (tmp / "overlays").mkdir()
        for name, image in overlays.items():
            if not cv2.imwrite(str(tmp / "overlays" / f"{name}.png"), image):
                raise InputError(out_dir, f"cannot write overlays/{name}.png")
    left = "".join(f"; {_count(len(v), 'frame')} {what}: {', '.join(v[:5])}{' ...' if len(v) > 5 else ''}"
                   for v, what in ((empty, "with no object"), (unread, "not read")) if v)
    answered = f", {sum(bool(r['shape']) for r in rows)} with the class {model_dir} answers" if model else ""
    frames = _count(len(names) - len(unread), "frame")
    click.echo(f"{out_dir / 'objects.csv'}: {_count(len(rows), 'object')} in {frames}{answered}{left}. "
               f"Fill in each row's shape (delete the rows you do not want; {out_dir / 'overlays'} numbers the "
               f"objects), then put the file in {folder} as objects.csv.")
