"""A local visibility graph: the shortest path among the obstacles near a reference path.

The fallback when tightening (:mod:`worldgen.feasibility.taut`) gives up. The
free space of a disc of radius R is the floor minus every footprint grown by R;
a grown disc is a circle and a grown convex polygon is its offset edges joined
by arcs round its corners. Each of those outlines near the reference path is
replaced by a polygon that circumscribes it (vertices a hair outside, every
edge tangent to or outside the true outline), so any straight segment between
two vertices that keeps R from every footprint (checked exactly) is free, and
the shortest path over those segments (Dijkstra) is a safe path whose length
exceeds the true shortest among those obstacles by at most the circumscribed
arcs' excess, tan(s/2)/(s/2) - 1 of the arc length for arc pieces of angle s.
"""

from __future__ import annotations

import math
from typing import Optional

import numpy as np
from scipy.sparse import coo_matrix
from scipy.sparse.csgraph import dijkstra

from worldgen.feasibility.geometry import Obstacles2D, inside_bounds

__all__ = ["ARC_PIECE", "local_shortest", "encloses"]

#: Largest angle (rad) of one circumscribing piece of an arc: the path's arc
#: parts come out at most 1.3 % long (before tightening runs again on the result).
ARC_PIECE = math.pi / 8
#: Vertices sit this much outside the grown outline, so segments along an offset
#: edge pass the exact check that keeps strictly more than R.
_OUTSIDE = 1e-6


def _arc_points(centre: np.ndarray, r: float, start: float, sweep: float) -> np.ndarray:
    """Vertices of a polyline circumscribing the arc of radius ``r`` from angle ``start`` over ``sweep``."""
    pieces = max(1, math.ceil(sweep / ARC_PIECE - 1e-9))
    step = sweep / pieces
    ends = np.array([start, start + sweep])
    mids = start + (np.arange(pieces) + 0.5) * step
    ang = np.concatenate([ends[:1], mids, ends[1:]])
    dist = np.concatenate([[r], np.full(pieces, r / math.cos(step / 2)), [r]]) + _OUTSIDE
    return centre + dist[:, None] * np.stack([np.cos(ang), np.sin(ang)], axis=1)


def _outline(obstacles: Obstacles2D, k: int, r: float) -> np.ndarray:
    """(m, 2) vertices circumscribing obstacle ``k`` grown by ``r``, in counter-clockwise order."""
    if k < obstacles.n_discs:
        return _arc_points(obstacles.disc_xy[k], obstacles.disc_r[k] + r, 0.0, 2 * math.pi)[:-1]
    corners = obstacles.corners(k)  # counter-clockwise
    edges = np.roll(corners, -1, axis=0) - corners
    normals = np.stack([edges[:, 1], -edges[:, 0]], axis=1)  # outward for a CCW ring
    out_angle = np.arctan2(normals[:, 1], normals[:, 0])
    pts = []
    for i, c in enumerate(corners):
        a_in, a_out = out_angle[i - 1], out_angle[i]  # normals of the edges meeting at corner i
        sweep = (a_out - a_in) % (2 * math.pi)
        pts.append(_arc_points(c, r, a_in, sweep))
    return np.concatenate(pts)


def local_shortest(obstacles: Obstacles2D, ref: np.ndarray, radius: float, bounds,
                   reach: float) -> Optional[np.ndarray]:
    """The shortest path from ``ref[0]`` to ``ref[-1]`` over the outlines of obstacles within
    ``reach`` of the polyline ``ref`` (every segment checked against every obstacle), or None."""
    start, goal = np.asarray(ref[0], float), np.asarray(ref[-1], float)
    # Samples along ref, not its segments' boxes: a long diagonal's box holds half the room.
    seg = np.hypot(*np.diff(ref, axis=0).T)
    along = np.concatenate([[0.0], np.cumsum(seg)])
    t = np.linspace(0.0, along[-1], max(2, int(along[-1] / (reach / 2)) + 2))
    samples = np.stack([np.interp(t, along, ref[:, 0]), np.interp(t, along, ref[:, 1])], axis=1)
    near = np.nonzero(obstacles.near(samples, samples, reach + radius).any(axis=0))[0]
    rings = [_outline(obstacles, int(k), radius) for k in near]
    if rings:
        ring_pts = np.concatenate(rings)
        prev = np.concatenate([np.roll(r, 1, axis=0) for r in rings])
        nxt = np.concatenate([np.roll(r, -1, axis=0) for r in rings])
    else:
        ring_pts = prev = nxt = np.zeros((0, 2))
    inside = inside_bounds(bounds, ring_pts, radius)
    # Only obstacles within the radius matter: a bounded query, not a distance to everything.
    free = inside & (obstacles.segments_distance(ring_pts, ring_pts, radius)[0] > radius) if len(ring_pts) else inside
    pts = np.vstack([start, goal, ring_pts[free]])
    prev = np.vstack([start, goal, prev[free]])
    nxt = np.vstack([start, goal, nxt[free]])
    n = len(pts)
    i, j = np.triu_indices(n, k=1)
    d = pts[j] - pts[i]

    to_prev, to_next = prev - pts, nxt - pts

    def tangent(at):
        # A shortest path bends only round a vertex whose outline neighbours lie on one side of it.
        p, q = to_prev[at], to_next[at]
        sa = d[:, 0] * p[:, 1] - d[:, 1] * p[:, 0]
        sb = d[:, 0] * q[:, 1] - d[:, 1] * q[:, 0]
        return (at < 2) | (sa * sb >= -1e-15)

    keep = tangent(i) & tangent(j)
    i, j = i[keep], j[keep]
    clear = obstacles.segments_distance(pts[i], pts[j], radius)[0] > radius
    i, j = i[clear], j[clear]
    w = np.hypot(*(pts[j] - pts[i]).T)
    graph = coo_matrix((w, (i, j)), shape=(n, n)).tocsr()
    dist, pred = dijkstra(graph, directed=False, indices=0, return_predecessors=True)
    if not np.isfinite(dist[1]):
        return None
    chain = [1]
    while chain[-1] != 0:
        chain.append(int(pred[chain[-1]]))
    return pts[chain[::-1]]


def encloses(path: np.ndarray, other: np.ndarray, obstacles: Obstacles2D) -> bool:
    """True when the two paths (same ends) pass some obstacle on different sides.

    The loop ``path`` then ``other`` reversed winds round every obstacle that lies
    between them; an obstacle is judged by one of its points (a disc's centre, a
    polygon's first corner), which lies inside the loop exactly when the whole
    obstacle does, since neither path enters it.
    """
    if len(obstacles) == 0:
        return False
    loop = np.vstack([path, other[::-1]])
    a, b = loop, np.roll(loop, -1, axis=0)
    lo, hi = loop.min(axis=0), loop.max(axis=0)
    probes = np.vstack([obstacles.disc_xy, np.array([r[0] for r in obstacles.poly_vertices]).reshape(-1, 2)])
    inside_box = np.all((probes >= lo) & (probes <= hi), axis=1)
    probes = probes[inside_box]
    if not len(probes):
        return False
    # Winding number by crossings of the horizontal ray to +x (the even-odd test is not enough
    # for a loop that may cross itself).
    ay, by = a[None, :, 1] - probes[:, None, 1], b[None, :, 1] - probes[:, None, 1]
    ax, bx = a[None, :, 0] - probes[:, None, 0], b[None, :, 0] - probes[:, None, 0]
    cross = ax * by - ay * bx
    up = (ay <= 0) & (by > 0) & (cross > 0)
    down = (ay > 0) & (by <= 0) & (cross < 0)
    winding = up.sum(axis=1) - down.sum(axis=1)
    return bool(np.any(winding != 0))
