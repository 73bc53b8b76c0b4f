"""Common tangent segments between corner circles: the edges of the tangent visibility graph.

A shortest path for a disc among grown convex obstacles is taut: straight
segments, each tangent to the circles at its two ends, joined by arcs of those
circles. A segment leaves circle 1 with the circle on its left (side ``s1 = +1``,
the path then winds counter-clockwise round it) or on its right (``s1 = -1``),
and meets circle 2 on side ``s2``. With ``unit`` the unit normal to the left of the
direction of travel, the touching points are ``q = c1 - s1 r1 unit`` and
``t = c2 - s2 r2 unit``, and the line is tangent to both exactly when
``unit . (c2 - c1) = s2 r2 - s1 r1``; of the two solutions, the one with the
direction of travel pointing from circle 1 to circle 2 is
``angle(unit) = angle(c2 - c1) + acos(k / |c2 - c1|)``.

A point (the spawn, the goal) is a circle of radius 0 with a full cone.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Optional

import numpy as np

from worldgen.feasibility.cspace import ConfigSpace

__all__ = ["Tangents", "tangents", "every_side", "SIDES", "TangentStore", "EdgeIndex", "TangentBatch", "grown_edges",
           "lonely_circles"]

#: The four kinds of common tangent (s1, s2): both circles on the left, left-right, ...
SIDES = ((1, 1), (1, -1), (-1, -1), (-1, 1))


@dataclass(frozen=True, eq=False)
class Tangents:
    """Free tangent segments (m,) from circles ``src`` to circles ``dst`` (ids; -1 for a point).

    ``s1``/``s2`` the sides (+1 left, -1 right), ``q``/``t`` (m, 2) the touching
    points, ``nq``/``nt`` (m, 2) the outward normals there (zero for a point),
    ``length`` (m,).
    """

    src: np.ndarray
    dst: np.ndarray
    s1: np.ndarray
    s2: np.ndarray
    q: np.ndarray
    t: np.ndarray
    nq: np.ndarray
    nt: np.ndarray
    length: np.ndarray

    def __len__(self) -> int:
        return len(self.src)

    def take(self, rows: np.ndarray) -> "Tangents":
        return Tangents(*(getattr(self, f)[rows] for f in _FIELDS))

    @staticmethod
    def concat(parts: list["Tangents"]) -> "Tangents":
        return Tangents(*(np.concatenate([getattr(p, f) for p in parts]) for f in _FIELDS))


_FIELDS = ("src", "dst", "s1", "s2", "q", "t", "nq", "nt", "length")


def every_side(src: np.ndarray, dst: np.ndarray, src_sides=(1, -1), dst_sides=(1, -1)):
    """(src, dst, s1, s2) with every pair repeated for each combination of the given sides."""
    src = np.asarray(src, dtype=np.int64)
    dst = np.asarray(dst, dtype=np.int64)
    sides = [(a, b) for a, b in SIDES if a in src_sides and b in dst_sides]
    n = len(src)
    s1 = np.repeat(np.array([a for a, _ in sides], dtype=np.int64), n)
    s2 = np.repeat(np.array([b for _, b in sides], dtype=np.int64), n)
    return np.tile(src, len(sides)), np.tile(dst, len(sides)), s1, s2


def tangents(cs: ConfigSpace, src: np.ndarray, dst: np.ndarray, s1: np.ndarray, s2: np.ndarray,
             src_xy=None, dst_xy=None, among=None, clear: bool = True) -> Tangents:
    """The free common tangent from circle ``src[k]`` on side ``s1[k]`` to circle ``dst[k]`` on side ``s2[k]``.

    Circle ids of -1 stand for points: ``src_xy``/``dst_xy`` ((2,) or (m, 2)) give them.
    Kept: tangents that touch each circle inside its cone, run from the first to
    the second, and keep the clearance from every other obstacle (and the box);
    ``among`` (ids), if given, holds every obstacle that could come near them. With ``clear=False`` the
    clearance is not tested (the caller tests the few it needs, :meth:`ConfigSpace.segments_clear`).
    """
    src = np.asarray(src, dtype=np.int64)
    dst = np.asarray(dst, dtype=np.int64)
    m = len(src)
    sf1 = np.asarray(s1, dtype=float)
    sf2 = np.asarray(s2, dtype=float)
    if src_xy is None:
        c1, r1 = cs.centre[src], cs.rho[src]
    else:
        c1, r1 = np.broadcast_to(np.asarray(src_xy, dtype=float), (m, 2)), np.zeros(m)
    if dst_xy is None:
        c2, r2 = cs.centre[dst], cs.rho[dst]
    else:
        c2, r2 = np.broadcast_to(np.asarray(dst_xy, dtype=float), (m, 2)), np.zeros(m)
    delta = c2 - c1
    dist = np.sqrt(delta[:, 0] * delta[:, 0] + delta[:, 1] * delta[:, 1])
    k = sf2 * r2 - sf1 * r1
    ok = np.abs(k) < dist
    safe = np.where(ok, dist, 1.0)
    cos = np.where(ok, k / safe, 0.0)
    sin = np.sqrt(1.0 - cos * cos)
    ux, uy = delta[:, 0] / safe, delta[:, 1] / safe
    unit = np.stack([cos * ux - sin * uy, sin * ux + cos * uy], axis=1)
    nq = -sf1[:, None] * unit
    nt = -sf2[:, None] * unit
    if src_xy is None:
        ok &= cs.in_cone(src, nq)
    if dst_xy is None:
        ok &= cs.in_cone(dst, nt)
    rows = np.flatnonzero(ok)
    q = c1[rows] + r1[rows, None] * nq[rows]
    t = c2[rows] + r2[rows, None] * nt[rows]
    own1 = cs.owner[src[rows]] if src_xy is None else np.full(len(rows), -1)
    own2 = cs.owner[dst[rows]] if dst_xy is None else np.full(len(rows), -1)
    free = cs.segments_clear(q, t, own1, own2, among=among) if clear else np.ones(len(rows), dtype=bool)
    keep = rows[free]
    q, t = q[free], t[free]
    seg = t - q
    return Tangents(src[keep], dst[keep], np.asarray(s1)[keep], np.asarray(s2)[keep], q, t,
                    np.where(src_xy is None, 1.0, 0.0) * nq[keep], np.where(dst_xy is None, 1.0, 0.0) * nt[keep],
                    np.sqrt(seg[:, 0] * seg[:, 0] + seg[:, 1] * seg[:, 1]))


class TangentStore:
    """Every tangent computed between obstacles, with the rows leaving each (circle, side)."""

    def __init__(self):
        self.parts: list[Tangents] = []
        self.tans: Optional[Tangents] = None
        self.dst_owner = np.zeros(0, dtype=np.int64)
        self.index: dict[int, list[np.ndarray]] = {}

    def add(self, tans: Tangents, cs) -> None:
        if not len(tans):
            return
        base = len(self.dst_owner)
        self.parts.append(tans)
        self.tans = None
        self.dst_owner = np.concatenate([self.dst_owner, cs.owner[tans.dst]])
        key = tans.src * 2 + (tans.s1 < 0)
        order = np.argsort(key, kind="stable")
        cut = np.flatnonzero(np.r_[True, key[order][1:] != key[order][:-1]])
        for k, rows in zip(key[order][cut].tolist(), np.split(order + base, cut[1:])):
            self.index.setdefault(k, []).append(rows)

    def rows(self, circle: int, side: int) -> np.ndarray:
        parts = self.index.get(circle * 2 + (side < 0))
        if not parts:
            return np.zeros(0, dtype=np.int64)
        if len(parts) > 1:
            parts[:] = [np.concatenate(parts)]
        return parts[0]

    def take(self, rows: np.ndarray) -> Tangents:
        if self.tans is None:
            self.tans = Tangents.concat(self.parts)
            self.parts = [self.tans]
        return self.tans.take(rows)


class EdgeIndex:
    """Grown polygon edges as tangents, looked up by (circle, side)."""

    def __init__(self, tans: Tangents, n_circles: int):
        self.tans = tans
        self.index = np.full((n_circles, 2), -1, dtype=np.int64)
        self.index[tans.src, (tans.s1 < 0).astype(np.int64)] = np.arange(len(tans))

    def pick(self, circles: np.ndarray, sides: np.ndarray) -> np.ndarray:
        return self.index[circles, (sides < 0).astype(np.int64)]


class TangentBatch:
    """Ways out of expanded nodes, gathered for one vectorised pass: parallel lists of arrays."""

    def __init__(self):
        self.parts: list[tuple] = []

    def add(self, node_index: np.ndarray, tans: Tangents) -> None:
        if len(tans):
            self.parts.append((node_index, tans))

    def merged(self):
        if not self.parts:
            return None, None
        idx = np.concatenate([p[0] for p in self.parts])
        return idx, Tangents.concat([p[1] for p in self.parts])


def lonely_circles(cs) -> np.ndarray:
    """(C,) bool: circles none of whose arcs can be blocked (no neighbour, disc inside the box)."""
    lo, hi = cs.centre - cs.rho[:, None], cs.centre + cs.rho[:, None]
    x0, y0, x1, y1 = cs.box
    inside = (lo[:, 0] >= x0) & (lo[:, 1] >= y0) & (hi[:, 0] <= x1) & (hi[:, 1] <= y1)
    return inside & (cs.nb_start[1:] == cs.nb_start[:-1])[cs.owner]


def grown_edges(cs) -> EdgeIndex:
    """The grown edges between neighbouring corners, as tangents each way, where clear."""
    corner = np.flatnonzero(cs.nxt >= 0)
    nxt = cs.nxt[corner]
    n = cs.cone_b[corner]
    a = cs.centre[corner] + cs.rho[corner, None] * n
    b = cs.centre[nxt] + cs.rho[nxt, None] * n
    ok = cs.inside_box(a) & cs.inside_box(b)
    row, o = cs.neighbour_pairs(corner)
    cs._drop_hits(a, b, row, o, ok)
    corner, nxt, n, a, b = corner[ok], nxt[ok], n[ok], a[ok], b[ok]
    length = np.hypot(*(b - a).T)
    one = np.ones(len(corner), dtype=np.int64)
    # Winding counter-clockwise (side +1) the path goes from a corner to the next; clockwise, back.
    tans = Tangents.concat([Tangents(corner, nxt, one, one, a, b, n, n, length),
                            Tangents(nxt, corner, -one, -one, b, a, n, n, length)])
    return EdgeIndex(tans, cs.n_circles)
