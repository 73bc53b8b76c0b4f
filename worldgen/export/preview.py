"""preview.png: a top-down picture of a world, drawn from its world.json alone.

``render(meta)`` returns PNG bytes; ``draw(meta)`` the Pillow image. Only the
metadata is read (entities, doors, dynamic obstacles, tasks, metrics), never the
scene, so ``worldgen preview WORLD_DIR`` redraws it from a folder a user received.
``files`` is ignored on purpose, and preview.png is not listed there: it is a
derived picture, and its bytes depend on Pillow's version (its zlib and its
font rasteriser), which world.json's bytes must not; nor does the in-memory
``World.metadata`` pay for drawing it. ``worldgen check`` leaves it alone;
``worldgen preview`` redraws it from world.json whenever wanted.

What it shows, back to front: the floor slab and the usable bounds (with a 1 m
or 5 m grid), the no-go zone (every collider below the robot's top, grown by
robot radius + clearance, translucent), walls, obstacles and door frames in
their true outlines (rotated boxes, circles; meshes and tilted shapes as their
bounding boxes), door leaves with their swing arc, movers' trajectories, the
reference paths, spawn and goal footprints with heading arrows; above the map a
title with the id and key figures, below it a scale bar and a legend.

Bytes are deterministic: no timestamps or text chunks (Pillow writes IHDR,
IDAT and IEND only for a fresh image), the font is Pillow's built-in one, and
every coordinate comes from the rounded metadata.
"""

from __future__ import annotations

import io
import math
from pathlib import Path
from typing import Any, Mapping

import numpy as np
import shapely
from PIL import Image

from worldgen.errors import OutputError, ParameterError
from worldgen.export.preview_frame import (
    COLOURS,
    DEFAULT_WIDTH,
    HIDDEN_ROLES,
    MAX_WIDTH,
    MIN_WIDTH,
    NOGO_ALPHA,
    SUPERSAMPLE,
    Layout,
    footer,
    layout,
    legend,
    title,
)
from worldgen.export.topdown import Pen, draw_movers, draw_people, text_font
from worldgen.files import PREVIEW_NAME, write_atomically
from worldgen.groundtruth.folder import WorldFolder
from worldgen.scene.pose import rpy_matrix

__all__ = ["DEFAULT_WIDTH", "MIN_WIDTH", "MAX_WIDTH", "COLOURS", "NOGO_ALPHA",
           "Layout", "layout", "draw", "render", "blocking"]

# -- geometry from the metadata ------------------------------------------------

def _outline(entity) -> tuple[str, Any]:
    """The entity's floor shadow: ("circle", (cx, cy, r)) or ("poly", (k, 2) points).

    Upright boxes and cylinders (their local z vertical) and spheres are exact;
    anything else (a mesh, a tilted shape, no shape) falls back to its world box.
    """
    shape = entity.get("shape") or {}
    x, y, _, roll, pitch, yaw = entity["pose"]
    rot = rpy_matrix(roll, pitch, yaw)
    upright = abs(abs(rot[2, 2]) - 1.0) < 1e-9
    kind = shape.get("type")
    if kind == "sphere" or (kind == "cylinder" and upright):
        return "circle", (x, y, shape["radius"])
    if kind == "box" and upright:
        sx, sy, _ = shape["size"]
        ex, ey = rot[:2, 0] * sx / 2, rot[:2, 1] * sy / 2
        c = np.array([x, y])
        return "poly", np.array([c - ex - ey, c + ex - ey, c + ex + ey, c - ex + ey])
    (x0, y0, _), (x1, y1, _) = entity["aabb"]
    return "poly", np.array([[x0, y0], [x1, y0], [x1, y1], [x0, y1]])


def blocking(entity, robot: Mapping[str, float]) -> bool:
    """True where the entity is in the no-go zone: a collider that reaches into the robot's height.

    Door leaves are left out: reference paths are planned with doors open.
    """
    if entity["role"] in HIDDEN_ROLES or entity["role"] == "door":
        return False
    (_, _, z0), (_, _, z1) = entity["aabb"]
    return z1 > 0.0 and z0 < robot["height"] + robot["clearance"]


def _inflated(kind: str, geo, grow: float) -> tuple[str, Any]:
    if kind == "circle":
        return "circle", (geo[0], geo[1], geo[2] + grow)
    ring = shapely.Polygon(geo).buffer(grow, quad_segs=8)
    return "poly", np.asarray(ring.exterior.coords)[:-1]


# -- drawing -------------------------------------------------------------------

def _Pen(image: Image.Image, lay: Layout) -> Pen:
    """The shared top-down pen (:mod:`worldgen.export.topdown`) on the supersampled image."""
    return Pen(image, lay, SUPERSAMPLE)


# long: the layers of the picture in drawing order, each a few lines
def draw(meta: Mapping[str, Any], width: int = DEFAULT_WIDTH) -> Image.Image:
    """The preview of ``meta`` (a world.json dict) as an RGB image ``width`` px wide."""
    lay = layout(meta, width)
    big = Image.new("RGB", (lay.width * SUPERSAMPLE, lay.height * SUPERSAMPLE), COLOURS["background"])
    pen = _Pen(big, lay)
    robot = meta["robot"]
    entities = list(meta.get("entities", []))

    for e in entities:  # the slab first: the usable bounds and the grid go on top of it
        if e["role"] == "floor":
            pen.shape(*_outline(e), fill=COLOURS["slab"])
    (bx0, by0), (bx1, by1) = meta["bounds"]["min"], meta["bounds"]["max"]
    pen.shape("poly", [(bx0, by0), (bx1, by0), (bx1, by1), (bx0, by1)], fill=COLOURS["floor"])
    unreachable = _unreachable(meta, entities)
    for ring in unreachable:
        pen.shape("poly", ring, fill=COLOURS["unreachable"])
    _grid(pen, (bx0, by0, bx1, by1), _grid_step(lay.scale))
    undrivable = _terrain(pen, meta)

    for e in entities:  # colliders the robot passes under (a door head): a thin outline, beneath the rest
        if e["role"] not in HIDDEN_ROLES and e["role"] != "door" and not blocking(e, robot):
            pen.shape(*_outline(e), outline=COLOURS["overhead"], width=1)

    # The no-go zone: one mask (so overlaps do not darken), blended once.
    mask = Image.new("L", big.size, 0)
    mask_pen = _Pen(mask, lay)
    grow = robot["radius"] + robot["clearance"]
    for e in entities:
        if blocking(e, robot):
            mask_pen.shape(*_inflated(*_outline(e), grow), fill=255)
    for ring in undrivable:  # ground the robot cannot drive is a no-go zone like an obstacle's
        mask_pen.shape(*_inflated("poly", ring, grow), fill=255)
    big.paste(COLOURS["nogo"], mask=mask.point(lambda v: round(v * NOGO_ALPHA)))

    layer_order = {"marker": 0, "obstacle": 1, "door_frame": 2, "wall": 3}
    for e in sorted((e for e in entities if e["role"] in layer_order), key=lambda e: layer_order[e["role"]]):
        kind, geo = _outline(e)
        if e["role"] == "marker":
            pen.shape(kind, geo, outline=COLOURS["marker"], width=1)
        elif blocking(e, robot):
            pen.shape(kind, geo, fill=COLOURS[{"obstacle": "obstacle", "door_frame": "frame", "wall": "wall"}[e["role"]]])
    by_name = {e["name"]: e for e in entities}
    for door in meta.get("doors", []) or []:
        _door(pen, door, by_name.get(door["name"]))
    for e in entities:  # leaves not named by doors[] (a hand-built scene): their outline alone
        if e["role"] == "door" and not any(d["name"] == e["name"] for d in meta.get("doors", []) or []):
            pen.shape(*_outline(e), fill=COLOURS["door"])

    draw_movers(pen, meta.get("dynamic_obstacles", []) or [])
    draw_people(pen, meta.get("people", []) or [])  # a colour each, a dot every topdown.TIME_MARK s

    tasks = list(meta.get("tasks", []))
    for t in tasks:
        if t.get("path"):
            pen.line(t["path"]["waypoints"], COLOURS["path"], width=3)
            if t.get("requires_door_open"):  # the reference path pushes a leaf open: say so on the line
                pen.line(t["path"]["waypoints"], COLOURS["door"], width=3, dash=6)
    for i, t in enumerate(tasks):
        label = "" if len(tasks) == 1 else str(i + 1)
        _pose_marker(pen, t["spawn"], robot["radius"], "spawn", "S" + label)
        _pose_marker(pen, t["goal"], robot["radius"], "goal", "G" + label, t.get("goal_tolerance"))

    image = big.reduce(SUPERSAMPLE)
    title(image, meta, lay)
    footer(image, lay, legend(meta, bool(unreachable)))
    return image


def _terrain(pen: Pen, meta: Mapping[str, Any]) -> list[np.ndarray]:
    """Draw world.json's terrain (each element's outline, filled) and return the rings of the ground its
    robot cannot drive (worldgen.scene.drivable); nothing on flat ground."""
    if not meta.get("terrain"):
        return []
    from worldgen.groundtruth.folder import robot_of
    from worldgen.scene import Scene
    from worldgen.scene.drivable import terrain_footprints
    from worldgen.scene.terrain import Terrain

    terrain = Terrain.from_canonical(meta["terrain"]["elements"])
    for e in terrain.elements:
        pen.shape("poly", np.asarray(e.outline().exterior.coords)[:-1], fill=COLOURS["terrain"],
                  outline=COLOURS["terrain_edge"], width=1)
    (x0, y0), (x1, y1) = meta["bounds"]["min"], meta["bounds"]["max"]
    scene = Scene((), bounds=((x0, y0), (x1, y1)), terrain=terrain)
    return [np.asarray(f.polygon.exterior.coords)[:-1] for f in terrain_footprints(scene, robot_of(meta))
            if f.polygon is not None]


def _unreachable(meta: Mapping[str, Any], entities) -> list[np.ndarray]:
    """Outer rings of the floor inside the bounds that the walls keep every footprint from a spawn out of.

    The robot's centre moves in the bounds shrunk by its inflation, less the no-go zone of the walls
    and door frames; the parts of that space holding a spawn, grown back by the inflation, are where it
    can be. The rest of the bounds (the inside of an L corridor, say) is drawn muted so the eye finds
    the drivable part. Obstacles are left out on purpose: the pockets between them are small, and
    taking them in cost 30-60 ms a picture at 50 obstacles against a millisecond for the walls alone.
    """
    robot, tasks = meta["robot"], meta.get("tasks", [])
    if not tasks:
        return []
    grow = robot["radius"] + robot["clearance"]
    (x0, y0), (x1, y1) = meta["bounds"]["min"], meta["bounds"]["max"]
    bounds = shapely.box(x0, y0, x1, y1)
    outlines = [_outline(e) for e in entities if e["role"] in ("wall", "door_frame") and blocking(e, robot)]
    shapes = [shapely.Point(geo[:2]).buffer(geo[2], quad_segs=8) if kind == "circle" else shapely.Polygon(geo)
              for kind, geo in outlines]
    shadows = [s.buffer(grow, quad_segs=4) for s in shapes]
    free = bounds.buffer(-grow, join_style="mitre").difference(shapely.union_all(shadows)) if shadows else \
        bounds.buffer(-grow, join_style="mitre")
    parts = list(getattr(free, "geoms", [free]))
    spawns = [shapely.Point(t["spawn"][0], t["spawn"][1]) for t in tasks]
    reach = [p for p in parts if any(p.buffer(1e-6).contains(s) for s in spawns)]
    if not reach:
        return []
    rest = bounds.difference(shapely.union_all(reach).buffer(grow, quad_segs=8))
    # The walls themselves are drawn over it anyway: what is left is floor nobody reaches. The corners
    # of a room are too small to be worth muting.
    if rest.difference(shapely.union_all(shapes)).area < 0.02 * bounds.area:
        return []
    return [np.asarray(p.exterior.coords)[:-1] for p in getattr(rest, "geoms", [rest]) if p.area > 1e-9]


def _grid_step(scale: float) -> float:
    """1 m lines unless they would be closer than 12 px, then 5 m, 10 m..."""
    for step in (1.0, 5.0, 10.0, 50.0, 100.0):
        if step * scale >= 12:
            return step
    return 500.0


def _grid(pen: Pen, box, step: float) -> None:
    x0, y0, x1, y1 = box
    for x in np.arange(math.ceil(x0 / step) * step, x1 + 1e-9, step):
        pen.line([(x, y0), (x, y1)], COLOURS["grid"])
    for y in np.arange(math.ceil(y0 / step) * step, y1 + 1e-9, step):
        pen.line([(x0, y), (x1, y)], COLOURS["grid"])


def _door(pen: Pen, door, leaf) -> None:
    """The leaf (its entity, where named), its swing arc from limit to limit, and the leaf at each limit."""
    hx, hy = door["hinge"][0], door["hinge"][1]
    width, angle = door["width"], door["angle"]
    lo, hi = door["limits"]
    sign = 1.0 if door["axis"][2] >= 0 else -1.0
    if leaf is not None:
        direction = math.atan2(leaf["pose"][1] - hy, leaf["pose"][0] - hx)
    else:  # no leaf entity: take joint angle 0 as closed, across the doorway towards its centre
        cx, cy = door["passage"]["center"]
        direction = math.atan2(cy - hy, cx - hx) + sign * angle
    if abs(door["axis"][2]) > 0.99:  # a vertical hinge: the swing is a circle arc on the floor
        at = [direction + sign * (q - angle) for q in np.linspace(lo, hi, 48)]
        arc = [(hx + width * math.cos(a), hy + width * math.sin(a)) for a in at]
        pen.line(arc, COLOURS["door"], width=1, dash=5)
        for a in (at[0], at[-1]):
            pen.line([(hx, hy), (hx + width * math.cos(a), hy + width * math.sin(a))], COLOURS["door"], width=1)
    if leaf is not None:
        pen.shape(*_outline(leaf), fill=COLOURS["door"])
    # A leaf is a few cm thick: a 4 px stroke keeps it visible at any scale.
    pen.line([(hx, hy), (hx + width * math.cos(direction), hy + width * math.sin(direction))],
             COLOURS["door"], width=4)
    pen.shape("circle", (hx, hy, 0.04), fill=COLOURS["frame"])


def _pose_marker(pen: Pen, pose, radius: float, kind: str, label: str, tolerance=None) -> None:
    x, y, yaw = pose[0], pose[1], pose[5]
    if tolerance:
        pen.shape("circle", (x, y, tolerance), outline=COLOURS[kind], width=1)
    pen.shape("circle", (x, y, radius), fill=COLOURS[kind + "_fill"], outline=COLOURS[kind], width=2)
    pen.arrow(x, y, yaw, radius * 2.2, COLOURS[kind])
    (u, v), = pen.xy([(x - radius * 0.75, y + radius * 0.75)])  # to the upper left, off the arrow's usual path
    font = text_font(15 * SUPERSAMPLE)
    pen.draw.text((u, v), label, fill=COLOURS[kind], font=font, anchor="rb")


def render(meta: Mapping[str, Any], width: int = DEFAULT_WIDTH) -> bytes:
    """preview.png of ``meta`` as PNG bytes (same metadata, same bytes)."""
    meta = {k: v for k, v in meta.items() if k != "files"}
    buf = io.BytesIO()
    draw(meta, width).save(buf, format="PNG", compress_level=6)
    return buf.getvalue()


def write_preview(folder, width: int = DEFAULT_WIDTH) -> Path:
    """Redraw ``folder/preview.png`` from ``folder/world.json``; return the picture's path.

    The file is replaced atomically (written beside it, then renamed), so a
    reader never sees half a picture. world.json is only read.
    """
    folder = Path(folder)
    opened = WorldFolder.open(folder, "argument WORLD_DIR")
    meta = opened.metadata
    try:
        png = render(meta, width)
    except (KeyError, TypeError, ValueError, IndexError) as exc:
        if isinstance(exc, ParameterError):
            raise
        raise ParameterError(f"argument WORLD_DIR '{folder}': world.json cannot be drawn "
                             f"({type(exc).__name__}: {exc})") from None
    target = opened.file("json").parent / PREVIEW_NAME
    try:
        write_atomically(target, png)
    except OSError as exc:
        raise OutputError(f"cannot write '{target}': {exc.strerror or exc}") from None
    return target
