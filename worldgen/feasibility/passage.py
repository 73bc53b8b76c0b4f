"""The narrowest passage of a task: the widest disc that can still get from spawn to goal.

A disc of radius r can travel where the clearance field is at least r, so the
bottleneck radius is the largest r for which the spawn's and the goal's cells
lie in one connected region of ``field >= r`` (never more than the clearance
of the spawn or the goal themselves). It is found by bisection over r, each
step one connected-component labelling of the grid.

Accuracy: the field is exact at cell centres, but connectivity is judged
between neighbouring centres (8-connected), so the grid's width (2 x radius)
is good to about one grid resolution ``h`` (the report's ``resolution``; a
little more was measured, up to 1.2 h). :func:`exact_width` then snaps it to
the exact gap between the two obstacles that explain it, so a corridor of width
w reports w; where no pair explains it, the grid's figure stands.
"""

from __future__ import annotations

import numpy as np
from scipy import ndimage

from worldgen.feasibility.field import DistanceField
from worldgen.feasibility.portals import gaps

__all__ = ["bottleneck_radius", "extend_field", "exact_width"]

_EIGHT = np.ones((3, 3), dtype=bool)
#: Probes along a gap, each way, in cells, looking for a free point on the route (see exact_width).
_PROBES = 12


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


def exact_width(width: float, field: DistanceField, obstacles, start: np.ndarray, goal: np.ndarray) -> float:
    """The grid's passage ``width`` snapped to the exact gap between two obstacles that explains it.

    With convex obstacles, the narrowest point of the widest route is the gap
    between two of them (the segment between their closest points), so the true
    width is one of those gaps. The grid's figure is within about a cell of it:
    take the gap in that band whose midpoint lies on the spawn-goal side of the
    field at that level, is no nearer any third obstacle, and is closest to the
    grid's figure plus half a cell (its usual shortfall). Where no gap fits (the
    bottleneck is the edge of the bounds, say), the grid's figure stands.
    """
    g = field.grid
    cell = max(g.hx, g.hy)
    lo, hi = width - 1.5 * cell, width + 2.5 * cell
    found = [(w, m, n) for w, m, n in gaps(obstacles, hi) if w >= lo]
    if not found:
        return width
    labels, _ = ndimage.label(field.values >= max(width / 2 - cell, 0.0), structure=_EIGHT)
    si, sj = (int(v[0]) for v in g.cell_of(start))
    gi, gj = (int(v[0]) for v in g.cell_of(goal))
    a = labels[max(si - 1, 0):si + 2, max(sj - 1, 0):sj + 2]
    b = labels[max(gi - 1, 0):gi + 2, max(gj - 1, 0):gj + 2]
    route = np.intersect1d(a[a > 0], b[b > 0])
    widths = np.array([w for w, _, _ in found])
    # Closest points are not unique between parallel walls, and the pair found may sit at a
    # corridor's closed end: probe along the gap (its normal) for a point of the same clearance.
    shifts = np.arange(-_PROBES, _PROBES + 1) * cell
    probes = np.concatenate([m + shifts[:, None] * n for _, m, n in found])
    owner = np.repeat(np.arange(len(found)), len(shifts))
    pi, pj = g.cell_of(probes)
    (x0, y0) = g.origin
    inside = ((probes[:, 0] > x0) & (probes[:, 0] < x0 + g.nx * g.hx)
              & (probes[:, 1] > y0) & (probes[:, 1] < y0 + g.ny * g.hy))
    on_route = inside & np.isin(labels[pi, pj], route) & (labels[pi, pj] > 0)
    # A third obstacle nearer the probe than half the gap closes the gap there.
    # (A bounded query: only obstacles within half the widest gap can close one.)
    free = obstacles.segments_distance(probes, probes, float(widths.max()) / 2)[0] >= widths[owner] / 2 - 1e-9
    keep = np.zeros(len(found), dtype=bool)
    np.logical_or.at(keep, owner, on_route & free)
    if not keep.any():
        return width
    widths = widths[keep]
    return float(widths[np.argmin(np.abs(widths - (width + 0.5 * cell)))])
