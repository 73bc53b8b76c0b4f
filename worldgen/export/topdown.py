"""One drawing of a world seen from above: the colour table, the pen and the layers every picture shares.

Three pictures show a world from above, and all of them draw with this module:

- preview.png (:mod:`worldgen.export.preview`, the world from its world.json);
- the environment's frames (:mod:`worldgen.envs.render`: the world, then the robot, its beams and track);
- the judge's run pictures (:mod:`worldgen.judge.report`: the world, then the run, its contacts and who
  was where at each contact).

So a mover, a person, the reference path or a contact looks the same in each. World point (x, y) goes
to a pixel through a layout (``px(x, y)`` and ``scale`` px/m: :class:`worldgen.export.preview_frame.Layout`),
+x right and +y up (REP 103 seen from above).

People are drawn so that many stay readable: each person has a colour of its own
(:data:`PERSON_COLOURS`, cycled), its track carries a dot every :data:`TIME_MARK` seconds, and its
start a ring with its number.
"""

from __future__ import annotations

import math
from functools import lru_cache
from typing import Any, Mapping, Optional, Sequence

import numpy as np
from PIL import Image, ImageDraw, ImageFont

from worldgen.scene.motion import positions_at

__all__ = ["COLOURS", "PERSON_COLOURS", "TIME_MARK", "Pen", "text_font", "person_colour", "draw_movers",
           "draw_people", "draw_run", "discs_at", "draw_robot"]

#: RGB of every layer of every top-down picture; tests sample pixels against these.
COLOURS = {
    "background": (255, 255, 255),
    "slab": (214, 214, 210),        # floor slab outside the usable bounds
    "floor": (248, 247, 242),       # the usable bounds
    "unreachable": (232, 231, 226), # floor inside the bounds that no footprint from a spawn can reach
    "grid": (228, 227, 220),
    "nogo": (232, 72, 64),          # blended at preview_frame.NOGO_ALPHA over what lies beneath
    "wall": (45, 45, 55),
    "obstacle": (84, 104, 140),
    "terrain": (222, 206, 170),     # ramps, kerbs, potholes, rough patches (docs/terrain.md)
    "terrain_edge": (160, 130, 80),
    "overhead": (150, 160, 180),    # outline of colliders the robot passes under
    "frame": (105, 80, 60),
    "door": (176, 112, 48),
    "marker": (120, 170, 120),
    "mover": (150, 70, 200),
    "path": (250, 140, 0),
    "spawn": (28, 150, 70),
    "spawn_fill": (206, 238, 214),
    "goal": (30, 90, 220),
    "goal_fill": (210, 224, 250),
    "text": (20, 20, 25),
    "alert": (200, 30, 30),
    "robot": (235, 110, 20),        # the environment's robot
    "beam": (236, 64, 122),         # its lidar beams (drawn translucent)
    "track": (20, 20, 25),          # the path it has driven
    "run_ok": (28, 120, 200),       # a judged run that succeeded
    "run": (200, 30, 30),           # a judged run that failed
    "contact": (200, 30, 30),       # where a run touched something
    "person": (214, 39, 122),       # the first person's colour, the legend's (PERSON_COLOURS[0])
}
#: One colour per person (cycled past ten): saturated, and none of them the path's, spawn's, goal's or a mover's.
PERSON_COLOURS = ((214, 39, 122), (0, 140, 150), (140, 86, 40), (120, 120, 20), (90, 60, 170),
                  (230, 110, 170), (0, 100, 60), (150, 30, 60), (70, 120, 190), (110, 110, 110))
#: Seconds between two dots on a person's track.
TIME_MARK = 5.0


@lru_cache(maxsize=None)
def text_font(size: int):
    """Pillow's built-in font at ``size`` px: the same glyphs on every machine, so the pictures' bytes are stable."""
    return ImageFont.load_default(size=size)


def person_colour(k: int) -> tuple[int, int, int]:
    return PERSON_COLOURS[k % len(PERSON_COLOURS)]


class Pen:
    """Draws world-frame shapes on an image ``supersample`` times the layout's size (1: the layout's own)."""

    def __init__(self, image: Image.Image, lay, supersample: int = 1):
        self.draw = ImageDraw.Draw(image)
        self.lay = lay
        self.k = supersample

    def xy(self, pts) -> list[tuple[float, float]]:
        out = []
        for x, y in np.asarray(pts, dtype=float).reshape(-1, 2):
            u, v = self.lay.px(x, y)
            out.append((u * self.k, v * self.k))
        return out

    def m(self, metres: float) -> float:
        return metres * self.lay.scale * self.k

    def shape(self, kind, geo, fill=None, outline=None, width=1):
        if kind == "circle":
            (u, v), = self.xy([geo[:2]])
            r = self.m(geo[2])
            self.draw.ellipse([u - r, v - r, u + r, v + r], fill=fill, outline=outline, width=width * self.k)
        else:
            self.draw.polygon(self.xy(geo), fill=fill, outline=outline, width=width * self.k)

    def line(self, pts, fill, width=1, dash: Optional[float] = None):
        p = self.xy(pts)
        if dash is None:
            self.draw.line(p, fill=fill, width=width * self.k, joint="curve")
            return
        step, on = dash * self.k, True
        for a, b in zip(p[:-1], p[1:]):  # the dash pattern restarts at each vertex: simple, and fine here
            n = max(1, int(math.dist(a, b) // step))
            for j in range(n):
                if on:
                    t0, t1 = j / n, (j + 1) / n
                    self.draw.line([(a[0] + (b[0] - a[0]) * t0, a[1] + (b[1] - a[1]) * t0),
                                    (a[0] + (b[0] - a[0]) * t1, a[1] + (b[1] - a[1]) * t1)],
                                   fill=fill, width=width * self.k)
                on = not on

    def arrow(self, x, y, yaw, length, fill, width=2):
        tip = np.array([x + length * math.cos(yaw), y + length * math.sin(yaw)])
        self.line([(x, y), tip], fill, width)
        head = min(length * 0.45, 0.35)
        wings = [tip - head * np.array([math.cos(yaw + s), math.sin(yaw + s)]) for s in (0.45, -0.45)]
        self.draw.polygon(self.xy([tip, wings[0], wings[1]]), fill=fill)

    def label(self, x: float, y: float, text: str, fill, size: int = 12, anchor: str = "mm") -> None:
        (u, v), = self.xy([(x, y)])
        self.draw.text((u, v), text, fill=fill, font=text_font(size * self.k), anchor=anchor)


def draw_movers(pen: Pen, movers: Sequence[Mapping[str, Any]]) -> None:
    """Each scripted mover's track (dashed, closed when it loops) and its disc where it starts."""
    for mover in movers:
        traj = [(x, y) for _, x, y in mover["trajectory"]]
        if mover.get("loop") and len(traj) > 2:
            traj.append(traj[0])
        pen.line(traj, COLOURS["mover"], width=2, dash=7)
        x, y = traj[0]
        pen.shape("circle", (x, y, mover["radius"]), outline=COLOURS["mover"], width=2)


def draw_people(pen: Pen, people: Sequence[Mapping[str, Any]]) -> None:
    """Each person's track in its own colour, a dot every TIME_MARK s along it, its start ring and number,
    and a small disc where it ends."""
    for k, person in enumerate(people):
        colour = person_colour(k)
        rows = np.asarray(person["trajectory"], dtype=float)
        pen.line(rows[:, 1:].tolist(), colour, width=1)
        marks = np.arange(0.0, rows[-1, 0] + 1e-9, TIME_MARK)
        for x, y in zip(np.interp(marks, rows[:, 0], rows[:, 1]), np.interp(marks, rows[:, 0], rows[:, 2])):
            pen.shape("circle", (x, y, 0.05), fill=colour)
        x, y, r = rows[0, 1], rows[0, 2], float(person["radius"])
        pen.shape("circle", (x, y, r), outline=colour, width=2)
        pen.label(x + r, y + r, str(k), colour, size=13, anchor="lb")  # its number, up and right of the start
        pen.shape("circle", (rows[-1, 1], rows[-1, 2], r / 2), fill=colour)  # where it ends up


def discs_at(meta: Mapping[str, Any], t: float) -> list[tuple[str, float, float, float, tuple[int, int, int]]]:
    """(name, x, y, radius, colour) of every mover and person where world.json's scripts have them at ``t`` s."""
    rows = [(m, COLOURS["mover"]) for m in meta.get("dynamic_obstacles") or []]
    rows += [(p, person_colour(k)) for k, p in enumerate(meta.get("people") or [])]
    if not rows:
        return []
    tracks = [np.asarray(m["trajectory"], dtype=float) for m, _ in rows]
    where = positions_at(tracks, [bool(m.get("loop", False)) for m, _ in rows], np.array([t]))[0]
    return [(str(m["name"]), float(x), float(y), float(m["radius"]), c) for (m, c), (x, y) in zip(rows, where)]


def draw_run(pen: Pen, meta: Mapping[str, Any], trajectory: np.ndarray, success: bool,
             contacts: Sequence[Mapping[str, Any]]) -> None:
    """A judged run over its world: the trajectory (``(n, >=3)`` t, x, y; blue when it succeeded, red when
    not), and at each contact the robot's footprint crossed out, with every mover and person where they
    were at that moment (filled discs in their colours, named)."""
    colour = COLOURS["run_ok"] if success else COLOURS["run"]
    if len(trajectory) > 1:
        pen.line(trajectory[:, 1:3], colour, width=3)
    robot_r = float(meta["robot"]["radius"])
    for c in contacts:
        t = float(c["time"])
        for name, x, y, r, disc_colour in discs_at(meta, t):
            pen.shape("circle", (x, y, r), fill=disc_colour, outline=COLOURS["text"], width=1)
            if name == c.get("entity"):
                pen.label(x, y + r, name, disc_colour, size=11, anchor="mb")
        x = float(np.interp(t, trajectory[:, 0], trajectory[:, 1]))
        y = float(np.interp(t, trajectory[:, 0], trajectory[:, 2]))
        pen.shape("circle", (x, y, robot_r), outline=COLOURS["contact"], width=3)
        d = robot_r / math.sqrt(2)
        pen.line([(x - d, y - d), (x + d, y + d)], COLOURS["contact"], width=2)
        pen.line([(x - d, y + d), (x + d, y - d)], COLOURS["contact"], width=2)


def draw_robot(pen: Pen, x: float, y: float, yaw: float, radius: float, collided: bool = False) -> None:
    """The robot's footprint (filled; in the alert colour after a collision) with its heading."""
    pen.shape("circle", (x, y, radius), fill=COLOURS["alert"] if collided else COLOURS["robot"],
              outline=COLOURS["track"], width=2)
    pen.line([(x, y), (x + 1.6 * radius * math.cos(yaw), y + 1.6 * radius * math.sin(yaw))], COLOURS["track"], width=3)
