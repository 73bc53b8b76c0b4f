"""Pull a safe path taut: wrap obstacles at exactly the inflation radius.

The shortest path for a disc of radius R among convex obstacles is made of
straight tangent segments and arcs of the obstacles grown by R. A grown disc is
a circle; a grown convex polygon is bounded by arcs of radius R around its
corners joined by its offset edges, which are exactly the outer tangents of
consecutive corner circles. So the taut path is a chain of *anchors*, each a
circle (centre, radius) passed on a known side, joined by closed-form tangents.

Starting from the anchors that the grid path's turns point at, the chain is
settled (an anchor that the path would have to wrap backwards is not needed
and is dropped), written out as a polyline whose arc pieces circumscribe the
circles (so the polyline never cuts into a grown obstacle), and checked
exactly against every footprint; an obstacle it still cuts becomes a new
anchor, on the side where the safe reference path passed it. The result stays
in the reference path's homotopy class and is locally shortest in it.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Optional

import numpy as np

from worldgen.feasibility.geometry import Obstacles2D, point_segment_distance

__all__ = ["Anchor", "tighten", "ARC_STEP"]

#: Largest angle (rad) of one polyline piece along an arc; the circumscribed
#: polyline is longer than the arc by tan(a/2)/(a/2) - 1 = 0.33 % of the arc.
ARC_STEP = 0.2
#: Settling and repair rounds before giving up on tightening (the caller then
#: keeps the safe reference path).
_MAX_ROUNDS = 80


@dataclass(frozen=True)
class Anchor:
    """A circle passed counter-clockwise (``side`` +1, obstacle on the left) or clockwise (-1).

    ``key`` = (obstacle id, corner index or -1) identifies it.
    """

    x: float
    y: float
    radius: float
    side: int
    key: tuple[int, int]

    @property
    def centre(self) -> np.ndarray:
        return np.array([self.x, self.y])


def tighten(obstacles: Obstacles2D, ref: np.ndarray, inflation: float, bounds, near: float) -> Optional[np.ndarray]:
    """The taut version of the free polyline ``ref`` (k, 2), or None if it cannot be made.

    ``inflation`` is the radius every segment must keep from every footprint
    (the caller adds its safety margin); ``near`` is how far from an obstacle a
    turn of ``ref`` may lie and still be blamed on it.
    """
    start, goal = ref[0], ref[-1]
    anchors = _initial(obstacles, ref, inflation, near)
    (x0, y0), (x1, y1) = bounds
    lo = np.array([x0, y0]) + inflation
    hi = np.array([x1, y1]) - inflation
    for _ in range(_MAX_ROUNDS):
        anchors = _settle(start, goal, anchors)
        if anchors is None:
            return None
        poly, owner = _polyline(start, goal, anchors)
        if np.any(poly < lo - 1e-9) or np.any(poly > hi + 1e-9):
            return None
        dist, which = obstacles.segments_distance(poly[:-1], poly[1:], inflation)
        bad = np.nonzero(dist < inflation * (1 - 1e-9) - 1e-9)[0]
        if not len(bad):
            return poly
        s = int(bad[0])
        a, b = poly[s], poly[s + 1]
        new = _anchor_for(obstacles, int(which[s]), a, b, ref, inflation)
        kind, k, half = owner[s]
        at = k if kind == "line" or half == 0 else k + 1
        if any(x.key == new.key for x in anchors[max(at - 1, 0):at + 1]):
            return None
        anchors = anchors[:at] + [new] + anchors[at:]
    return None


def _circle(obstacles: Obstacles2D, obstacle: int, near_to: np.ndarray, side: int, inflation: float) -> Anchor:
    """The anchor of ``obstacle``: its grown disc, or the grown corner chosen by ``near_to``."""
    if obstacle < obstacles.n_discs:
        c = obstacles.disc_xy[obstacle]
        return Anchor(float(c[0]), float(c[1]), float(obstacles.disc_r[obstacle] + inflation), side, (obstacle, -1))
    corners = obstacles.corners(obstacle)
    k = int(np.argmin(np.hypot(*(corners - near_to).T)))
    return Anchor(float(corners[k, 0]), float(corners[k, 1]), float(inflation), side, (obstacle, k))


def _initial(obstacles: Obstacles2D, ref: np.ndarray, inflation: float, near: float) -> list[Anchor]:
    """Anchors at the turns of ``ref``: the nearest obstacle of each turning point, on the inside."""
    if len(ref) < 3 or len(obstacles) == 0:
        return []
    inner = ref[1:-1]
    turn = _cross(inner - ref[:-2], ref[2:] - inner)
    dist, which = obstacles.points_distance(inner)
    out: list[Anchor] = []
    for p, t, d, o in zip(inner, turn, dist, which):
        if o < 0 or d > inflation + near or abs(t) < 1e-12:
            continue
        a = _circle(obstacles, int(o), p, 1 if t > 0 else -1, inflation)
        if not out or out[-1].key != a.key:
            out.append(a)
    return out


def _anchor_for(obstacles: Obstacles2D, obstacle: int, a: np.ndarray, b: np.ndarray, ref: np.ndarray,
                inflation: float) -> Anchor:
    """The anchor that keeps segment ``ab`` off ``obstacle``, on the side ``ref`` passes it."""
    if obstacle < obstacles.n_discs:
        side = _side(obstacles.disc_xy[obstacle], ref)
        return _circle(obstacles, obstacle, a, side, inflation)
    corners = obstacles.corners(obstacle)
    d = point_segment_distance(corners[:, None, :], ref[None, :-1], ref[None, 1:]).min(axis=1)
    side = _side(corners[int(np.argmin(d))], ref)
    u = (b - a) / max(np.hypot(*(b - a)), 1e-300)
    # The corner that reaches farthest across the segment, towards the path's side.
    k = int(np.argmin(side * _cross(np.broadcast_to(u, corners.shape), corners - a)))
    return Anchor(float(corners[k, 0]), float(corners[k, 1]), float(inflation), side, (obstacle, k))


def _side(p: np.ndarray, ref: np.ndarray) -> int:
    """+1 if point ``p`` lies left of the polyline ``ref`` where it passes closest, else -1."""
    a, b = ref[:-1], ref[1:]
    ab = b - a
    den = np.maximum(np.einsum("ij,ij->i", ab, ab), 1e-300)
    t = np.clip(np.einsum("ij,ij->i", p - a, ab) / den, 0.0, 1.0)
    d = np.hypot(*(a + t[:, None] * ab - p).T)
    m = int(np.argmin(d))
    interior_vertex = (t[m] <= 0.0 and m > 0) or (t[m] >= 1.0 and m < len(a) - 1)
    if interior_vertex:
        v = m if t[m] <= 0.0 else m + 1
        turn = _cross(ref[v] - ref[v - 1], ref[v + 1] - ref[v])
        if abs(turn) > 1e-12:
            return -1 if turn > 0 else 1  # nearest to a corner: on its outer side
    return 1 if _cross(ab[m], p - a[m]) > 0 else -1


def _cross(u, v):
    return u[..., 0] * v[..., 1] - u[..., 1] * v[..., 0]


def _tangent(c1: np.ndarray, rs1: float, c2: np.ndarray, rs2: float):
    """Points (p1, p2) of the segment leaving circle 1 and arriving on circle 2.

    ``rs`` = radius x side; a point is a circle of radius 0. None where the
    circles leave no such tangent (one inside the other, or crossing circles
    passed on opposite sides).
    """
    d = c2 - c1
    length = math.hypot(d[0], d[1])
    k = rs1 - rs2
    if length <= abs(k) + 1e-12:
        return None
    dh = d / length
    a = k / length
    w = a * dh - math.sqrt(max(1.0 - a * a, 0.0)) * np.array([-dh[1], dh[0]])
    return c1 + rs1 * w, c2 + rs2 * w


def _settle(start, goal, anchors: list[Anchor]) -> Optional[list[Anchor]]:
    """Drop anchors until every tangent exists and every arc turns the right way (< pi)."""
    anchors = list(anchors)
    while True:
        tangents = _tangents(start, goal, anchors)
        if isinstance(tangents, int):  # the pair (tangents - 1, tangents) in the full chain has none
            k = tangents
            prev = anchors[k - 1] if k >= 1 else None
            nxt = anchors[k] if k < len(anchors) else None
            if prev is not None and nxt is not None and prev.side == nxt.side:
                # One circle inside the other: the smaller adds nothing.
                del anchors[k - 1 if prev.radius < nxt.radius else k]
                continue
            if prev is not None and nxt is not None and prev.key == nxt.key:
                del anchors[k]
                continue
            return None
        worst, worst_phi = -1, math.pi + 1e-9
        for i, anchor in enumerate(anchors):
            phi = _arc_angle(anchor, tangents[i][1], tangents[i + 1][0])
            if phi > worst_phi:
                worst, worst_phi = i, phi
        if worst < 0:
            return anchors
        del anchors[worst]


def _tangents(start, goal, anchors: list[Anchor]):
    """Tangent segments along the chain, or the index of the first missing one."""
    centres = [start] + [a.centre for a in anchors] + [goal]
    rs = [0.0] + [a.radius * a.side for a in anchors] + [0.0]
    out = []
    for k in range(len(centres) - 1):
        t = _tangent(centres[k], rs[k], centres[k + 1], rs[k + 1])
        if t is None:
            return k
        out.append(t)
    return out


def _arc_angle(anchor: Anchor, p_in: np.ndarray, p_out: np.ndarray) -> float:
    """Angle swept from ``p_in`` to ``p_out`` around the anchor in its direction, in [0, 2 pi)."""
    t_in = math.atan2(p_in[1] - anchor.y, p_in[0] - anchor.x)
    t_out = math.atan2(p_out[1] - anchor.y, p_out[0] - anchor.x)
    phi = (anchor.side * (t_out - t_in)) % (2 * math.pi)
    return 0.0 if phi > 2 * math.pi - 1e-12 else phi


def _polyline(start, goal, anchors: list[Anchor]):
    """The chain as points, with the owner of each segment: ("line", k, 0) or ("arc", k, half)."""
    tangents = _tangents(start, goal, anchors)
    pts = [np.asarray(start, dtype=float)]
    owner = []
    for k, anchor in enumerate(anchors):
        p_in, p_out = tangents[k][1], tangents[k + 1][0]
        pts.append(p_in)
        owner.append(("line", k, 0))
        phi = _arc_angle(anchor, p_in, p_out)
        if phi <= 1e-12:
            continue
        n = max(1, math.ceil(phi / ARC_STEP))
        step = phi / n
        t_in = math.atan2(p_in[1] - anchor.y, p_in[0] - anchor.x)
        reach = anchor.radius / math.cos(step / 2)
        for j in range(1, n + 1):
            t = t_in + anchor.side * (j - 0.5) * step
            pts.append(anchor.centre + reach * np.array([math.cos(t), math.sin(t)]))
            owner.append(("arc", k, 0 if j <= n / 2 else 1))
        pts.append(p_out)
        owner.append(("arc", k, 1))
    pts.append(np.asarray(goal, dtype=float))
    owner.append(("line", len(anchors), 0))
    return np.array(pts), owner
