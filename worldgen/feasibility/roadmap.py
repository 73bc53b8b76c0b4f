"""Many exact shortest paths in one configuration space: the whole tangent visibility graph, built once.

The crowd model asks about a hundred shortest paths in one person's configuration space (a leg a
person starts, a replan). :class:`~worldgen.feasibility.planner.Planner` builds its graph lazily for
each query (about 2 ms a query among 50 obstacles); here it is built once, every free common tangent
between circles of different obstacles and the grown edges, and a query only adds its two ends.

The graph, its chains of tangent points and which pieces of their arcs are blocked, is
:mod:`~worldgen.feasibility.roadmap_graph`'s; here are the queries over it, and a point's ways out along
its chain, gathered when a search first needs them and kept for the next.

A query is A* over the arrival points, the straight-line distance to the goal its heuristic (consistent:
no arc or leg is shorter than its chord). The start's tangents enter chains at new points (going on to
the next point, or round to the goal's tangent), the goal's leave them from new points. The graph holds
every taut path with the planner's tolerances (sweeps within 1e-9 of zero are zero, arcs with slack below
-1e-9 blocked), so the optimum is the planner's; tests/feasibility/test_roadmap.py checks the lengths.
"""

from __future__ import annotations

import heapq
import math
from typing import Optional

import numpy as np

from worldgen.feasibility.cspace import ConfigSpace
from worldgen.feasibility.roadmap_graph import EPS, SPAN, TWO_PI, TangentGraph
from worldgen.feasibility.route import Contact, Route
from worldgen.feasibility.tangents import Tangents, every_side, tangents

__all__ = ["Roadmap"]

#: A start tangent's clearance is tested together with those whose cost is within this (m) of it: one
#: vectorised test for the few the search is about to reach.
VERIFY_BAND = 1.0
#: What waits in a query's queue: an arrival on a chain, a start tangent not yet tested, a way to the goal
#: (its cost exact) not yet tested, a path round one circle not yet tested.
_STATE, _SEED, _GOAL, _DIRECT = 0, 1, 2, 3


class Roadmap(TangentGraph):
    """Shortest paths in one configuration space, all of them over one tangent graph built once
    (:class:`~worldgen.feasibility.roadmap_graph.TangentGraph`)."""

    def __init__(self, cs: ConfigSpace):
        super().__init__(cs)
        self._ways: dict[int, tuple] = {}
        # A query's tangents: from a point to every circle, each side; twice (the start's, the goal's).
        src, dst, s1, s2 = every_side(np.full(cs.n_circles, -1), np.arange(cs.n_circles), (1,), (1, -1))
        self._ends_rows = (np.tile(src, 2), np.tile(dst, 2), np.tile(s1, 2), np.tile(s2, 2))

    def _piece_blocked(self, chain: np.ndarray, u: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """(the last position at or before angle ``u`` on ``chain``, or the chain's start - 1: before its
        first; whether the piece of arc holding ``u`` is blocked). An arc within a clear piece is clear."""
        raw = np.searchsorted(self._key, chain * SPAN + u, side="right") - 1
        s, e = self._start[chain], self._start[chain + 1]
        before = raw < s
        at = np.where(before & self._full[chain // 2] & (e > s), e - 1, raw)
        head = at < s
        blocked = np.where(head, self._head[chain], self._blocked[np.clip(at, 0, max(len(self._u) - 1, 0))]
                           if len(self._u) else True)
        return raw, blocked

    def _ways_out(self, k: int) -> tuple:
        """(first, last unrolled index, chain start, chain length, [(arrival position, cost, tangent, sweep)])
        of position ``k``: every departure reachable along its chain from it, kept for later queries."""
        got = self._ways.get(k)
        if got is not None:
            return got
        u, ch = self._u_l, self._chain_l[k]
        s, e = self._start_l[ch], self._start_l[ch + 1]
        m = e - s
        full = self._full_l[ch // 2]
        i = lo = k - s
        while lo > 0 and u[s + lo - 1] >= u[k] - EPS:
            lo -= 1
        limit = lo + m - 1 if full else m - 1
        hi = i
        blocked = self._blocked
        while hi < limit and not blocked[s + hi % m]:
            hi += 1
        rho, n = self._rho_l[ch // 2], self._n
        out = []
        for idx in range(lo, hi + 1):
            p = s + idx % m
            j = self._node_l[p]
            if j >= n:
                continue  # an arrival: nothing leaves there
            sweep = u[p] - u[k] + (TWO_PI if idx >= m else 0.0)
            sweep = 0.0 if sweep < 0.0 or (full and sweep > TWO_PI - EPS) else sweep
            out.append((self._arr_l[j], rho * sweep + self._len_l[j], j, sweep))
        got = (lo, hi, s, m, out)
        self._ways[k] = got
        return got

    # long: a query (the A* loop is the hot path; splitting it costs a call per expanded node)
    def shortest(self, start, goal) -> Optional[Route]:
        """The shortest path from ``start`` to ``goal`` ((2,) each, both free), or None if there is none.

        The start's and the goal's tangents are tested for clearance only when the search reaches them
        (most of them never are): a tangent not yet tested waits in the queue at its cost, which no test
        can lower, and is tested when it comes first.
        """
        cs, start, goal = self.cs, np.asarray(start, dtype=float), np.asarray(goal, dtype=float)
        if cs.segments_clear(start[None], goal[None])[0]:
            return Route(np.array([start, goal]), (), float(np.hypot(*(goal - start))))
        # The start's and the goal's tangents to every circle in one call; the goal's walked backwards.
        m = len(self._ends_rows[0]) // 2
        both = tangents(cs, *self._ends_rows, src_xy=np.repeat([start, goal], m, axis=0), clear=False)
        mine = np.all(both.q == start, axis=1)
        to = both.take(np.flatnonzero(~mine))
        ins = _Ends(self, both.take(np.flatnonzero(mine)), True)
        outs = _Ends(self, Tangents(to.dst, to.src, -to.s2, -to.s1, to.t, to.q, to.nt, to.nq, to.length), False)
        gx, gy, px, py, hypot = float(goal[0]), float(goal[1]), self._px, self._py, math.hypot
        seed_f = ins.length + ins.sweep * self.cs.rho[ins.chain // 2]
        if len(self._points):
            seed_f = seed_f + np.hypot(self._points[ins.pos, 0] - gx, self._points[ins.pos, 1] - gy)
        # The start's tangents join the queue one at a time, cheapest first: most are never reached.
        seeds = ins.rows[np.argsort(seed_f[ins.rows], kind="stable")].tolist()
        heap: list = [(f, k, _DIRECT, data) for k, (f, data) in enumerate(self._direct(ins, outs))]
        order = len(heap) + 1  # (f, order, kind, data): kinds above; order 0 is the next start tangent
        if seeds:
            heap.append((float(seed_f[seeds[0]]), 0, _SEED, 0))
        heapq.heapify(heap)
        # The goal's departures by chain: (position before, sweep from it, cost to the goal, row).
        leave: dict[int, list] = {}
        rows = outs.rows
        for ch, p, extra, length, r in zip(self._chain[outs.pos[rows]].tolist(), outs.pos[rows].tolist(),
                                           outs.sweep[rows].tolist(), outs.length[rows].tolist(), rows.tolist()):
            leave.setdefault(ch, []).append((p, extra, length, r))
        dist: dict[int, float] = {}
        parent: dict[int, tuple] = {}
        goal_f = np.full(len(outs.length), math.inf)  # the cheapest way to the goal over each goal tangent
        u = self._u_l
        while heap:
            f, _, kind, data = heapq.heappop(heap)
            if kind == _GOAL:
                if outs.verified(int(data[1]), upto=f + VERIFY_BAND, f=goal_f):
                    return self._route(start, goal, f, data, parent, ins, outs)
                continue
            if kind == _DIRECT:
                a, b, sweep, inside = data
                if ins.verified(a, arc=False) and outs.verified(b, arc=False) and self._arcs_clear(
                        ins.chain[a:a + 1], ins.rel[a:a + 1], outs.rel[b:b + 1], np.array([sweep]), np.array([inside]))[0]:
                    return self._route(start, goal, f, ("direct",) + data, parent, ins, outs)
                continue
            if kind == _SEED:
                if data + 1 < len(seeds):
                    heapq.heappush(heap, (float(seed_f[seeds[data + 1]]), 0, _SEED, data + 1))
                data = seeds[data]
                if not ins.verified(data, upto=f + VERIFY_BAND, f=seed_f):
                    continue
                k = int(ins.pos[data])
                g = float(ins.length[data]) + self._rho_l[self._chain_l[k] // 2] * float(ins.sweep[data])
                if g >= dist.get(k, math.inf):
                    continue
                dist[k], parent[k] = g, (-1, data)
            else:
                g, k = data
                if g > dist[k]:
                    continue
            lo, hi, s, m, out = self._ways_out(k)
            here = leave.get(self._chain_l[k])
            if here:
                rho, full = self._rho_l[self._chain_l[k] // 2], self._full_l[self._chain_l[k] // 2]
                for p, extra, length, r in here:
                    idx = p - s
                    if idx < lo and full:
                        idx += m
                    if lo <= idx <= hi:
                        sweep = u[p] - u[k] + (TWO_PI if idx >= m else 0.0) + extra
                        sweep = 0.0 if sweep < 0.0 or (full and sweep > TWO_PI - EPS) else sweep
                        total = g + rho * sweep + length
                        if total < goal_f[r]:
                            goal_f[r] = total
                            heapq.heappush(heap, (total, order, _GOAL, (k, r, sweep)))
                            order += 1
            for p, cost, j, _ in out:
                nd = g + cost
                if nd < dist.get(p, math.inf):
                    dist[p], parent[p] = nd, (k, j)
                    heapq.heappush(heap, (nd + hypot(px[p] - gx, py[p] - gy), order, _STATE, (nd, p)))
                    order += 1
        return None

    def _direct(self, ins: "_Ends", outs: "_Ends") -> list[tuple[float, tuple]]:
        """(cost, (start row, goal row, sweep, known clear)) of the paths that wind round one circle only: in on
        a start tangent, out on a goal tangent of the same chain (one of each at most), arc not yet measured."""
        common, ia, ib = np.intersect1d(ins.chain, outs.chain, return_indices=True)
        if not len(common):
            return []
        full = self._full[common // 2]
        sweep = outs.u[ib] - ins.u[ia]
        sweep = np.where(full, np.mod(sweep, 2 * np.pi), sweep)
        sweep = np.where(full & (sweep > 2 * np.pi - EPS), 0.0, sweep)
        sweep = np.where(~full & (sweep < 0) & (sweep > -EPS), 0.0, sweep)
        # Within one clear piece of the chain, not across its wrap: clear without measuring.
        inside = (ins.piece[ia] == outs.piece[ib]) & ~ins.blocked[ia] & (outs.u[ib] >= ins.u[ia])
        total = ins.length[ia] + self.cs.rho[common // 2] * np.maximum(sweep, 0.0) + outs.length[ib]
        keep = np.flatnonzero(sweep >= 0)
        return [(float(total[k]), (int(ia[k]), int(ib[k]), float(max(sweep[k], 0.0)), bool(inside[k])))
                for k in keep]

    def _route(self, start, goal, length: float, data: tuple, parent: dict, ins: "_Ends", outs: "_Ends") -> Route:
        """The path found walked back through ``parent``: points and contacts in travel order."""
        tin, tout = ins.tans, outs.tans
        if data[0] == "direct":
            _, a, b, sweep, _ = data
            contacts = [self._contact(int(tout.src[b]), int(tout.s1[b]), tin.nt[a], sweep)]
            points = [goal, tout.q[b], tin.t[a], start]
        else:
            k, r_out, sweep = data
            points, contacts, t = [goal, tout.q[r_out]], [], self.tans
        # Walking back: at position k the path arrived on its chain; ``sweep`` ran from k to the way out.
        while data[0] != "direct":
            prev, via = parent[k]
            ch = self._chain_l[k]
            side = 1 if ch % 2 == 0 else -1
            if prev < 0:  # entered from the start: the arc began at the tangent's own point, before k
                sweep += float(ins.sweep[via])
                contacts.append(self._contact(ch // 2, side, tin.nt[via], max(sweep, 0.0)))
                points += [tin.t[via], start]
                break
            contacts.append(self._contact(ch // 2, side, t.nt[via], max(sweep, 0.0)))
            points += [t.t[via], t.q[via]]
            sweep = next(w for _, _, j, w in self._ways_out(prev)[4] if j == via)
            k = prev
        # A contact with no sweep is the path passing straight by a circle (collinear grown edges): left out.
        points, contacts = points[::-1], contacts[::-1]
        keep = [k for k, c in enumerate(contacts) if c.sweep > EPS]
        pts = [points[0]] + [p for k in keep for p in points[1 + 2 * k:3 + 2 * k]] + [points[-1]]
        return Route(np.array(pts, dtype=float), tuple(contacts[k] for k in keep), float(length))

    @staticmethod
    def _contact(circle: int, side: int, normal: np.ndarray, sweep: float) -> Contact:
        return Contact(circle, side, float(math.atan2(normal[1], normal[0])), float(sweep))


class _Ends:
    """A query's tangents from the start (``into``: they enter chains) or to the goal (they leave chains):
    where each meets its chain, the piece of arc it lies in, the position of the chain the path goes on to
    (or comes from) and the sweep to it; and which of them have been tested for clearance (0: not yet)."""

    def __init__(self, rm: Roadmap, tans: Tangents, into: bool):
        self.rm, self.tans, self.into = rm, tans, into
        circle, side, normal = (tans.dst, tans.s2, tans.nt) if into else (tans.src, tans.s1, tans.nq)
        self.rel = rm._rel(circle, normal)
        self.chain = circle * 2 + (side < 0)
        self.u = rm._wind(circle, side, self.rel)
        self.length = tans.length
        self.piece, self.blocked = rm._piece_blocked(self.chain, self.u)
        s, e = rm._start[self.chain], rm._start[self.chain + 1]
        if into:  # on to the chain's next position
            pos = np.searchsorted(rm._key, self.chain * SPAN + self.u - EPS, side="left")
            wrap = pos >= e
            pos = np.where(wrap, s, pos)
        else:  # from the chain's position before
            pos = np.searchsorted(rm._key, self.chain * SPAN + self.u + EPS, side="right") - 1
            wrap = pos < s
            pos = np.where(wrap, e - 1, pos)
        ok = (e > s) & (~wrap | rm._full[circle])
        self.pos = np.where(ok, pos, 0)
        there = rm._u[self.pos] if len(rm._u) else np.zeros(len(tans))
        turn = np.where(wrap, 2 * np.pi, 0.0)  # over a full circle's seam
        self.sweep = np.maximum(there + turn - self.u if into else self.u + turn - there, 0.0)
        self.rows = np.flatnonzero(ok)
        self.seg, self.arc = np.zeros(len(tans), dtype=np.int8), np.zeros(len(tans), dtype=np.int8)

    def verified(self, r: int, arc: bool = True, upto: Optional[float] = None, f=None) -> bool:
        """Row ``r``'s tangent keeps the clearance (and, with ``arc``, so does its arc along the chain); with
        ``upto``, every untested row of :attr:`rows` whose ``f`` is at most ``upto`` is tested in the same call."""
        if self.seg[r] and (not arc or self.arc[r] or self.seg[r] < 0):
            return bool(self.seg[r] == 1 and (not arc or self.arc[r] == 1))
        batch = np.array([r])
        if upto is not None and f is not None:
            more = self.rows[(self.seg[self.rows] == 0) & (f[self.rows] <= upto)]
            batch = np.concatenate([batch, more[more != r]])
        todo = batch[self.seg[batch] == 0]
        if len(todo):
            rm, t = self.rm, self.tans
            none = np.full(len(todo), -1)
            own = rm.cs.owner[t.dst[todo]] if self.into else rm.cs.owner[t.src[todo]]
            clear = rm.cs.segments_clear(t.q[todo], t.t[todo], *((none, own) if self.into else (own, none)))
            self.seg[todo] = np.where(clear, 1, -1)
        if arc:
            todo = batch[(self.arc[batch] == 0) & (self.seg[batch] == 1)]
            if len(todo):
                rm = self.rm
                other = rm._rel_sorted[self.pos[todo]]
                rel_from, rel_to = (self.rel[todo], other) if self.into else (other, self.rel[todo])
                clear = rm._arcs_clear(self.chain[todo], rel_from, rel_to, self.sweep[todo], ~self.blocked[todo])
                self.arc[todo] = np.where(clear, 1, -1)
        return bool(self.seg[r] == 1 and (not arc or self.arc[r] == 1))
