"""The tangent graph of one configuration space, built once for many shortest-path queries.

Every free common tangent between circles of different obstacles, and every grown edge
(:mod:`~worldgen.feasibility.tangents`), leaves a circle on a side (the way the path winds round it) and
arrives on another on a side. On each (circle, side), a *chain*, those points are sorted the way the path
winds; a path arriving at one may leave at any later one, over the arc between, if that arc keeps the
clearance: exactly when each piece between consecutive points does, so the pieces are measured here, once.
The queries over this graph are :class:`~worldgen.feasibility.roadmap.Roadmap`'s.
"""

from __future__ import annotations

import math

import numpy as np

from worldgen.feasibility.cspace import ConfigSpace
from worldgen.feasibility.tangents import Tangents, every_side, grown_edges, lonely_circles, tangents

__all__ = ["TangentGraph", "EPS", "SPAN", "TWO_PI"]

#: Angles (rad) within this of each other count as one: the planner's tolerance on a sweep.
EPS = 1e-9
#: Chain keys: chain id times SPAN plus the winding angle (< 2 pi + a hair), one sorted array for all.
SPAN, TWO_PI = 8.0, 2 * math.pi


class TangentGraph:
    """Every tangent of one configuration space on its chains, and which pieces of each chain's arc are
    blocked; per position (a tangent's departure or arrival on its chain, sorted by chain and angle) what
    a search reads."""

    def __init__(self, cs: ConfigSpace):
        self.cs = cs
        self._arc_free = lonely_circles(cs)
        self._angle0 = np.arctan2(cs.cone_a[:, 1], cs.cone_a[:, 0])
        self._full = cs.full
        self.tans = self._all_tangents()
        t = self.tans
        n = len(t)
        # Positions: departures of every tangent (rows 0..n-1), then arrivals (n..2n-1), sorted by chain and angle.
        circle = np.concatenate([t.src, t.dst])
        side = np.concatenate([t.s1, t.s2])
        rel = self._rel(circle, np.concatenate([t.nq, t.nt]))
        chain = circle * 2 + (side < 0)
        u = self._wind(circle, side, rel)
        order = np.lexsort((u, chain))
        self._chain = chain[order]
        self._u = u[order]
        self._rel_sorted = rel[order]
        self._key = self._chain * SPAN + self._u
        self._node = order  # what each position is: a departure (< n) or an arrival (>= n) of tangent node % n
        at = np.empty(2 * n, dtype=np.int64)
        at[order] = np.arange(2 * n)
        self._arrival_pos = at[n:]  # tangent j arrives at this position
        self._points = np.concatenate([t.q, t.t])[order]
        self._start = np.searchsorted(self._chain, np.arange(2 * cs.n_circles + 1)).astype(np.int64)
        self._blocked, self._head = self._gaps()
        # Hot per-position data as Python lists: the search reads them one at a time.
        self._u_l, self._chain_l, self._node_l = self._u.tolist(), self._chain.tolist(), self._node.tolist()
        self._start_l, self._full_l, self._rho_l = self._start.tolist(), self._full.tolist(), cs.rho.tolist()
        self._len_l, self._arr_l = t.length.tolist(), self._arrival_pos.tolist()
        self._px, self._py = self._points[:, 0].tolist(), self._points[:, 1].tolist()
        self._n = n

    # -- the graph ------------------------------------------------------------
    def _all_tangents(self) -> Tangents:
        """Every free tangent between circles of different obstacles (each side), and the grown edges.

        Computed one way round only: the tangent from circle 1 on side s1 to circle 2 on side s2, walked
        backwards, is the one from circle 2 on side -s2 to circle 1 on side -s1 (the same segment and normals).
        """
        cs = self.cs
        c = np.arange(cs.n_circles)
        src, dst = np.repeat(c, len(c)), np.tile(c, len(c))
        keep = cs.owner[src] < cs.owner[dst]
        one = tangents(cs, *every_side(src[keep], dst[keep]))
        back = Tangents(one.dst, one.src, -one.s2, -one.s1, one.t, one.q, one.nt, one.nq, one.length)
        return Tangents.concat([one, back, grown_edges(cs).tans])

    def _rel(self, circle: np.ndarray, normals: np.ndarray) -> np.ndarray:
        """Angle (rad) of each outward normal from its circle's cone start, counter-clockwise (the planner's)."""
        ang = np.mod(np.arctan2(normals[:, 1], normals[:, 0]) - self._angle0[circle], 2 * np.pi)
        return np.where(~self._full[circle] & (ang > self.cs.cone_w[circle] + 1e-6), 0.0, ang)

    def _wind(self, circle: np.ndarray, side: np.ndarray, rel: np.ndarray) -> np.ndarray:
        """The angle along the way the path winds (side -1 winds clockwise: from the cone's end)."""
        w = self.cs.cone_w[circle]
        u = np.where(side > 0, rel, w - rel)
        return np.where(self._full[circle], np.mod(u, 2 * np.pi), u)

    def _gaps(self) -> tuple[np.ndarray, np.ndarray]:
        """Which pieces of each chain's arc do not keep the clearance: (positions,) from each position to the
        next of its chain (wrapping on a full circle; to the cone's end after a polygon corner's last), and
        (chains,) from the cone's start to the chain's first position (the whole circle or cone if none)."""
        m, cs = len(self._u), self.cs
        circle = self._chain // 2
        last = np.r_[self._chain[1:] != self._chain[:-1], True] if m else np.zeros(0, dtype=bool)
        first_of = self._start[self._chain]
        nxt = np.where(last, first_of, np.arange(1, m + 1))
        nxt_u = np.where(last, np.where(self._full[circle], self._u[first_of] + 2 * np.pi, cs.cone_w[circle]),
                         self._u[np.minimum(np.arange(1, m + 1), m - 1)] if m else 0.0)
        nxt_rel = np.where(last & ~self._full[circle], np.where(self._chain % 2 == 0, cs.cone_w[circle], 0.0),
                           self._rel_sorted[nxt % max(m, 1)] if m else 0.0)
        sweep = nxt_u - self._u
        i = np.flatnonzero((sweep > 0) & ~self._arc_free[circle])
        blocked = np.zeros(m, dtype=bool)
        blocked[i] = ~self._arcs_clear(self._chain[i], self._rel_sorted[i], nxt_rel[i], sweep[i])
        # Heads: from the cone's start (on side -1, its end) to the first position.
        chains = np.arange(2 * cs.n_circles)
        c = chains // 2
        empty = self._start[1:] == self._start[:-1]
        head_u = np.where(empty, cs.cone_w[c], self._u[np.minimum(self._start[:-1], max(m - 1, 0))] if m else 0.0)
        head_u = np.where(self._full[c] & ~empty, 0.0, head_u)  # a full circle's wrap is a gap already
        head_rel = np.where(empty, np.where(chains % 2 == 0, cs.cone_w[c], 0.0),
                            self._rel_sorted[np.minimum(self._start[:-1], max(m - 1, 0))] if m else 0.0)
        from_rel = np.where(chains % 2 == 0, 0.0, cs.cone_w[c])
        head = np.zeros(len(chains), dtype=bool)
        j = np.flatnonzero(head_u > 0)
        head[j] = ~self._arcs_clear(chains[j], from_rel[j], head_rel[j], head_u[j])
        return blocked, head

    def _arcs_clear(self, chain, rel_from, rel_to, sweep, clear=None) -> np.ndarray:
        """(m,) bool: the arcs on ``chain`` (m,) from ``rel_from`` to ``rel_to`` the way it winds keep the
        clearance; ``clear`` (m,) bool, if given: those known to (they lie in a clear piece of their chain)."""
        circle = chain // 2
        ok = np.ones(len(chain), dtype=bool)
        unsure = (sweep > 0) & ~self._arc_free[circle]
        if clear is not None:
            unsure &= ~clear
        check = np.flatnonzero(unsure)
        if len(check):
            # Counter-clockwise from where a side +1 path arrives, or a side -1 path leaves.
            start = self._angle0[circle[check]] + np.where(chain[check] % 2 == 0, rel_from[check], rel_to[check])
            ok[check] = self.cs.arc_clearance(circle[check], start, sweep[check]) >= -EPS
        return ok
