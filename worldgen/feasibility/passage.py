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
    gap, a, b, anchor_a, touch, anchor_b = _joins(obstacles, bounds, 2 * limit)
    s, g = ends
    turn = (_sweep(anchor_a, touch, s) + _sweep(touch, anchor_b, s)) - (
        _sweep(anchor_a, touch, g) + _sweep(touch, anchor_b, g))
    n = len(obstacles) + 4
    parent = list(range(n))
    potential = [0.0] * n  # potential[u] = phi(u) - phi(parent of u)

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

    for k in range(len(gap)):
        ra, pa = find(int(a[k]))
        rb, pb = find(int(b[k]))
        if ra == rb:
            if abs(pa + turn[k] - pb) > math.pi:
                return max(float(gap[k]), 0.0)
            continue
        parent[rb] = ra  # the join asks phi(b) = phi(a) + turn
        potential[rb] = pa + turn[k] - pb
    return 2 * limit


def _sweep(a: np.ndarray, b: np.ndarray, z: np.ndarray) -> np.ndarray:
    """(m,) angle (rad) each segment a[i] -> b[i] sweeps about the point ``z`` (counter-clockwise positive)."""
    ax, ay = a[:, 0] - z[0], a[:, 1] - z[1]
    bx, by = b[:, 0] - z[0], b[:, 1] - z[1]
    return np.arctan2(ax * by - ay * bx, ax * bx + ay * by)


def _joins(obstacles: Obstacles2D, bounds, reach: float):
    """Arrays (gap, piece a, piece b, anchor a, touching point, anchor b) of every pair of pieces closer
    than ``reach``, sorted by gap. Pieces: the obstacles, then the outside of the bounds beyond each edge
    (left, bottom, right, top), each a half-plane."""
    (x0, y0), (x1, y1) = bounds
    n = len(obstacles)
    far = (x1 - x0) + (y1 - y0) + 1.0
    xc, yc = (x0 + x1) / 2, (y0 + y1) / 2
    starts = obstacles.edge_start[:-1]
    counts = np.diff(obstacles.edge_start)
    means = (np.add.reduceat(obstacles.edge_a, starts) / counts[:, None]) if len(starts) else np.zeros((0, 2))
    anchors = np.vstack([obstacles.disc_xy.reshape(-1, 2), means,
                         [(x0 - far, yc), (xc, y0 - far), (x1 + far, yc), (xc, y1 + far)]])
    gaps, pa, pb, touches = [np.zeros(4)], [n + np.arange(4)], [n + (np.arange(4) + 1) % 4], []
    # Neighbouring half-planes always meet, at the bounds' corners.
    touches.append(np.array([(x0, y0), (x1, y0), (x1, y1), (x0, y1)], dtype=float))
    boxes = obstacles.boxes
    lo, hi = extreme_points(obstacles)
    # Obstacles and the bounds: the gap between the obstacle's extreme point and the edge.
    for k, (axis, low, edge) in enumerate(((0, True, x0), (1, True, y0), (0, False, x1), (1, False, y1))):
        point = lo[axis] if low else hi[axis]
        gap = point[:, axis] - edge if low else edge - point[:, axis]
        near = np.flatnonzero(gap < reach)
        touch = point[near].copy()
        shift = np.where(gap[near] > 0, gap[near] / 2, 0.0)
        touch[:, axis] = np.where(gap[near] > 0, edge + (shift if low else -shift), touch[:, axis])
        gaps.append(gap[near])
        pa.append(near)
        pb.append(np.full(len(near), n + k))
        touches.append(touch)
    # Obstacle pairs: candidates by their boxes, then exact gaps and where their grown copies first touch.
    if n > 1:
        env_lo, env_hi = boxes[:, :2], boxes[:, 2:]
        tree = shapely.STRtree(shapely.box(env_lo[:, 0], env_lo[:, 1], env_hi[:, 0], env_hi[:, 1]))
        qi, ti = tree.query(shapely.box(env_lo[:, 0] - reach, env_lo[:, 1] - reach,
                                        env_hi[:, 0] + reach, env_hi[:, 1] + reach))
        keep = qi < ti
        i, j = qi[keep], ti[keep]
        gap, touch = _pair_gaps(obstacles, i, j)
        close = gap < reach
        gaps.append(gap[close])
        pa.append(i[close])
        pb.append(j[close])
        touches.append(touch[close])
    gap, a, b = np.concatenate(gaps), np.concatenate(pa), np.concatenate(pb)
    touch = np.concatenate(touches)
    order = np.lexsort((b, a, gap))
    a, b = a[order], b[order]
    return gap[order], a, b, anchors[a], touch[order], anchors[b]


def extreme_points(obstacles: Obstacles2D) -> tuple[list[np.ndarray], list[np.ndarray]]:
    """Per axis (x, y): the (N, 2) point of each footprint lowest and highest along it."""
    lows, highs = [], []
    verts, owner = obstacles.edge_a, obstacles.edge_owner
    for axis in (0, 1):
        step = np.zeros((len(obstacles.disc_r), 2))
        step[:, axis] = obstacles.disc_r
        found = []
        for sign in (1.0, -1.0):
            # Sorted by polygon, then by the coordinate: each polygon's first row is its extreme vertex.
            order = np.lexsort((sign * verts[:, axis], owner))
            first = order[np.r_[True, owner[order][1:] != owner[order][:-1]]] if len(order) else order
            found.append(np.vstack([obstacles.disc_xy - sign * step, verts[first]]))
        lows.append(found[0])
        highs.append(found[1])
    return lows, highs


def _pair_gaps(obstacles: Obstacles2D, i: np.ndarray, j: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(gap (m,), touching point (m, 2)) per pair of obstacle ids: the exact gap between the footprints
    (negative or 0 where they overlap) and the point where their grown copies first touch (a point of
    both where they overlap)."""
    if len(i) == 0:
        return np.zeros(0), np.zeros((0, 2))
    shapes = obstacles.cores
    radius = np.concatenate([obstacles.disc_r, np.zeros(len(obstacles.poly_vertices))])
    coords = shapely.get_coordinates(shapely.shortest_line(shapes[i], shapes[j])).reshape(-1, 2, 2)
    p, q = coords[:, 0], coords[:, 1]  # nearest points of the two cores (a disc's core is its centre)
    d = np.hypot(*(q - p).T)
    ra, rb = radius[i], radius[j]
    gap = d - ra - rb
    u = (q - p) / np.where(d > 0, d, 1.0)[:, None]
    apart = ((p + ra[:, None] * u) + (q - rb[:, None] * u)) / 2  # midway between the footprints
    overlap = p + np.minimum(ra, d)[:, None] * u  # in both: discs come before polygons in the ids
    return gap, np.where((gap > 0)[:, None], apart, overlap)
