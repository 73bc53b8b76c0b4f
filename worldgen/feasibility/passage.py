"""The narrowest passage of a task: the widest disc that can still get from spawn to goal.

A disc of radius r can travel where the clearance field is at least r, so the
bottleneck radius is the largest r for which the spawn's and the goal's cells
lie in one connected region of ``field >= r`` (never more than the clearance
of the spawn or the goal themselves). It is found by bisection over r, each
step one connected-component labelling of the grid.

Accuracy: the field is exact at cell centres, but connectivity is judged
between neighbouring centres (8-connected), so the radius is accurate to about
half a cell diagonal, i.e. the reported width (2 x radius) to about one grid
resolution ``h`` (the report's ``resolution``): a corridor of width w reports a
value in [w - h, w] (+ the bisection tolerance of h / 8).
"""

from __future__ import annotations

import numpy as np
from scipy import ndimage

from worldgen.feasibility.field import DistanceField

__all__ = ["bottleneck_radius", "extend_field"]

_EIGHT = np.ones((3, 3), dtype=bool)


def extend_field(field: DistanceField) -> DistanceField:
    """The field with the cells it capped filled in from a Euclidean distance transform.

    A capped cell c gets D(q) + |c - q|, where q is the nearest cell of the exact
    band (values below cap) and D(q) its exact clearance: an upper bound on c's
    clearance (distance is 1-Lipschitz) that is tight when q lies on the way from
    c to its nearest obstacle, as it does up to the grid's resolution. One C pass
    over the grid instead of exact distances to every obstacle far out; the
    passage figure stays accurate to about a grid cell.
    """
    g = field.grid
    capped = field.values >= field.cap
    if not capped.any() or capped.all():
        return field
    reach, (qi, qj) = ndimage.distance_transform_edt(capped, sampling=(g.hx, g.hy), return_indices=True)
    values = np.where(capped, field.values[qi, qj] + reach, field.values)
    return DistanceField(g, values, float(values.max()))


def bottleneck_radius(field: DistanceField, start: np.ndarray, goal: np.ndarray, low: float, high: float) -> float:
    """Largest r in [low, high] with start and goal connected through cells of clearance >= r.

    ``low`` must be a radius known to connect them (e.g. the inflation radius of
    a found path) and ``high`` an upper bound (the smaller of the endpoints'
    exact clearances, and at most the field's cap). Returns ``low`` if even a
    hair more does not connect.
    """
    g = field.grid
    si, sj = (int(v[0]) for v in g.cell_of(start))
    gi, gj = (int(v[0]) for v in g.cell_of(goal))
    tol = min(g.hx, g.hy) / 8

    def connected(r: float) -> bool:
        labels, _ = ndimage.label(field.values >= r, structure=_EIGHT)
        a = labels[max(si - 1, 0):si + 2, max(sj - 1, 0):sj + 2]
        b = labels[max(gi - 1, 0):gi + 2, max(gj - 1, 0):gj + 2]
        common = np.intersect1d(a[a > 0], b[b > 0])
        return len(common) > 0

    if high <= low:
        return high
    if connected(high):
        return high
    while high - low > tol:
        mid = 0.5 * (low + high)
        if connected(mid):
            low = mid
        else:
            high = mid
    return low
