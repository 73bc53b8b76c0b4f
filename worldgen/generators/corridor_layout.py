"""The corridor's centreline: legs, turns and the rectangles they make, exact for axis-aligned headings.

:func:`layout` turns the corridor generator's ``shape``, ``segments``, ``turns``, ``length`` and
``width`` into a :class:`Layout` (raising a one-line ParameterError for a combination no corridor has);
the generator (:mod:`worldgen.generators.corridor`) builds walls, openings and obstacles along it.
"""

from __future__ import annotations

from typing import Any, Mapping

import numpy as np

from worldgen.errors import ParameterError

__all__ = ["Layout", "layout", "ZIGZAG_SEGMENTS"]

#: Unit vectors of the four headings (+x, +y, -x, -y): exact, so coordinates stay exact sums.
_HEADINGS = ((1.0, 0.0), (0.0, 1.0), (-1.0, 0.0), (0.0, -1.0))
_SEGMENT_COUNT = {"straight": 1, "L": 2, "U": 3}
#: Default number of segments of a zigzag given neither segments nor turns.
ZIGZAG_SEGMENTS = 4


class Layout:
    """The corridor's centreline and derived frame, all exact for axis-aligned headings.

    ``points`` (k+1, 2) centreline vertices, ``heads`` (k,) heading index of each
    segment (0 +x, 1 +y, 2 -x, 3 -y), ``lengths`` (k,), ``turns`` (k-1,) +1 left / -1 right.
    """

    def __init__(self, lengths, turns, width: float):
        self.lengths = [float(v) for v in lengths]
        self.turns = list(turns)
        self.width = width
        heads, points = [0], [np.zeros(2)]
        for i, length in enumerate(self.lengths):
            points.append(points[-1] + length * np.array(_HEADINGS[heads[-1]]))
            if i < len(self.turns):
                heads.append((heads[-1] + self.turns[i]) % 4)
        self.heads = heads
        self.points = np.array(points)

    def u(self, i: int) -> np.ndarray:
        return np.array(_HEADINGS[self.heads[i]])

    def n(self, i: int) -> np.ndarray:
        """The left normal of segment i."""
        return np.array(_HEADINGS[(self.heads[i] + 1) % 4])

    def rects(self, extra: float = 0.0) -> list[tuple[float, float, float, float]]:
        """(minx, miny, maxx, maxy) of each leg's floor (corner squares included), widened by ``extra``."""
        out = []
        half = self.width / 2 + extra
        k = len(self.lengths)
        for i in range(k):
            u = self.u(i)
            start = self.points[i] - (self.width / 2 + extra if i > 0 else extra) * u
            end = self.points[i + 1] + (self.width / 2 + extra if i < k - 1 else extra) * u
            n = self.n(i)
            pts = np.array([start + half * n, start - half * n, end + half * n, end - half * n])
            out.append((*pts.min(axis=0), *pts.max(axis=0)))
        return out

    def bounds(self):
        r = np.array(self.rects())
        return ((float(r[:, 0].min()), float(r[:, 1].min())), (float(r[:, 2].max()), float(r[:, 3].max())))

    def straight_part(self, i: int) -> tuple[float, float]:
        """Along-segment interval of leg i outside the corner squares (0 = its start vertex)."""
        lo = self.width / 2 if i > 0 else 0.0
        hi = self.lengths[i] - (self.width / 2 if i < len(self.lengths) - 1 else 0.0)
        return lo, hi


def _lengths_and_turns(params: Mapping[str, Any]) -> tuple[list[float], list[int]]:
    shape = params["shape"]
    segments, turns = params["segments"], params["turns"]
    words = turns.split(",") if turns is not None else None
    if shape == "zigzag":
        count = len(segments) if segments is not None else (len(words) + 1 if words else ZIGZAG_SEGMENTS)
        if count < 2:
            raise ParameterError(f"parameter 'segments' must hold at least 2 lengths for a zigzag, got {segments!r}")
        if words is None:
            words = ["left" if i % 2 == 0 else "right" for i in range(count - 1)]
        if len(words) != count - 1:
            raise ParameterError(f"parameter 'turns' must name {count - 1} turns for {count} zigzag segments, got {turns!r}")
    else:
        count = _SEGMENT_COUNT[shape]
        if segments is not None and len(segments) != count:
            raise ParameterError(f"parameter 'segments' must hold {count} length(s) for a {shape} corridor, got {segments!r}")
        if shape == "straight":
            if words is not None:
                raise ParameterError(f"parameter 'turns' does not apply to a straight corridor; leave it unset, got {turns!r}")
            words = []
        elif words is None:
            words = ["left"] * (count - 1)
        elif len(words) != count - 1 or len(set(words)) != 1:
            need = "one turn" if shape == "L" else "two turns the same way (e.g. left,left)"
            raise ParameterError(f"parameter 'turns' must be {need} for a {shape} corridor, got {turns!r}")
    lengths = list(segments) if segments is not None else [params["length"]] * count
    return lengths, [1 if w == "left" else -1 for w in words]


def layout(params: Mapping[str, Any]) -> Layout:
    """The centreline of validated ``params`` (raises :class:`ParameterError` for impossible ones)."""
    lengths, turns = _lengths_and_turns(params)
    return Layout(lengths, turns, params["width"])
