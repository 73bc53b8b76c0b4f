"""An exact reference for shortest paths and narrowest passages, written here, sharing no code with worldgen.

The robot is a disc of radius R; its centre may go wherever it keeps at least R
from every footprint and from the bounds' edges. The free space is the bounds
shrunk by R minus every footprint grown by R. Here the grown footprints become
polygons with shapely's buffer: *inscribed* in the true rounded shapes (vertices
on the arcs) or *circumscribed* about them (buffered by R / cos(half a step), so
every edge of a round join touches the arc). The shortest path among polygons
runs straight between polygon vertices that see each other, so Dijkstra over
that visibility graph gives it; the inscribed answer can only be shorter than the
truth and the circumscribed one only longer: together they bracket it.
"""

from __future__ import annotations

import math
from typing import Optional

import numpy as np
import shapely
from scipy.sparse import coo_matrix
from scipy.sparse.csgraph import dijkstra

#: Segments per quarter circle of the polygons round the arcs.
QUAD_SEGS = 16
#: Segments shorter than this inside the obstacles still count as seeing each other: tangents
#: graze the polygons.
GRAZE = 1e-7


def grown(footprints, radius: float, bounds, outer: bool):
    """The blocked region for a disc of ``radius``: every footprint grown, and the outside of the bounds."""
    # Outer: every arc's radius divided by cos(half a step), so each edge of a round join touches it.
    k = 1 / math.cos(math.pi / (4 * QUAD_SEGS)) if outer else 1.0
    shapes = [shapely.Point(fp.centre).buffer((fp.radius + radius) * k, quad_segs=QUAD_SEGS) if fp.is_disc
              else fp.polygon.buffer(radius * k, quad_segs=QUAD_SEGS) for fp in footprints]
    (x0, y0), (x1, y1) = bounds
    inner = shapely.box(x0 + radius, y0 + radius, x1 - radius, y1 - radius)
    outside = shapely.box(x0 - 99, y0 - 99, x1 + 99, y1 + 99).difference(inner)
    return shapely.union_all(shapes + [outside])


def shortest(footprints, radius: float, bounds, start, goal, outer: bool) -> float:
    """Length of the shortest path among the polygonal obstacles (inf where there is none)."""
    blocked = grown(footprints, radius, bounds, outer)
    core = blocked.buffer(-GRAZE)  # the inside proper: a segment along an edge is free
    shapely.prepare(core)
    start, goal = np.asarray(start, float), np.asarray(goal, float)
    if core.contains(shapely.Point(start)) or core.contains(shapely.Point(goal)):
        return math.inf
    pts, prev, nxt = [start, goal], [start, goal], [start, goal]
    for poly in getattr(blocked, "geoms", [blocked]):
        for ring in [poly.exterior, *poly.interiors]:
            c = np.asarray(ring.coords)[:-1]
            pts += list(c)
            prev += list(np.roll(c, 1, axis=0))
            nxt += list(np.roll(c, -1, axis=0))
    n = len(pts)
    pts, prev, nxt = np.array(pts), np.array(prev), np.array(nxt)
    ends = np.zeros(n, dtype=bool)
    ends[:2] = True
    i, j = np.triu_indices(n, k=1)
    d = pts[j] - pts[i]

    def side(q, at):
        v = q - pts[at]
        return d[:, 0] * v[:, 1] - d[:, 1] * v[:, 0]

    def tangent(at):
        # A shortest path only bends round a vertex whose two ring neighbours lie on one side of it.
        return ends[at] | (side(prev[at], at) * side(nxt[at], at) >= -1e-15)

    keep = tangent(i) & tangent(j)
    i, j = i[keep], j[keep]
    seen = ~shapely.intersects(shapely.linestrings(np.stack([pts[i], pts[j]], axis=1)), core)
    i, j = i[seen], j[seen]
    w = np.linalg.norm(pts[i] - pts[j], axis=1)
    graph = coo_matrix((w, (i, j)), shape=(n, n)).tocsr()
    return float(dijkstra(graph, directed=False, indices=0)[1])


def bracket(footprints, radius: float, bounds, start, goal, safety: float = 0.0) -> tuple[float, Optional[float]]:
    """(lower, upper) bounds of the true shortest path for a disc of ``radius``; upper is for
    ``radius + safety`` (None when the circumscribed polygons close a gap the arcs leave open)."""
    lower = shortest(footprints, radius, bounds, start, goal, outer=False)
    upper = shortest(footprints, radius + safety, bounds, start, goal, outer=True)
    return lower, (upper if math.isfinite(upper) else None)


def connected(footprints, radius: float, bounds, start, goal, outer: bool) -> bool:
    """Whether start and goal lie in one piece of the free space of a disc of ``radius``."""
    (x0, y0), (x1, y1) = bounds
    if x1 - x0 <= 2 * radius or y1 - y0 <= 2 * radius:
        return False
    free = shapely.box(x0 - 1, y0 - 1, x1 + 1, y1 + 1).difference(grown(footprints, radius, bounds, outer))
    a, b = shapely.Point(start), shapely.Point(goal)
    return any(p.contains(a) and p.contains(b) for p in getattr(free, "geoms", [free]))
