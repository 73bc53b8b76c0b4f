"""The narrowest passage of a task: the widest disc that can still get from spawn to goal, exactly.

A disc of radius r fits wherever its centre keeps r from every footprint and
from the bounds' edges. As r grows, the footprints grown by r (and the outside
of the bounds, grown inwards) start to touch, pair by pair, each pair at half
its gap. Spawn and goal become separated exactly when the grown pieces that
touch form a closed chain with the spawn on one side and the goal on the other:
a cycle whose winding number about the spawn differs from that about the goal.

So: sort every gap narrower than the ends' own clearance, join the pieces in
that order (Kruskal), and carry along each join the angle that a curve through
the two pieces (piece anchor -> touching point -> piece anchor, inside the
grown pieces) sweeps about the spawn minus the angle about the goal. A union-find
keeps these angles as potentials; the first join that closes a cycle with a
non-zero total (a multiple of 2 pi) separates the ends, and half its gap is the
bottleneck radius. Without such a join, the ends' clearance is. Exact up to the
gaps' own floating-point distances (GEOS for polygons, closed forms for discs).
"""

from __future__ import annotations

import math

import numpy as np
import shapely

from worldgen.feasibility.geometry import Obstacles2D

__all__ = ["narrowest_passage"]


def narrowest_passage(obstacles: Obstacles2D, bounds, start, goal) -> float:
    """Diameter (m) of the widest disc that can travel from ``start`` to ``goal`` (0 if none fits at either)."""
    (x0, y0), (x1, y1) = bounds
    ends = np.array([start, goal], dtype=float).reshape(2, 2)
    box_gap = np.minimum(np.minimum(ends[:, 0] - x0, x1 - ends[:, 0]), np.minimum(ends[:, 1] - y0, y1 - ends[:, 1]))
    obs_gap = obstacles.points_distance(ends)[0]
    limit = float(np.min(np.minimum(box_gap, obs_gap)))
    if limit <= 0:
        return 0.0
    joins = _joins(obstacles, bounds, 2 * limit)
    s, g = ends
    n = len(obstacles) + 4
    parent = list(range(n))
    potential = [0.0] * n  # angle from a piece to its parent

    def find(u: int) -> tuple[int, float]:
        total = 0.0
        path = []
        while parent[u] != u:
            path.append(u)
            total += potential[u]
            u = parent[u]
        # Compress: every piece on the way points at the root with its summed angle.
        acc = total
        for v in path:
            step = potential[v]
            parent[v], potential[v] = u, acc
            acc -= step
        return u, total

    for gap, a, b, anchor_a, touch, anchor_b in joins:
        if gap >= 2 * limit:
            break
        turn = (_sweep(anchor_a, touch, s) + _sweep(touch, anchor_b, s)) - (
            _sweep(anchor_a, touch, g) + _sweep(touch, anchor_b, g))
        ra, pa = find(a)
        rb, pb = find(b)
        if ra == rb:
            if abs(pa + turn - pb) > math.pi:
                return max(gap, 0.0)
            continue
        # potential[u] = phi(u) - phi(parent); the join asks phi(b) = phi(a) + turn.
        parent[rb] = ra
        potential[rb] = pa + turn - pb
    return 2 * limit


def _sweep(a, b, z) -> float:
    """Angle (rad) the segment from ``a`` to ``b`` sweeps about ``z`` (counter-clockwise positive)."""
    ax, ay = a[0] - z[0], a[1] - z[1]
    bx, by = b[0] - z[0], b[1] - z[1]
    return math.atan2(ax * by - ay * bx, ax * bx + ay * by)


def _joins(obstacles: Obstacles2D, bounds, reach: float):
    """(gap, piece a, piece b, anchor a, touching point, anchor b) for every pair of pieces closer than
    ``reach``, sorted by gap. Pieces: the obstacles, then the outside of the bounds beyond each edge
    (left, bottom, right, top), each a half-plane."""
    (x0, y0), (x1, y1) = bounds
    n = len(obstacles)
    nd = obstacles.n_discs
    far = (x1 - x0) + (y1 - y0) + 1.0
    xc, yc = (x0 + x1) / 2, (y0 + y1) / 2
    anchors = [tuple(obstacles.disc_xy[i]) for i in range(nd)]
    anchors += [tuple(ring.mean(axis=0)) for ring in obstacles.poly_vertices]
    anchors += [(x0 - far, yc), (xc, y0 - far), (x1 + far, yc), (xc, y1 + far)]
    out = []
    # Neighbouring half-planes always meet, at the bounds' corners.
    corners = ((x0, y0), (x1, y0), (x1, y1), (x0, y1))
    for k in range(4):
        a, b = n + k, n + (k + 1) % 4
        out.append((0.0, a, b, anchors[a], corners[k], anchors[b]))
    boxes = obstacles.boxes
    # Obstacles and the bounds: the gap between the obstacle's extreme point and the edge.
    for k, (axis, sign, edge) in enumerate(((0, -1, x0), (1, -1, y0), (0, 1, x1), (1, 1, y1))):
        extreme = boxes[:, axis] if sign < 0 else boxes[:, axis + 2]
        gap = (extreme - edge) * -sign
        for i in np.flatnonzero(gap < reach):
            point = _extreme_point(obstacles, int(i), axis, sign)
            touch = list(point)
            touch[axis] = edge - sign * gap[i] / 2 if gap[i] > 0 else point[axis]
            out.append((float(gap[i]), int(i), n + k, anchors[i], tuple(touch), anchors[n + k]))
    # Obstacle pairs: candidates by their boxes, then exact gaps and the midpoint of the closest pair.
    if n > 1:
        lo, hi = boxes[:, :2], boxes[:, 2:]
        envelopes = shapely.box(lo[:, 0], lo[:, 1], hi[:, 0], hi[:, 1])
        tree = shapely.STRtree(envelopes)
        grown = shapely.box(lo[:, 0] - reach, lo[:, 1] - reach, hi[:, 0] + reach, hi[:, 1] + reach)
        qi, ti = tree.query(grown)
        keep = qi < ti
        for i, j, gap, touch in zip(*_pair_gaps(obstacles, qi[keep], ti[keep])):
            if gap < reach:
                out.append((gap, int(i), int(j), anchors[i], touch, anchors[j]))
    out.sort(key=lambda e: (e[0], e[1], e[2]))
    return out


def _extreme_point(obstacles: Obstacles2D, i: int, axis: int, sign: int) -> tuple[float, float]:
    """The point of footprint ``i`` farthest along ``sign`` on ``axis``."""
    nd = obstacles.n_discs
    if i < nd:
        c = obstacles.disc_xy[i].copy()
        c[axis] += sign * obstacles.disc_r[i]
        return (float(c[0]), float(c[1]))
    ring = obstacles.poly_vertices[i - nd]
    k = int(np.argmax(sign * ring[:, axis]))
    return (float(ring[k, 0]), float(ring[k, 1]))


def _pair_gaps(obstacles: Obstacles2D, i: np.ndarray, j: np.ndarray):
    """(i, j, gap, touching point) per pair of obstacle ids: the exact gap between the footprints
    (negative or 0 where they overlap) and the point where their grown copies first touch."""
    shapes = np.array([shapely.Point(c) for c in obstacles.disc_xy]
                      + [shapely.Polygon(r) for r in obstacles.poly_vertices], dtype=object)
    radius = np.concatenate([obstacles.disc_r, np.zeros(len(obstacles.poly_vertices))])
    gaps, touches = [], []
    if len(i):
        lines = shapely.shortest_line(shapes[i], shapes[j])
        coords = shapely.get_coordinates(lines).reshape(-1, 2, 2)
    else:
        coords = np.zeros((0, 2, 2))
    for k in range(len(i)):
        p, q = coords[k]  # nearest points of the two cores (a disc's core is its centre)
        d = float(math.hypot(q[0] - p[0], q[1] - p[1]))
        ra, rb = radius[i[k]], radius[j[k]]
        gap = d - ra - rb
        u = (q - p) / d if d > 0 else np.zeros(2)
        if gap > 0:  # the midpoint of the footprints' nearest points, where the grown copies meet
            touch = (p + ra * u + q - rb * u) / 2
        else:  # a point of both footprints
            touch = p + min(ra, d) * u
        gaps.append(gap)
        touches.append((float(touch[0]), float(touch[1])))
    return i, j, gaps, touches
