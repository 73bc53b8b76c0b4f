"""The robot's configuration space in the plane: obstacles grown by a disc, bounds shrunk by it.

The robot's centre must stay ``radius`` (inflation plus the planner's safety
margin) away from every footprint and inside the bounds shrunk by the same.
Growing a footprint by a disc (a Minkowski sum) gives a disc of the larger
radius, or a *rounded* convex polygon: its edges pushed out by ``radius`` and
joined at every vertex by an arc of radius ``radius`` about that vertex. Those
arcs are what a taut path wraps, so the configuration space is held here as
**corner circles**: one per disc, one per polygon vertex, each usable only over
its *cone* of outward normals (the angles between the normals of the vertex's
two edges; every angle for a disc). A line touching a circle at a normal inside
its cone touches the grown obstacle from outside (the grown obstacle is convex,
so such a line is a supporting line); outside the cone it cuts into it.

Indices: obstacle ids are those of :class:`~worldgen.feasibility.geometry.Obstacles2D`
(discs first); circle ids run over all corner circles, grouped by obstacle
(``first[o]`` to ``first[o + 1]``), a polygon's in counter-clockwise order.
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import cached_property
from typing import Optional

import numpy as np

from worldgen.feasibility.corners import NEAR_MARGIN, corner_circles
from worldgen.feasibility.geometry import Obstacles2D, cross, point_segment_distance, segment_segment_distance
from worldgen.feasibility.grid import SegmentGrid

__all__ = ["ConfigSpace", "TOUCH", "CONE_SLACK", "NEAR_MARGIN"]

#: Distances within this of the required one count as touching, which is allowed (the
#: required radius already carries the planner's safety margin).
TOUCH = 1e-9
#: Cone tests accept normals this far outside (sine of the angle): a line along a grown
#: edge touches both of its corner circles exactly at their cones' common boundary.
CONE_SLACK = 1e-9
#: From this many obstacles on, segments are tested through a grid rather than against every box.
GRID_FROM = 250
#: Samples along each segment in the first round of the grid's walk (half a cell apart; doubling).
WALK = 4


def _unskipped(seg: np.ndarray, o: np.ndarray, skip1, skip2) -> tuple[np.ndarray, np.ndarray]:
    """The (segment, obstacle) pairs but those naming the segment's own skipped obstacles."""
    if skip1 is None:
        return seg, o
    keep = o != skip1[seg]
    if skip2 is not None:
        keep &= o != skip2[seg]
    return seg[keep], o[keep]


def _near(lo: np.ndarray, hi: np.ndarray, reach_boxes: np.ndarray) -> np.ndarray:
    """(m, n) bool: query box m (corners ``lo``/``hi``) meets box n of ``reach_boxes`` ((n, 4), grown)."""
    return ((lo[:, None, 0] <= reach_boxes[None, :, 2]) & (hi[:, None, 0] >= reach_boxes[None, :, 0])
            & (lo[:, None, 1] <= reach_boxes[None, :, 3]) & (hi[:, None, 1] >= reach_boxes[None, :, 1]))


@dataclass(frozen=True, eq=False)
class ConfigSpace:
    """Corner circles of the grown obstacles, the shrunk bounds, and exact clearance tests.

    Per circle (C,): ``centre`` (C, 2), ``rho`` (grown radius), ``cone_a`` and
    ``cone_b`` (C, 2) the cone's first and last outward normal (counter-clockwise),
    ``cone_w`` its width (rad; 2 pi for a disc), ``full`` (disc), ``owner``
    (obstacle id), ``nxt``/``prv`` the next/previous corner of the same polygon
    (-1 for discs). Per obstacle (N,): ``first`` (N + 1,) circle offsets,
    ``hull_c`` (N, 2) and ``hull_r`` (N,) a disc containing the grown obstacle,
    ``core_r`` (N,) the radius of a disc about ``hull_c`` inside it (-1 if none);
    ``nb_ids[nb_start[o]:nb_start[o + 1]]`` the obstacles whose boxes come within
    (2 + :data:`NEAR_MARGIN`) x ``radius`` of obstacle o's: the only ones its grown
    boundary can come within ``NEAR_MARGIN x radius`` of.
    ``box`` = (x0, y0, x1, y1): where the robot's centre may be.
    """

    obstacles: Obstacles2D
    radius: float
    box: tuple[float, float, float, float]
    centre: np.ndarray
    rho: np.ndarray
    cone_a: np.ndarray
    cone_b: np.ndarray
    cone_w: np.ndarray
    owner: np.ndarray
    nxt: np.ndarray
    prv: np.ndarray
    first: np.ndarray
    hull_c: np.ndarray
    hull_r: np.ndarray
    core_r: np.ndarray
    nb_start: np.ndarray
    nb_ids: np.ndarray

    @classmethod
    def build(cls, obstacles: Obstacles2D, radius: float, bounds) -> "ConfigSpace":
        """The configuration space of a disc of ``radius`` among ``obstacles`` within ``bounds`` ((x0, y0),
        (x1, y1)): its corner circles as :mod:`~worldgen.feasibility.corners` builds them."""
        (x0, y0), (x1, y1) = bounds
        box = (x0 + radius, y0 + radius, x1 - radius, y1 - radius)
        return cls(obstacles, float(radius), box, **corner_circles(obstacles, radius))

    @property
    def n_circles(self) -> int:
        return len(self.rho)

    # -- cones and angles --------------------------------------------------
    def circles_of(self, obstacles: np.ndarray) -> np.ndarray:
        """Every circle id of the given obstacle ids, in order."""
        lo, hi = self.first[obstacles], self.first[obstacles + 1]
        counts = hi - lo
        return np.repeat(lo, counts) + (np.arange(counts.sum()) - np.repeat(np.cumsum(counts) - counts, counts))

    def in_cone(self, circle: np.ndarray, normal: np.ndarray) -> np.ndarray:
        """(m,) bool: the outward ``normal`` (m, 2) lies in the cone of ``circle`` (m,)."""
        a, b = self.cone_a[circle], self.cone_b[circle]
        inside = (cross(a, normal) >= -CONE_SLACK) & (cross(normal, b) >= -CONE_SLACK)
        return self.full[circle] | inside

    @property
    def full(self) -> np.ndarray:
        """(C,) bool: the circle is a disc obstacle's, usable at every angle."""
        return self.cone_w >= 2 * np.pi

    # -- clearance tests ---------------------------------------------------
    def inside_box(self, pts: np.ndarray) -> np.ndarray:
        """(n,) bool: the (n, 2) points lie where the robot's centre may be."""
        x0, y0, x1, y1 = self.box
        t = TOUCH
        return (pts[:, 0] >= x0 - t) & (pts[:, 0] <= x1 + t) & (pts[:, 1] >= y0 - t) & (pts[:, 1] <= y1 + t)

    def segments_clear(self, a: np.ndarray, b: np.ndarray, skip1: Optional[np.ndarray] = None,
                       skip2: Optional[np.ndarray] = None, among: Optional[np.ndarray] = None) -> np.ndarray:
        """(m,) bool: segment ``a[i]b[i]`` keeps ``radius`` from every obstacle but ``skip1[i]``, ``skip2[i]``
        (ids; -1 for none) and stays inside the box.

        The obstacles to skip are those the segment is tangent to: it touches them by
        construction, at a normal inside their cone, so it cannot cut into them.
        ``among`` (ids) limits the test to obstacles the caller knows to hold every
        one that could come near the segments. Many obstacles: a grid finds those near
        each segment, walking it from its start, and a segment is dropped at its first hit.
        """
        a = np.asarray(a, dtype=float).reshape(-1, 2)
        b = np.asarray(b, dtype=float).reshape(-1, 2)
        # Both ends inside the box exactly when the segment's bounding box is (the same comparisons).
        lo, hi = np.minimum(a, b), np.maximum(a, b)
        x0, y0, x1, y1 = self.box
        ok = (lo[:, 0] >= x0 - TOUCH) & (lo[:, 1] >= y0 - TOUCH) & (hi[:, 0] <= x1 + TOUCH) & (hi[:, 1] <= y1 + TOUCH)
        if len(self.obstacles) == 0 or not ok.any():
            return ok
        if self._grid is not None and (among is None or len(among) > GRID_FROM):
            return self._grid_clear(a, b, ok, skip1, skip2)
        rows = np.flatnonzero(ok)
        if len(rows) < len(ok):
            lo, hi = lo[rows], hi[rows]
        boxes = self._reach_boxes if among is None else self._reach_boxes[among]
        seg, k = np.nonzero(_near(lo, hi, boxes))
        seg, o = rows[seg], (k if among is None else np.asarray(among, dtype=np.int64)[k])
        seg, o = _unskipped(seg, o, skip1, skip2)
        self._drop_hits(a, b, seg, o, ok)
        return ok

    @cached_property
    def _reach_boxes(self) -> np.ndarray:
        """(N, 4) the boxes grown by ``radius``: a segment whose box misses one's stays ``radius - TOUCH`` away."""
        return self.obstacles.boxes + np.array([-self.radius, -self.radius, self.radius, self.radius])

    @cached_property
    def _grid(self) -> Optional[SegmentGrid]:
        return SegmentGrid.build(self) if len(self.obstacles) > GRID_FROM else None

    def _grid_clear(self, a, b, ok, skip1, skip2) -> np.ndarray:
        grid = self._grid
        assert grid is not None, "called only when the space has a grid"
        step = grid.h / 2
        d = b - a
        steps = np.maximum(np.ceil(np.sqrt(d[:, 0] ** 2 + d[:, 1] ** 2) / step).astype(np.int64), 1)
        rows = np.flatnonzero(ok)
        first, walk = 0, WALK
        while len(rows):
            k = first + np.arange(walk)
            t = k[None, :] / steps[rows, None]
            inside = t <= 1.0
            r = np.broadcast_to(rows[:, None], t.shape)[inside]
            pts = a[r] + t[inside][:, None] * d[r]
            seg, o = _unskipped(*grid.pairs(r, pts), skip1, skip2)
            if len(seg):
                self._drop_hits(a, b, seg, o, ok)
            first += walk
            walk *= 2  # the segments still going are few: longer strides, fewer rounds
            rows = rows[ok[rows] & (steps[rows] >= first)]
        return ok

    def _drop_hits(self, a: np.ndarray, b: np.ndarray, seg: np.ndarray, o: np.ndarray, ok: np.ndarray) -> None:
        """Set ``ok[seg[i]]`` False for each (segment ``a[seg[i]]b[seg[i]]``, obstacle ``o[i]``) pair closer
        than ``radius``. Most pairs are settled by the obstacle's bounding and core discs; polygon edges
        are measured only for segments that pass between the two and that no core has blocked already
        (most candidate tangents are blocked, and one hit settles a segment)."""
        obs = self.obstacles
        r = self.radius - TOUCH
        d = point_segment_distance(self.hull_c[o], a[seg], b[seg])
        hit = d < self.core_r[o] - TOUCH  # through the core (for a disc: exactly the test)
        ok[seg[hit]] = False
        unsure = np.flatnonzero(~hit & (d < self.hull_r[o] - TOUCH) & (o >= obs.n_discs))
        unsure = unsure[ok[seg[unsure]]]
        if len(unsure) == 0:
            return
        p = o[unsure] - obs.n_discs
        counts = obs.edge_start[p + 1] - obs.edge_start[p]
        starts = np.cumsum(counts) - counts
        pair = np.repeat(np.arange(len(unsure)), counts)
        e = obs.edge_start[p][pair] + (np.arange(counts.sum()) - starts[pair])
        s = seg[unsure][pair]
        ap, bp = a[s], b[s]
        close = segment_segment_distance(ap, bp, obs.edge_a[e], obs.edge_b[e]) < r
        # A segment wholly inside a polygon crosses no edge: its start lies left of every edge.
        left = cross(obs.edge_b[e] - obs.edge_a[e], ap - obs.edge_a[e]) >= 0
        # Per pair: any edge close, or every edge with the start on its left (counted, as ufunc.at would).
        n = len(unsure)
        blocked = (np.bincount(pair, close, n) > 0) | (np.bincount(pair, ~left, n) == 0)
        ok[seg[unsure][blocked]] = False

    def neighbour_pairs(self, circle: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """(row, obstacle id) for each of ``circle`` (m,) and each neighbour of the circle's obstacle."""
        own = self.owner[circle]
        counts = self.nb_start[own + 1] - self.nb_start[own]
        row = np.repeat(np.arange(len(circle)), counts)
        k = self.nb_start[own][row] + (np.arange(counts.sum()) - np.repeat(np.cumsum(counts) - counts, counts))
        return row, self.nb_ids[k]

    def points_clearance(self, pts: np.ndarray) -> np.ndarray:
        """(n,) exact distance from each point to the nearest footprint or the bounds' edge, minus ``radius``
        on the bounds side: the slack (m) a disc of ``radius`` has there (negative where it does not fit)."""
        pts = np.asarray(pts, dtype=float).reshape(-1, 2)
        d_obs = self.obstacles.points_distance(pts)[0] - self.radius
        x0, y0, x1, y1 = self.box
        d_box = np.minimum(np.minimum(pts[:, 0] - x0, x1 - pts[:, 0]), np.minimum(pts[:, 1] - y0, y1 - pts[:, 1]))
        return np.minimum(d_obs, d_box)

    # -- arcs ---------------------------------------------------------------
    def arc_clearance(self, circle: np.ndarray, start: np.ndarray, sweep: np.ndarray) -> np.ndarray:
        """(m,) slack (m) of the arcs on ``circle`` (m,) from outward angle ``start`` counter-clockwise over
        ``sweep`` (rad): the smallest distance from the arc to any other footprint minus ``radius``, and to
        the box's edges; exact up to ``NEAR_MARGIN x radius``, which it never exceeds (farther
        obstacles are not measured).

        The arc's own obstacle is skipped (the arc lies on its grown boundary). Exact:
        the nearest pair between an arc and a segment is an end of one of them, the
        foot of the perpendicular from the arc's centre on the segment, or a crossing.
        """
        circle = np.asarray(circle, dtype=np.int64)
        m = len(circle)
        slack = np.full(m, NEAR_MARGIN * self.radius)
        if m == 0:
            return slack
        c = self.centre[circle]
        rho = self.rho[circle]
        start = np.asarray(start, dtype=float)
        sweep = np.asarray(sweep, dtype=float)
        # The box: the arc's extreme points are its ends and the axis directions it sweeps over.
        x0, y0, x1, y1 = self.box
        for quarter, (ux, uy) in enumerate(((1.0, 0.0), (0.0, 1.0), (-1.0, 0.0), (0.0, -1.0))):
            ang = quarter * np.pi / 2
            swept = np.mod(ang - start, 2 * np.pi) <= sweep
            px, py = c[:, 0] + rho * ux, c[:, 1] + rho * uy
            margin = np.minimum(np.minimum(px - x0, x1 - px), np.minimum(py - y0, y1 - py))
            slack = np.where(swept, np.minimum(slack, margin), slack)
        ends = [c + rho[:, None] * np.stack([np.cos(t), np.sin(t)], axis=1) for t in (start, start + sweep)]
        for e in ends:
            slack = np.minimum(slack, np.minimum(np.minimum(e[:, 0] - x0, x1 - e[:, 0]),
                                                 np.minimum(e[:, 1] - y0, y1 - e[:, 1])))
        obs = self.obstacles
        row, o = self.neighbour_pairs(circle)
        if len(row) == 0:
            return slack
        nd = obs.n_discs
        disc = o < nd
        if disc.any():
            r, k = row[disc], o[disc]
            q = obs.disc_xy[k]
            d = _point_arc_distance(q, c[r], rho[r], start[r], sweep[r], ends[0][r], ends[1][r]) - obs.disc_r[k]
            np.minimum.at(slack, r, d - self.radius)
        if (~disc).any():
            r, p = row[~disc], o[~disc] - nd
            counts = obs.edge_start[p + 1] - obs.edge_start[p]
            r_e = np.repeat(r, counts)
            offsets = np.arange(counts.sum()) - np.repeat(np.cumsum(counts) - counts, counts)
            e = np.repeat(obs.edge_start[p], counts) + offsets
            d = _segment_arc_distance(obs.edge_a[e], obs.edge_b[e], c[r_e], rho[r_e], start[r_e], sweep[r_e],
                                      ends[0][r_e], ends[1][r_e])
            np.minimum.at(slack, r_e, d - self.radius)
        return slack


def _in_sweep(direction: np.ndarray, start: np.ndarray, sweep: np.ndarray) -> np.ndarray:
    ang = np.arctan2(direction[:, 1], direction[:, 0])
    return np.mod(ang - start, 2 * np.pi) <= sweep


def _point_arc_distance(p, c, rho, start, sweep, e0, e1) -> np.ndarray:
    """(m,) distance from points ``p`` to arcs (centre ``c``, radius ``rho``, angles start..start+sweep)."""
    v = p - c
    dist_c = np.hypot(v[:, 0], v[:, 1])
    radial = np.abs(dist_c - rho)
    ends = np.minimum(np.hypot(*(p - e0).T), np.hypot(*(p - e1).T))
    return np.where(_in_sweep(v, start, sweep) & (dist_c > 0), radial, ends)


def _segment_arc_distance(a, b, c, rho, start, sweep, e0, e1) -> np.ndarray:
    """(m,) distance between segments ``ab`` and arcs (see :func:`_point_arc_distance`)."""
    d = np.minimum(point_segment_distance(e0, a, b), point_segment_distance(e1, a, b))
    d = np.minimum(d, _point_arc_distance(a, c, rho, start, sweep, e0, e1))
    d = np.minimum(d, _point_arc_distance(b, c, rho, start, sweep, e0, e1))
    ab = b - a
    den = np.einsum("ij,ij->i", ab, ab)
    den = np.where(den > 0, den, 1.0)
    t = np.einsum("ij,ij->i", c - a, ab) / den
    foot = a + t[:, None] * ab
    on = (t >= 0) & (t <= 1)
    d = np.where(on, np.minimum(d, _point_arc_distance(foot, c, rho, start, sweep, e0, e1)), d)
    # Crossings of the segment's line with the circle, within the segment and the arc.
    h = foot - c
    h2 = np.einsum("ij,ij->i", h, h)
    under = rho * rho - h2
    cut = under >= 0
    half = np.sqrt(np.where(cut, under, 0.0) / den)
    for sign in (-1.0, 1.0):
        s = t + sign * half
        x = a + s[:, None] * ab
        crossing = cut & (s >= 0) & (s <= 1) & _in_sweep(x - c, start, sweep)
        d = np.where(crossing, 0.0, d)
    return d
