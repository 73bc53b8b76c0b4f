"""The exact shortest path for a disc: A* over the tangent visibility graph, built lazily.

Nodes are the points where a common tangent (see :mod:`~worldgen.feasibility.tangents`)
touches a corner circle, together with the side the path winds round it.
From a node the path follows the circle's arc the way it winds (an arc inside
the circle's cone, clear of every other obstacle) and leaves on another tangent
of the same side: to another obstacle, to the goal, or (for a polygon corner)
along the grown edge to the next corner. The graph holds every taut path, so
the search returns the true optimum; its length counts the arcs exactly.

Nothing is built ahead:

- A node asks for tangents only to the obstacles that could still lie on a
  path of length ``f`` through it (``g + |p - x| + |x - goal|`` over the
  obstacle's bounding disc), and comes back for the others when the search
  reaches their bound (partial expansion).
- Tangents between two obstacles are computed once and shared by every node on them.
- A node reached no cheaper than an already expanded node on the same circle
  can reach it along the arc is skipped (it is dominated).
- Nodes whose keys lie within :data:`BATCH` of the smallest (or :data:`BATCH_SHARE` of that
  key, whichever is wider) are expanded together, so that the geometry runs in few, large
  vectorised calls. Expanding a node a little early never loses the optimum: every node stays
  reachable, and the search stops only when no key left is below the best path found.

The bounds themselves, and the band of obstacles a node asks for at once, are
:mod:`~worldgen.feasibility.bounds`'s.
"""

from __future__ import annotations

import heapq
import math
from typing import Optional

import numpy as np

from worldgen.feasibility.bounds import lower_bounds, next_band
from worldgen.feasibility.cspace import ConfigSpace
from worldgen.feasibility.route import Contact, Route
from worldgen.feasibility.tangents import (
    TangentBatch,
    Tangents,
    TangentStore,
    every_side,
    grown_edges,
    lonely_circles,
    tangents,
)

__all__ = ["Planner"]

#: Slack (m) added to a node's bound when it asks for tangents, so that one
#: request covers the obstacles just beyond it.
BAND = 0.25
#: Nodes whose keys lie within this (m) of the smallest are expanded together. Tuned on cluttered
#: 20 x 20 m worlds (40 seeds each, same paths): 0.5 and 16 took 3.2 / 14.3 ms a query at 50 / 200
#: obstacles, these 2.7 / 13.5 ms; no batching (0) is fastest at 50 but 1.5x slower at 200.
BATCH = 0.25
#: ... or within this share of the key, whichever is wider; the same for a node's band. A long detour
#: (a path hundreds of metres round walls) otherwise takes thousands of rounds of a few cm each: a
#: 500 m door world found by `make fuzz` took over 300 s with 0 and takes 0.1 s with this; the
#: 50- and 200-obstacle queries above are unchanged (2.6 / 12.7 ms).
BATCH_SHARE = 0.02


class _Node:
    __slots__ = ("circle", "side", "normal", "point", "g", "parent", "lb", "done", "prev_done", "rel")

    def __init__(self, circle, side, normal, point, g, parent):
        self.circle = circle
        self.side = side
        self.normal = normal
        self.point = point
        self.g = g
        self.parent = parent  # (parent node index, departure normal, departure point); None at the start
        self.lb = None  # per-obstacle bounds, once expanded
        self.done = -math.inf  # bound up to which tangents were taken
        self.prev_done = -math.inf  # ... before the last request
        self.rel = 0.0  # the arrival's angle within the circle's cone


class Planner:
    """Shortest paths in one configuration space; tangents between obstacles are shared by every query."""

    def __init__(self, cs: ConfigSpace):
        self.cs = cs
        n = len(cs.obstacles)
        self._have: dict[int, np.ndarray] = {}  # per (circle, side): the obstacles its tangents were computed to
        self._store = TangentStore()
        self._angle0 = np.arctan2(cs.cone_a[:, 1], cs.cone_a[:, 0])
        self._full = cs.full
        self._hull_max = float(cs.hull_r.max()) if n else 0.0
        self._arc_free = lonely_circles(cs)
        self._edges = grown_edges(cs)

    # -- the search --------------------------------------------------------
    def shortest(self, start, goal) -> Optional[Route]:
        """The shortest path from ``start`` to ``goal`` ((2,) each, both free), or None if there is none."""
        cs = self.cs
        start = np.asarray(start, dtype=float)
        goal = np.asarray(goal, dtype=float)
        if cs.segments_clear(start[None], goal[None])[0]:
            return Route(np.array([start, goal]), (), float(np.hypot(*(goal - start))))
        self._goal = goal
        self._nodes: list[_Node] = [_Node(-1, 0, None, start, 0.0, None)]
        self._heap = [(float(np.hypot(*(goal - start))), 0, 0)]
        self._tie = 1
        self._expanded: dict[tuple[int, int], list[tuple[float, float]]] = {}
        self._best: tuple[float, Optional[tuple[int, np.ndarray, np.ndarray]]] = (math.inf, None)
        heap = self._heap
        while heap and heap[0][0] < self._best[0] - 1e-12:
            limit = heap[0][0] + max(BATCH, BATCH_SHARE * heap[0][0])
            batch = []
            while heap and heap[0][0] <= limit and heap[0][0] < self._best[0] - 1e-12:
                key, _, i = heapq.heappop(heap)
                batch.append((key, i))
            self._expand(batch)
        if self._best[1] is None:
            return None
        return self._route(start, goal)

    def _push(self, node: _Node) -> None:
        self._nodes.append(node)
        key = node.g + math.hypot(self._goal[0] - node.point[0], self._goal[1] - node.point[1])
        heapq.heappush(self._heap, (key, self._tie, len(self._nodes) - 1))
        self._tie += 1

    def _expand(self, batch: list[tuple[float, int]]) -> None:
        """Expand a batch of nodes popped together: their tangents to the goal and along the grown edges,
        their departures to the obstacles in each node's band, then the best arrival and the new nodes."""
        live, fresh_circles = self._admit(batch)
        out, goals = TangentBatch(), TangentBatch()
        if fresh_circles:
            self._from_fresh_circles(fresh_circles, out, goals)
        self._departures(live, out)
        self._settle(goals, out)

    def _admit(self, batch: list[tuple[float, int]]) -> tuple[list[tuple[float, int]], list[int]]:
        """The batch less the nodes dominated on their circle; fresh nodes get their lower bounds."""
        nodes = self._nodes
        live, fresh_circles, fresh = [], [], []
        dominated = self._dominated([i for _, i in batch if nodes[i].lb is None and nodes[i].circle >= 0])
        for key, i in batch:
            node = nodes[i]
            if node.lb is None:
                if node.circle >= 0:
                    if i in dominated:
                        continue
                    self._expanded.setdefault((node.circle, node.side), []).append((node.rel, node.g))
                    fresh_circles.append(i)
                fresh.append(node)
            live.append((key, i))
        if fresh:
            for node, lb in zip(fresh, self._bounds(fresh)):
                node.lb = lb
        return live, fresh_circles

    def _from_fresh_circles(self, fresh_circles: list[int], out: TangentBatch, goals: TangentBatch) -> None:
        """Fresh nodes on circles: straight to the goal, and along the grown edge to the next corner."""
        cs, nodes, goal = self.cs, self._nodes, self._goal
        idx = np.array(fresh_circles)
        circles = np.array([nodes[i].circle for i in fresh_circles])
        sides = np.array([nodes[i].side for i in fresh_circles])
        # Tangents to the goal once per (circle, side); every node there may take them.
        key = circles * 2 + (sides < 0)
        uniq, first = np.unique(key, return_index=True)
        among = self._blockers([nodes[i] for i in fresh_circles], None)
        tans = tangents(cs, circles[first], np.full(len(first), -1), sides[first],
                        np.ones(len(first), dtype=np.int64), dst_xy=goal, among=among)
        if len(tans):
            tkey = tans.src * 2 + (tans.s1 < 0)
            for k in range(len(idx)):
                rows = np.flatnonzero(tkey == key[k])
                goals.add(np.full(len(rows), idx[k]), tans.take(rows))
        edge_rows = self._edges.pick(circles, sides)
        keep = edge_rows >= 0
        out.add(idx[keep], self._edges.tans.take(edge_rows[keep]))

    def _departures(self, live: list[tuple[float, int]], out: TangentBatch) -> None:
        """Departures to the obstacles in each node's band; a node with bounds beyond it goes back on the heap."""
        cs, nodes = self.cs, self._nodes
        requests = []
        for key, i in live:
            node = nodes[i]
            band, upto = self._band(node, key + max(BAND, BATCH_SHARE * key))
            node.prev_done, node.done = node.done, upto
            rest = node.lb[node.lb > upto]
            if len(rest):
                heapq.heappush(self._heap, (float(rest.min()), self._tie, i))
                self._tie += 1
            if len(band):
                requests.append((i, band, upto))
        if not requests:
            return
        self._fill_tables(requests)
        picked, owners = [], []
        for i, band, upto in requests:
            node = nodes[i]
            if node.circle < 0:
                dst = cs.circles_of(band)
                src, dst, s1, s2 = every_side(np.full(len(dst), -1), dst, (1,), (1, -1))
                tans = tangents(cs, src, dst, s1, s2, src_xy=node.point, among=self._blockers([node], None))
                out.add(np.full(len(tans), i), tans)
                continue
            rows = self._store.rows(node.circle, node.side)
            if len(rows):
                # This request's band: the obstacles whose bound it has just passed.
                lb = node.lb[self._store.dst_owner[rows]]
                rows = rows[(lb > node.prev_done) & (lb <= upto)]
                picked.append(rows)
                owners.append(np.full(len(rows), i))
        if picked:
            out.add(np.concatenate(owners), self._store.take(np.concatenate(picked)))

    def _settle(self, goals: TangentBatch, out: TangentBatch) -> None:
        """The best arrival at the goal so far, and a node for every unblocked tangent's end."""
        idx, tans = goals.merged()
        if idx is not None:
            g = self._leave(idx, tans)
            k = int(np.argmin(g))
            if g[k] < self._best[0]:
                self._best = (float(g[k]), (int(idx[k]), tans.nq[k], tans.q[k]))
        idx, tans = out.merged()
        if idx is not None:
            g = self._leave(idx, tans)
            for r in np.flatnonzero(np.isfinite(g)):
                self._push(_Node(int(tans.dst[r]), int(tans.s2[r]), tans.nt[r], tans.t[r], float(g[r]),
                                 (int(idx[r]), tans.nq[r], tans.q[r])))

    def _leave(self, idx: np.ndarray, tans: Tangents) -> np.ndarray:
        """(m,) cost at the far end of each tangent, leaving node ``idx[k]`` along its arc (inf if blocked)."""
        nodes = self._nodes
        g = np.array([nodes[i].g for i in idx]) + tans.length
        on = np.flatnonzero(tans.src >= 0)
        if len(on) == 0:
            return g
        circle = tans.src[on]
        side = tans.s1[on]
        rel_in = np.array([nodes[i].rel for i in idx[on]])
        rel_out = self._rel_many(circle, tans.nq[on])
        sweep = (rel_out - rel_in) * side
        full = self._full[circle]
        sweep = np.where(full, np.mod(sweep, 2 * np.pi), sweep)
        sweep = np.where(full & (sweep > 2 * np.pi - 1e-9), 0.0, sweep)
        sweep = np.where(~full & (sweep < 0) & (sweep > -1e-9), 0.0, sweep)
        ok = sweep >= 0
        check = np.flatnonzero(ok & (sweep > 0) & ~self._arc_free[circle])
        if len(check):
            start = self._angle0[circle[check]] + np.where(side[check] > 0, rel_in[check], rel_out[check])
            slack = self.cs.arc_clearance(circle[check], start, sweep[check])
            ok[check[slack < -1e-9]] = False
        g[on] = np.where(ok, g[on] + self.cs.rho[circle] * np.maximum(sweep, 0.0), np.inf)
        return g

    # -- bounds, bands and tables --------------------------------------------
    def _bounds(self, nodes: list[_Node]) -> np.ndarray:
        """(k, N) per node: a lower bound on the length of any path through it whose next obstacle is each one."""
        return lower_bounds(self.cs, self._goal, np.array([n.point for n in nodes]), np.array([n.g for n in nodes]),
                            np.array([n.circle for n in nodes]))

    def _band(self, node: _Node, hi: float) -> tuple[np.ndarray, float]:
        """The obstacles whose bound lies in (node.done, hi], and the bound up to which they are taken."""
        return next_band(node.lb, node.done, hi)

    def _blockers(self, nodes: list[_Node], upto: Optional[float]) -> np.ndarray:
        """Ids of the obstacles that can meet a tangent leaving any of ``nodes``' obstacles towards one
        whose bound is at most ``upto`` (each node's own ``done`` when None), or towards the goal.

        With phi(x) = |p - x| + |x - goal| (convex), such a tangent runs between a point
        of the node's obstacle's bounding disc and one of the other's (or the goal),
        where phi is at most (upto - g) + 4 r_max (r_max: the largest bounding radius);
        so does any obstacle it meets, whose bound is then at most upto + 4 r_max.
        """
        near = np.zeros(len(self.cs.obstacles), dtype=bool)
        for node in nodes:
            reach = node.done if upto is None else upto
            reach = max(reach, node.g + math.hypot(self._goal[0] - node.point[0], self._goal[1] - node.point[1]))
            near |= node.lb <= reach + 4 * self._hull_max
        return np.flatnonzero(near)

    def _fill_tables(self, requests) -> None:
        """Compute, in one call, every tangent the requests need that no earlier request did: from each
        node's own circle and side (the only rows it reads) to every circle of its band's new obstacles."""
        cs = self.cs
        src_parts, dst_parts, s1_parts, nodes = [], [], [], []
        for i, band, _ in requests:
            node = self._nodes[i]
            if node.circle < 0:
                continue
            have = self._have.setdefault(node.circle * 2 + (node.side < 0), np.zeros(len(cs.obstacles), dtype=bool))
            todo = band[~have[band]]
            if len(todo):
                have[todo] = True
                dst_c = cs.circles_of(todo)
                src_parts.append(np.full(len(dst_c), node.circle))
                dst_parts.append(dst_c)
                s1_parts.append(np.full(len(dst_c), node.side))
                nodes.append(node)
        if src_parts:
            src, dst, s1 = np.concatenate(src_parts), np.concatenate(dst_parts), np.concatenate(s1_parts)
            n = len(src)
            s2 = np.repeat(np.array([1, -1], dtype=np.int64), n)
            self._store.add(tangents(cs, np.tile(src, 2), np.tile(dst, 2), np.tile(s1, 2), s2,
                                     among=self._blockers(nodes, None)), cs)

    # -- arcs --------------------------------------------------------------
    def _rel(self, circle: int, normal: np.ndarray) -> float:
        return float(self._rel_many(np.array([circle]), normal[None])[0])

    def _rel_many(self, circle: np.ndarray, normals: np.ndarray) -> np.ndarray:
        """Angle (rad) of each outward normal from its circle's cone start, counter-clockwise."""
        ang = np.mod(np.arctan2(normals[:, 1], normals[:, 0]) - self._angle0[circle], 2 * np.pi)
        # A normal a hair before a polygon cone's start is its start.
        return np.where(~self._full[circle] & (ang > self.cs.cone_w[circle] + 1e-6), 0.0, ang)

    def _dominated(self, fresh: list[int]) -> set[int]:
        """Those of the ``fresh`` nodes that a node already expanded on the same circle and side reaches
        along its arc no dearer (the arcs to check go to the geometry in one call)."""
        nodes, out = self._nodes, set()
        asks = []  # (node index, circle, start angle, sweep) of arcs that decide a dominance
        for i in fresh:
            node = nodes[i]
            node.rel = self._rel(node.circle, node.normal)
            seen = self._expanded.get((node.circle, node.side))
            if not seen:
                continue
            c, rho, full = node.circle, self.cs.rho[node.circle], self._full[node.circle]
            for rel0, g0 in seen:
                sweep = (node.rel - rel0) * node.side
                if full:
                    sweep %= 2 * math.pi
                if sweep < -1e-9 or g0 + rho * max(sweep, 0.0) > node.g + 1e-9:
                    continue
                if sweep <= 0 or self._arc_free[c]:
                    out.add(i)
                    break
                asks.append((i, c, self._angle0[c] + (rel0 if node.side > 0 else node.rel), sweep))
        asks = [a for a in asks if a[0] not in out]
        if asks:
            who, circle, start, sweep = (np.array(v) for v in zip(*asks))
            free = self.cs.arc_clearance(circle.astype(np.int64), start, sweep) >= -1e-9
            out.update(int(k) for k in who[free])
        return out

    # -- the answer --------------------------------------------------------
    def _route(self, start, goal) -> Route:
        nodes = self._nodes
        g, found = self._best
        assert found is not None, "called once a search has found a path"
        i, n_out, q_out = found
        points = [goal, q_out]
        contacts = []
        out_normal = n_out
        while i > 0:
            node = nodes[i]
            rel_out = self._rel(node.circle, out_normal)
            sweep = (rel_out - node.rel) * node.side
            if self._full[node.circle]:
                sweep %= 2 * math.pi
                if sweep > 2 * math.pi - 1e-9:
                    sweep = 0.0
            contacts.append(Contact(node.circle, node.side,
                                    float(math.atan2(node.normal[1], node.normal[0])), max(float(sweep), 0.0)))
            points.append(node.point)
            i, out_normal, q = node.parent
            if i > 0:
                points.append(q)
        points.append(start)
        return Route(np.array(points[::-1], dtype=float), tuple(contacts[::-1]), float(g))
