"""Portals: the narrow gaps between two obstacles that the grid cannot prove passable.

The grid search proves a move free only where the clearance field has room to
spare: about two cells more than the disc's diameter. A gap between two
obstacles that is wider than the disc but narrower than that is real, and the
shortest path often runs through it (in dense clutter, by tens of percent), so
the search would choose a longer way round and report it as the shortest.

For two convex footprints A and B with closest points a and b, A lies wholly on
a's side of the line through a perpendicular to ab, and B on b's side; so every
point of the line through the gap's midpoint, perpendicular to ab, is at least
|ab| / 2 from both. A portal is a short piece of that line: if |ab| / 2 exceeds
the disc's radius and no third obstacle comes near the piece (checked with
exact distances), the disc can cross the gap along it. Its two ends join the
grid search as extra nodes, linked to nearby cells by exactly checked segments.
"""

from __future__ import annotations

import weakref
from dataclasses import dataclass

import numpy as np
import shapely

from worldgen.feasibility.field import DistanceField
from worldgen.feasibility.geometry import Obstacles2D, inside_bounds

__all__ = ["Portal", "gaps", "find_portals", "exact_links"]

#: A gap counts as narrow (one the grid may miss) below the disc's diameter plus this many cells.
NARROW_CELLS = 3.0
#: Half lengths of a portal tried, in cells: its ends should sit where the grid can see again.
HALF_LENGTH_CELLS = (3.0, 1.5, 0.75)
#: Cells around a point tried as its links into the grid (a square of 2k+1 cells a side).
LINK_CELLS = 3


@dataclass(frozen=True, eq=False)
class Portal:
    """A proven crossing of a narrow gap: the segment ``ends[0]``-``ends[1]`` keeps the disc clear.

    ``width`` is the gap between the two obstacles (m).
    """

    ends: np.ndarray
    width: float


def _shape(obstacles: Obstacles2D, k: int):
    if k < obstacles.n_discs:
        return shapely.Point(obstacles.disc_xy[k]), float(obstacles.disc_r[k])
    return shapely.Polygon(obstacles.corners(k)), 0.0


_GAPS: "weakref.WeakKeyDictionary[Obstacles2D, tuple[float, list]]" = weakref.WeakKeyDictionary()


def gaps(obstacles: Obstacles2D, below: float) -> list[tuple[float, np.ndarray, np.ndarray]]:
    """Every gap narrower than ``below`` between two obstacles: (width, midpoint, unit normal to the gap).

    The gap of two convex footprints is the segment between their closest points;
    the normal runs along the gap, perpendicular to that segment. Remembered per
    obstacle set (portals and the passage width both ask), for the widest
    ``below`` asked so far.
    """
    known = _GAPS.get(obstacles)
    if known is None or known[0] < below:
        known = (below, _gaps(obstacles, below))
        _GAPS[obstacles] = known
    return [gap for gap in known[1] if gap[0] < below]


def _gaps(obstacles: Obstacles2D, below: float) -> list[tuple[float, np.ndarray, np.ndarray]]:
    n = len(obstacles)
    if n < 2:
        return []
    b = obstacles.boxes
    gap_x = np.maximum(b[:, None, 0] - b[None, :, 2], b[None, :, 0] - b[:, None, 2])
    gap_y = np.maximum(b[:, None, 1] - b[None, :, 3], b[None, :, 1] - b[:, None, 3])
    close = np.triu(np.hypot(np.maximum(gap_x, 0), np.maximum(gap_y, 0)) < below, k=1)
    shapes = {}
    out = []
    for i, j in np.argwhere(close):
        for k in (i, j):
            if k not in shapes:
                shapes[k] = _shape(obstacles, k)
        (gi, ri), (gj, rj) = shapes[i], shapes[j]
        line = np.asarray(shapely.shortest_line(gi, gj).coords)
        pa, pb = line[0], line[1]
        d = float(np.hypot(*(pb - pa)))
        if d <= 1e-12:
            continue  # touching or overlapping: no gap
        u = (pb - pa) / d
        pa, pb = pa + ri * u, pb - rj * u  # from a disc's centre to its rim
        width = d - ri - rj
        if 0 < width < below:
            out.append((width, (pa + pb) / 2, np.array([-u[1], u[0]])))
    return out


def find_portals(obstacles: Obstacles2D, bounds, radius: float, cell: float) -> list[Portal]:
    """Every gap between two obstacles in (2 radius, 2 radius + NARROW_CELLS cells) that a disc crosses."""
    narrow = 2 * radius + NARROW_CELLS * cell
    mids, dirs, widths = [], [], []
    for width, mid, normal in gaps(obstacles, narrow):
        if width > 2 * radius:
            mids.append(mid)
            dirs.append(normal)
            widths.append(width)
    if not mids:
        return []
    mids, dirs = np.array(mids), np.array(dirs)
    # Long enough to reach where the grid sees again, but a third obstacle close by may
    # cut a long one short: try shorter ones for the gaps a longer one could not cross.
    found: dict[int, Portal] = {}
    for cells in HALF_LENGTH_CELLS:
        todo = np.array([k for k in range(len(mids)) if k not in found], dtype=np.int64)
        if not len(todo):
            break
        half = cells * cell
        a, b_ = mids[todo] - half * dirs[todo], mids[todo] + half * dirs[todo]
        clear = ((obstacles.segments_distance(a, b_, radius)[0] > radius)
                 & inside_bounds(bounds, a, radius) & inside_bounds(bounds, b_, radius))
        for k in np.nonzero(clear)[0]:
            found[int(todo[k])] = Portal(np.array([a[k], b_[k]]), widths[todo[k]])
    return [found[k] for k in sorted(found)]


def exact_links(field: DistanceField, obstacles: Obstacles2D, bounds, points: np.ndarray,
                radius: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Links from each of the (p, 2) ``points`` to nearby free cells, checked with exact distances.

    Returns (point index, cell index, length) per link. The bounds are convex,
    so a segment whose ends keep the disc inside them keeps it inside throughout.
    """
    g = field.grid
    points = np.asarray(points, dtype=float).reshape(-1, 2)
    ci, cj = g.cell_of(points)
    r = np.arange(-LINK_CELLS, LINK_CELLS + 1)
    di, dj = np.meshgrid(r, r, indexing="ij")
    i = (ci[:, None] + di.ravel()[None, :]).ravel()
    j = (cj[:, None] + dj.ravel()[None, :]).ravel()
    which = np.repeat(np.arange(len(points)), di.size)
    keep = (i >= 0) & (i < g.nx) & (j >= 0) & (j < g.ny)
    i, j, which = i[keep], j[keep], which[keep]
    keep = field.values[i, j] > radius
    i, j, which = i[keep], j[keep], which[keep]
    centres = g.centre_of(i, j)
    clear = obstacles.segments_distance(points[which], centres, radius)[0] > radius
    clear &= inside_bounds(bounds, centres, radius)
    length = np.hypot(*(centres - points[which]).T)
    return which[clear], (i * g.ny + j)[clear], length[clear]
