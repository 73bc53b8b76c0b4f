"""Where each walking person of the crowd model is headed: its places in order, the shortest path to the
current one, and the waypoint of that path it steers at (:mod:`~worldgen.people.crowd` does the walking).

A waypoint is passed when the next one is in sight (checked every :data:`LOOK` steps), and the path is
planned again from where the person stands when its waypoint has been out of sight for :data:`REPLAN`
checks (unless the waypoint before it is in sight: then the person walks back to that one, which leads
on). A person who has moved less than :data:`STUCK` m a look for ``2 x REPLAN`` looks in a row (held by
others, or by a wall's push near a place) gives that place up and walks to the next. A place in another
pocket of the floor (:mod:`~worldgen.people.reach`) is given up without asking the planner.
"""

from __future__ import annotations

import numpy as np

from worldgen.feasibility.cspace import ConfigSpace
from worldgen.feasibility.exact import ExactPlanner
from worldgen.people.reach import Pockets

__all__ = ["Router", "LOOK", "REPLAN", "ARRIVE", "STUCK"]

#: Steps between two looks ahead (is the next waypoint in sight?).
LOOK = 5
#: Looks with the waypoint out of sight before the path is planned again from where the person is.
REPLAN = 4
#: Distance (m) at which a waypoint counts as reached.
ARRIVE = 0.2
#: Least distance (m) a walking person covers between two looks before it counts as held up.
STUCK = 0.1


class Router:
    """Each person's places and the planned path to the current one; ``target`` the waypoint steered to."""

    def __init__(self, planner: ExactPlanner, sight: ConfigSpace, starts: np.ndarray, places: np.ndarray):
        # Sight is tested in a configuration space SLACK thinner than the planner's (a waypoint on a planner's
        # circle is then in sight, not touching); places in another pocket are skipped without a query.
        self.planner, self.sight, self.places, self.pockets = planner, sight, places, Pockets(planner.cs)
        n = len(starts)
        self.place = np.full(n, -1)
        self.route: list[np.ndarray] = [np.zeros((0, 2))] * n
        self.way = np.zeros(n, dtype=np.int64)
        self.unseen = np.zeros(n, dtype=np.int64)
        self.held = np.zeros(n, dtype=np.int64)
        self.last = starts.copy()
        self.done = np.zeros(n, dtype=bool)
        self.target = starts.copy()
        for i in range(n):
            self._next_place(i, starts[i])

    def _next_place(self, i: int, at: np.ndarray) -> None:
        """Plan from ``at`` to the next place that can be reached; done when none is left."""
        while self.place[i] + 1 < self.places.shape[1] and not np.isnan(self.places[i, self.place[i] + 1, 0]):
            self.place[i] += 1
            if self._plan(i, at):
                return
        self.done[i] = True
        self.target[i] = at

    def _plan(self, i: int, at: np.ndarray) -> bool:
        goal = self.places[i, self.place[i]]
        route = None if self.pockets.apart(at, goal) else self.planner.shortest(at, goal)
        if route is None:
            return False
        # The route keeps its start, so that the waypoint before the one steered at always exists.
        self.route[i], self.way[i], self.unseen[i] = route.points, 1, 0
        self.target[i] = self.route[i][1]
        return True

    def update(self, p: np.ndarray, step: int, waiting: np.ndarray) -> None:
        """Pass reached waypoints; every LOOK steps, skip to a waypoint in sight or plan again
        (``waiting``: those not yet set off, left alone)."""
        reached = ~self.done & ~waiting & (np.hypot(*(self.target - p).T) < ARRIVE)
        for i in np.flatnonzero(reached):
            self._advance(int(i), p[i])
        if step % LOOK:
            return
        live = np.flatnonzero(~self.done & ~waiting)
        if not len(live):
            return
        moved = np.hypot(*(p - self.last).T) >= STUCK
        self.held = np.where(moved | waiting, 0, self.held + 1)
        self.last = p.copy()
        for i in live[self.held[live] >= 2 * REPLAN]:
            self.held[i] = 0
            self._next_place(i, p[i])
        live = live[~self.done[live]]
        if not len(live):
            return
        cs = self.sight
        routes, way = [self.route[i] for i in live], self.way[live]
        ahead = np.array([r[min(w + 1, len(r) - 1)] for r, w in zip(routes, way)])
        back = np.array([r[w - 1] for r, w in zip(routes, way)])
        seen = cs.segments_clear(np.vstack([p[live]] * 3), np.vstack([ahead, self.target[live], back]))
        m = len(live)
        see_ahead, see_target, see_back = seen[:m], seen[m:2 * m], seen[2 * m:]
        for k, i in enumerate(live):
            if see_ahead[k] and self.way[i] + 1 < len(self.route[i]):
                self.way[i] += 1
                self.target[i] = self.route[i][self.way[i]]
                see_target[k] = True
        self.unseen[live[see_target]] = 0
        blind = np.flatnonzero(~see_target)
        self.unseen[live[blind]] += 1  # looks in a row with the waypoint out of sight
        for k in blind[self.unseen[live[blind]] >= REPLAN]:
            i = live[k]
            self.unseen[i] = 0
            if see_back[k]:  # pushed back round a corner: the waypoint before is in sight, and leads on
                self.way[i] -= 1
                self.target[i] = self.route[i][self.way[i]]
            elif self.planner.cs.points_clearance(p[i][None])[0] > 0:
                self._plan(i, p[i])

    def _advance(self, i: int, at: np.ndarray) -> None:
        if self.way[i] + 1 < len(self.route[i]):
            self.way[i] += 1
            self.target[i] = self.route[i][self.way[i]]
        else:
            self._next_place(i, at)
