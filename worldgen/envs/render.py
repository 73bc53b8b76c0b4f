"""``render_mode="rgb_array"``: a top-down picture of the episode, drawn with Pillow (no OpenGL).

The world is drawn once per episode by :func:`worldgen.export.preview.draw` (the same
picture as preview.png: walls, obstacles, no-go zone, reference path, spawn and
goal, title, scale bar); each frame copies it and adds, in the preview's own
world-to-pixel layout and with the one drawing of a world from above
(:mod:`worldgen.export.topdown`: its pen and colour table): the lidar beams as thin
lines to where they read, the path travelled so far, the movers where they are
now, and the robot (its footprint and heading).
"""

from __future__ import annotations

import math
from typing import Optional, Sequence

import numpy as np
from PIL import Image, ImageDraw

from worldgen.export.preview import draw, layout
from worldgen.export.topdown import COLOURS, Pen, draw_robot

__all__ = ["FRAME_WIDTH", "MAX_BEAMS_DRAWN", "TopDown", "mover_discs", "ROBOT_COLOUR", "BEAM_COLOUR", "TRACK_COLOUR"]

#: Width of a frame in pixels (the preview's default).
FRAME_WIDTH = 640
ROBOT_COLOUR = COLOURS["robot"]
BEAM_COLOUR = COLOURS["beam"]
TRACK_COLOUR = COLOURS["track"]
#: At most this many beams are drawn (evenly spaced), so a 4096-beam scan stays readable.
MAX_BEAMS_DRAWN = 360


class TopDown:
    """Frames of one world (a world.json dict ``meta``) at ``width`` px."""

    def __init__(self, meta: dict, width: int = FRAME_WIDTH):
        self.layout = layout(meta, width)
        self.background = draw(meta, width)
        self.radius = float(meta["robot"]["radius"])

    def _px(self, x: float, y: float) -> tuple[float, float]:
        return self.layout.px(x, y)

    def frame(self, pose: tuple[float, float, float], track: np.ndarray, beam_angles: np.ndarray,
              ranges: np.ndarray, movers: Sequence[tuple[float, float, float]] = (),
              collided: bool = False) -> np.ndarray:
        """(height, width, 3) uint8 RGB: the world, the beams, the track, the movers and the robot.

        ``pose`` = (x, y, yaw); ``track`` (n, 2) positions so far; ``beam_angles``
        and ``ranges`` (beams,) from the heading and the noise-free reading;
        ``movers`` (x, y, radius) each.
        """
        image = self.background.copy()
        overlay = Image.new("RGBA", image.size, (0, 0, 0, 0))
        beams = ImageDraw.Draw(overlay)
        x, y, yaw = pose
        step = max(1, int(math.ceil(len(ranges) / MAX_BEAMS_DRAWN)))
        origin = self._px(x, y)
        for a, r in zip(beam_angles[::step], ranges[::step]):
            end = self._px(x + r * math.cos(yaw + a), y + r * math.sin(yaw + a))
            beams.line([origin, end], fill=BEAM_COLOUR + (70,), width=1)
        image.paste(overlay, (0, 0), overlay)
        pen = Pen(image, self.layout)
        if len(track) > 1:
            pen.line(track, TRACK_COLOUR, width=2)
        for mx, my, mr in movers:
            pen.shape("circle", (mx, my, mr), fill=COLOURS["mover"])
        draw_robot(pen, x, y, yaw, self.radius, collided)
        return np.asarray(image, dtype=np.uint8)


def mover_discs(movers: list, xy: Optional[np.ndarray]) -> list[tuple[float, float, float]]:
    """(x, y, radius) of each mover (world.json ``dynamic_obstacles``) at positions ``xy`` (n, 2)."""
    if xy is None:
        return []
    return [(float(p[0]), float(p[1]), float(m["radius"])) for m, p in zip(movers, xy)]
