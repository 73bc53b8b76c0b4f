"""One exact shortest-path planner for a disc, two ways of answering it, and the choice between them.

Both answer the same question: the shortest path from a start to a goal in one configuration space,
exact (straight tangents and arcs of the corner circles), as a :class:`~worldgen.feasibility.route.Route`,
or None when there is none. They differ in what they build ahead:

- :class:`~worldgen.feasibility.planner.Planner` builds nothing: A* over the tangent graph, each tangent
  computed when the search first needs it (shared by later queries). Cheap for a few queries.
- :class:`~worldgen.feasibility.roadmap.Roadmap` builds the whole graph once (2 C^2 candidate tangents for C
  corner circles); a query then only adds its two ends. Cheap for many queries in a small space.

:func:`exact_planner` picks the one that costs less for the number of queries coming; callers hold the
:class:`ExactPlanner` protocol, never a class. The answers are the same: lengths equal within 1e-9
(tests/feasibility/test_planner_queries.py checks both against stored answers). Where two paths are equally
long up to rounding, the two may return different ones of them.
"""

from __future__ import annotations

from typing import Optional, Protocol, runtime_checkable

import numpy as np

from worldgen.feasibility.cspace import ConfigSpace
from worldgen.feasibility.planner import Planner
from worldgen.feasibility.roadmap import Roadmap
from worldgen.feasibility.route import Route

__all__ = ["ExactPlanner", "exact_planner", "GRAPH_ROWS_PER_QUERY", "GRAPH_MAX_CIRCLES"]

#: The graph pays from this many candidate tangents (2 C^2) per query coming. Measured in people's walks of
#: the benchmark's world (137 circles): the graph costs about 0.67 us per candidate, a query over it about
#: 0.6 ms less than a lazy one (docs/benchmarks.md, "One tangent graph per walk"); a power of two times the
#: crowd's 117 candidates per person-second (a walk asks about 0.125 queries per person-second), so that
#: the crowd chooses as it did before this module (exactly so wherever people x seconds is exact in floating
#: point, as for whole and half seconds).
GRAPH_ROWS_PER_QUERY = 936
#: ... and only up to this many circles: at 524 circles the build took 1.4 s and 0.5 GB, a query 2.5 ms
#: against the lazy planner's 2.7.
GRAPH_MAX_CIRCLES = 250


@runtime_checkable
class ExactPlanner(Protocol):
    """Exact shortest paths in one configuration space."""

    cs: ConfigSpace

    def shortest(self, start: np.ndarray, goal: np.ndarray) -> Optional[Route]:
        """The shortest path from ``start`` to ``goal`` ((2,) each, both free), or None if there is none."""
        ...


def exact_planner(cs: ConfigSpace, queries: float) -> ExactPlanner:
    """The exact planner for about ``queries`` shortest paths in ``cs``: the prebuilt graph when its build
    costs less than the queries it saves (and the space is small enough to hold it), else the lazy search."""
    c = cs.n_circles
    if c <= GRAPH_MAX_CIRCLES and 2 * c * c <= GRAPH_ROWS_PER_QUERY * queries:
        return Roadmap(cs)
    return Planner(cs)
