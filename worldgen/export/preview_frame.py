"""The frame of preview.png: its size and the world-to-pixel layout, the title above the map,
and the scale bar, axes and legend below it (:mod:`worldgen.export.preview` draws the map)."""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any, Mapping

import numpy as np
from PIL import Image, ImageDraw

from worldgen.errors import ParameterError
from worldgen.export.topdown import COLOURS, text_font

__all__ = ["DEFAULT_WIDTH", "MIN_WIDTH", "MAX_WIDTH", "COLOURS", "NOGO_ALPHA", "SUPERSAMPLE",
           "HIDDEN_ROLES", "Layout", "layout", "text_font", "title", "title_lines", "footer"]

DEFAULT_WIDTH = 800
MIN_WIDTH, MAX_WIDTH = 400, 4000

#: Opacity of the no-go zone: light enough that the floor grid still shows through.
NOGO_ALPHA = 0.3

_MARGIN = 16     # px left and right of the map
_TITLE_H = 46    # px above the map: two lines of text
_FOOTER_H = 40   # px below the map per legend row
SUPERSAMPLE = 2          # the map is drawn at twice the size and averaged down: smooth edges, no blur
_SCALE_BAR_MAX = 130  # px: the longest round length (100, 50, 10, 5, 1, 0.5 m) below it
HIDDEN_ROLES = ("floor", "marker")  # roles that never block the robot


@dataclass(frozen=True)
class Layout:
    """Where the world lands in the image.

    World point (x, y) -> pixel ``(left + (x - x0) * scale, top + (y1 - y) * scale)``:
    +x to the right, +y up (REP 103 seen from above). ``scale`` is px per metre;
    (x0, y1) is the top-left corner of the drawn extent.
    """

    width: int
    height: int
    scale: float
    x0: float
    y1: float
    left: float
    top: float
    legend_rows: int

    def px(self, x: float, y: float) -> tuple[float, float]:
        return self.left + (x - self.x0) * self.scale, self.top + (self.y1 - y) * self.scale


def layout(meta: Mapping[str, Any], width: int = DEFAULT_WIDTH) -> Layout:
    """The image size and world->pixel map for ``meta`` at ``width`` px.

    The drawn extent covers the bounds, every entity's box, every mover's
    trajectory and every spawn and goal, plus a small margin. The map is at
    most as tall as it is wide, so a long corridor along y stays on screen.
    """
    if isinstance(width, bool) or not isinstance(width, int) or not MIN_WIDTH <= width <= MAX_WIDTH:
        raise ParameterError(f"parameter 'width' must be an integer in [{MIN_WIDTH}, {MAX_WIDTH}] px, got {width!r}")
    xs, ys = _extent_points(meta)
    lo = np.array([min(xs), min(ys)])
    hi = np.array([max(xs), max(ys)])
    span = hi - lo
    pad = 0.02 * float(span.max()) + 0.1
    lo, hi = lo - pad, hi + pad
    span = hi - lo
    room = width - 2 * _MARGIN
    scale = min(room / span[0], room / span[1])
    map_w, map_h = span[0] * scale, span[1] * scale
    rows = 1 if _LEGEND_START + _legend_width(legend(meta, unreachable=True)) + _MARGIN <= width else 2
    height = int(math.ceil(_TITLE_H + map_h + _FOOTER_H * rows - 1e-6))  # 768.0000001 px is 768
    return Layout(width, height, float(scale), float(lo[0]), float(hi[1]),
                  float((width - map_w) / 2), float(_TITLE_H), rows)


def _extent_points(meta) -> tuple[list[float], list[float]]:
    b = meta["bounds"]
    xs, ys = [b["min"][0], b["max"][0]], [b["min"][1], b["max"][1]]
    for e in meta.get("entities", []):
        (x0, y0, _), (x1, y1, _) = e["aabb"]
        xs += [x0, x1]
        ys += [y0, y1]
    for m in meta.get("dynamic_obstacles", []) or []:
        for _, x, y in m["trajectory"]:
            xs += [x - m["radius"], x + m["radius"]]
            ys += [y - m["radius"], y + m["radius"]]
    r = meta["robot"]["radius"]
    for t in meta.get("tasks", []):
        for p in (t["spawn"], t["goal"]):
            xs += [p[0] - r, p[0] + r]
            ys += [p[1] - r, p[1] + r]
    return xs, ys


def _fmt_m(x) -> str:
    return "-" if x is None else f"{x:.2f} m"


def title_lines(meta) -> tuple[str, list[str]]:
    """The title's first line (the folder's name: ``<preset>--<world_id>`` for a preset's world) and the parts
    of its second, most important first: the level (asked for, with the request's seed, or the one measured),
    how many people, the path, the narrowest passage, obstacles, doors, the robot."""
    head = str(meta.get("world_id", "?"))
    if meta.get("preset"):
        head = f"{meta['preset']}--{head}"
    metrics = meta.get("metrics", {}) or {}
    lengths = [t["path"]["length"] for t in meta.get("tasks", []) if t.get("path")]
    level = metrics.get("difficulty_level")
    request = meta.get("difficulty_request") or {}
    parts = [
        *([f"level {request['level']} (request seed {request['seed']})"] if request else []),
        *([f"level {level}/10"] if level is not None and not request else []),
        *([f"{len(meta['people'])} people"] if meta.get("people") else []),
        f"path {', '.join(f'{x:.2f}' for x in lengths)} m" if lengths else "no path",
        f"narrowest passage {_fmt_m(metrics.get('narrowest_passage'))}",
        f"{metrics.get('obstacle_count', '?')} obstacles",
        *([f"doors: {', '.join(d['state'] for d in meta['doors'])}"] if meta.get("doors") else []),
        f"robot r {meta['robot']['radius']:.2f} + {meta['robot']['clearance']:.2f} m",
    ]
    return head, parts


def title(image: Image.Image, meta, lay: Layout) -> None:
    d = ImageDraw.Draw(image)
    room = lay.width - 2 * _MARGIN
    big, small = text_font(16), text_font(13)
    head, parts = title_lines(meta)
    d.text((_MARGIN, 6), head, fill=COLOURS["text"], font=big)
    feas = meta.get("feasibility", {}) or {}
    if feas and not feas.get("feasible", True):
        failed = ", ".join(c["name"] for c in feas.get("checks", []) if not c.get("ok"))
        x = _MARGIN + big.getlength(head) + 12
        d.text((x, 6), _fit(f"INFEASIBLE: {failed}", big, _MARGIN + room - x), fill=COLOURS["alert"], font=big)
    while len(parts) > 1 and small.getlength("   |   ".join(parts)) > room:  # narrow image: least important last
        parts.pop()
    d.text((_MARGIN, 26), _fit("   |   ".join(parts), small, room), fill=COLOURS["text"], font=small)


def _fit(text: str, font, room: float) -> str:
    """``text`` cut (with an ellipsis) to at most ``room`` px."""
    if font.getlength(text) <= room:
        return text
    while text and font.getlength(text + "...") > room:
        text = text[:-1]
    return text + "..."


#: Every legend entry (text, colour, glyph), in order; a picture lists those its world has (:func:`legend`).
_LEGEND = (("obstacle", "obstacle", "box"), ("wall", "wall", "box"), ("no-go zone", "nogo", "zone"),
           ("unreachable", "unreachable", "box"), ("path", "path", "line"),
           ("path (opens a door)", "path", "line"), ("spawn", "spawn", "disc"), ("goal", "goal", "disc"),
           ("door", "door", "box"), ("mover", "mover", "dash"),
           ("people (a colour each, dot every 5 s)", "person", "track"))
_LEGEND_START = _MARGIN + _SCALE_BAR_MAX + 28 + 40  # right of the longest scale bar and the axes
_LEGEND_GAP = 12  # px between one entry's text and the next glyph


def legend(meta: Mapping[str, Any], unreachable: bool) -> tuple[tuple[str, str, str], ...]:
    """The legend entries of what ``meta``'s picture shows: no door or mover entry in a world without one."""
    roles = {e["role"] for e in meta.get("entities", [])}
    tasks = meta.get("tasks", [])
    through_door = any(t.get("path") and t.get("requires_door_open") for t in tasks)
    shown = {
        "obstacle": "obstacle" in roles, "wall": "wall" in roles or "door_frame" in roles,
        "no-go zone": bool(roles - {"floor", "marker"}), "unreachable": unreachable,
        "path": any(t.get("path") and not t.get("requires_door_open") for t in tasks),
        "path (opens a door)": through_door, "spawn": bool(tasks), "goal": bool(tasks),
        "door": bool(meta.get("doors")) or "door" in roles, "mover": bool(meta.get("dynamic_obstacles")),
        "people (a colour each, dot every 5 s)": bool(meta.get("people")),
    }
    return tuple(entry for entry in _LEGEND if shown[entry[0]])


def _legend_width(entries=_LEGEND) -> float:
    font = text_font(12)
    return sum(19 + font.getlength(text) + _LEGEND_GAP for text, _, _ in entries)


def footer(image: Image.Image, lay: Layout, entries=_LEGEND) -> None:
    d = ImageDraw.Draw(image)
    font = text_font(12)
    top = lay.height - _FOOTER_H * lay.legend_rows
    y = top + 14
    length = next((s for s in (100.0, 50.0, 10.0, 5.0, 1.0, 0.5) if s * lay.scale <= _SCALE_BAR_MAX), 0.5)
    x0, x1 = _MARGIN, _MARGIN + length * lay.scale
    d.line([(x0, y), (x1, y)], fill=COLOURS["text"], width=3)
    for x in (x0, x1):
        d.line([(x, y - 5), (x, y + 5)], fill=COLOURS["text"], width=2)
    d.text(((x0 + x1) / 2, y + 6), f"{length:g} m", fill=COLOURS["text"], font=font, anchor="ma")
    # Axes: +x right, +y up.
    ax, ay = x1 + 28, y + 8
    d.line([(ax, ay), (ax + 18, ay)], fill=COLOURS["text"], width=2)
    d.line([(ax, ay), (ax, ay - 18)], fill=COLOURS["text"], width=2)
    d.text((ax + 20, ay), "x", fill=COLOURS["text"], font=font, anchor="lm")
    d.text((ax, ay - 20), "y", fill=COLOURS["text"], font=font, anchor="mb")
    # Legend, wrapped onto the rows the layout reserved.
    # Each row right-aligned on its own width, so no entry runs off the picture.
    per_row = max(1, math.ceil(len(entries) / lay.legend_rows))
    rows = [entries[k:k + per_row] for k in range(0, len(entries), per_row)]
    for i, (text, colour, glyph) in enumerate(entries):
        if i % per_row == 0:
            gx = max(ax + 40, lay.width - _MARGIN - _legend_width(rows[i // per_row]) + _LEGEND_GAP)
        gy = top + 12 + (i // per_row) * _FOOTER_H
        c = COLOURS[colour]
        if glyph == "box":
            d.rectangle([gx, gy - 5, gx + 14, gy + 5], fill=c, outline=COLOURS["grid"] if colour == "unreachable" else None)
        elif glyph == "zone":
            blend = tuple(round(f + (n - f) * NOGO_ALPHA) for f, n in zip(COLOURS["floor"], c))
            d.rectangle([gx, gy - 5, gx + 14, gy + 5], fill=blend, outline=c)
        elif glyph == "line":
            d.line([(gx, gy), (gx + 14, gy)], fill=c, width=3)
            if text != "path":  # through a door it opens: dashed in the leaf's colour, as on the map
                d.line([(gx + 5, gy), (gx + 9, gy)], fill=COLOURS["door"], width=3)
        elif glyph == "disc":
            d.ellipse([gx + 1, gy - 6, gx + 13, gy + 6], fill=COLOURS[colour + "_fill"], outline=c, width=2)
        elif glyph == "track":
            d.line([(gx, gy), (gx + 14, gy)], fill=c, width=1)
            d.ellipse([gx + 5, gy - 2, gx + 9, gy + 2], fill=c)
        else:
            d.line([(gx, gy), (gx + 5, gy)], fill=c, width=2)
            d.line([(gx + 9, gy), (gx + 14, gy)], fill=c, width=2)
        d.text((gx + 19, gy), text, fill=COLOURS["text"], font=font, anchor="lm")
        gx += 19 + font.getlength(text) + _LEGEND_GAP
