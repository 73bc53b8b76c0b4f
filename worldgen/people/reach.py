"""Which places a walking person can never reach: a proof of disconnection that costs no planner query.

Among many obstacles (65 boxes on 10 x 10 m) the free floor falls apart into pockets, and a person's
drawn places often lie in another pocket than the person. The exact planner says so only after searching
the person's whole pocket (10 to 150 ms a query); a walk asked it several hundred times and spent 15 of
its 16 s there (``cluttered --seed 5 --set n_obstacles=65 --set n_people=10``, cProfile).

:class:`Pockets` is a superset of the planner's free space: the floor box shrunk by the planner's
radius, less every obstacle grown by that radius as shapely buffers it (each arc a polygon whose
vertices lie on the arc, so inside the exact rounded offset), with the radius a further
:data:`MARGIN` smaller. Two points in different components of this superset are in different
components of the exact free space, so a query between them fails; the router skips it and asks the
planner only where the superset joins the two. The answer is the planner's either way, so the walks,
and the worlds, are the same bytes (``tests/people/test_reach.py`` compares both on every query of a
sweep).
"""

from __future__ import annotations

from typing import Optional

import numpy as np
import shapely

__all__ = ["MARGIN", "QUAD_SEGS", "Pockets"]

#: m: how much smaller than the planner's radius the obstacles are grown, so that rounding never makes the
#: superset thinner than the exact free space (the planner's own tolerances are far below it).
MARGIN = 1e-6
#: Segments per quarter circle of a buffered corner (shapely's ``quad_segs``); finer costs time, coarser
#: only joins pockets the exact space keeps apart (a query then answers, as before).
QUAD_SEGS = 64


class Pockets:
    """The components of a free space that contains the configuration space ``cs``'s."""

    def __init__(self, cs):
        grow = max(cs.radius - MARGIN, 0.0)
        obstacles = cs.obstacles
        shapes = [shapely.Polygon(ring).buffer(grow, quad_segs=QUAD_SEGS) for ring in obstacles.poly_vertices]
        shapes += [shapely.Point(xy).buffer(r + grow, quad_segs=QUAD_SEGS)
                   for xy, r in zip(obstacles.disc_xy, obstacles.disc_r)]
        x0, y0, x1, y1 = cs.box
        floor = shapely.box(x0 - MARGIN, y0 - MARGIN, x1 + MARGIN, y1 + MARGIN)
        free = floor.difference(shapely.union_all(shapes)) if shapes else floor
        self.parts = [g for g in getattr(free, "geoms", [free]) if not g.is_empty]
        for part in self.parts:
            shapely.prepare(part)
        self._bounds = np.array([p.bounds for p in self.parts]).reshape(-1, 4)

    def of(self, xy) -> Optional[int]:
        """The component holding point ``xy``, None where it lies in none (or on a component's edge)."""
        x, y = float(xy[0]), float(xy[1])
        b = self._bounds
        for k in np.flatnonzero((b[:, 0] <= x) & (x <= b[:, 2]) & (b[:, 1] <= y) & (y <= b[:, 3])):
            if shapely.contains_xy(self.parts[k], x, y):
                return int(k)
        return None

    def apart(self, a, b) -> bool:
        """True when no path joins ``a`` and ``b`` in the exact free space (proven: different components of
        the superset); False when the planner has to be asked."""
        ka, kb = self.of(a), self.of(b)
        return ka is not None and kb is not None and ka != kb
