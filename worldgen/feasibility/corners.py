"""Building a configuration space: the corner circles of obstacles grown by a disc, and who neighbours whom.

:class:`~worldgen.feasibility.cspace.ConfigSpace` holds a grown obstacle as the circles its boundary is
made of (the module's docstring says why); this is where they come from, all obstacles at once as flat
arrays. A disc grows into one circle of the larger radius, usable at every angle. A convex polygon grows
into one circle of ``radius`` per vertex, usable over the cone between the outward normals of the vertex's
two edges (counter-clockwise, the ring's order); a vertex whose edges are collinear has no cone and no
circle. Each obstacle also gets a disc containing it grown (``hull``), a disc about the same centre within
it (``core``), both to settle most distance tests without looking at edges, and the list of obstacles
near enough for its grown boundary to come close to theirs.
"""

from __future__ import annotations

import numpy as np
import shapely

from worldgen.feasibility.geometry import Obstacles2D, cross

__all__ = ["corner_circles", "NEAR_MARGIN"]

#: How far beyond touching (as a fraction of the radius) an obstacle's neighbours are kept.
NEAR_MARGIN = 0.1
#: Polygon vertices whose cone is narrower than this (rad) are collinear: no circle.
_FLAT = 1e-12


def corner_circles(obstacles: Obstacles2D, radius: float) -> dict[str, np.ndarray]:
    """The per-circle and per-obstacle arrays of :class:`~worldgen.feasibility.cspace.ConfigSpace` (its fields
    from ``centre`` to ``nb_ids``, named as there) for a disc of ``radius`` among ``obstacles``."""
    nd, n = obstacles.n_discs, len(obstacles)
    # Polygon corners, all rings at once: edge k runs from vertex k to the next of its ring.
    e = obstacles.edge_b - obstacles.edge_a
    normals = np.stack([e[:, 1], -e[:, 0]], axis=1)
    normals /= np.maximum(np.linalg.norm(normals, axis=1, keepdims=True), 1e-300)
    ring_start = obstacles.edge_start[obstacles.edge_owner]
    ring_len = obstacles.edge_start[obstacles.edge_owner + 1] - ring_start
    local = np.arange(len(e)) - ring_start
    before = normals[ring_start + (local - 1) % np.maximum(ring_len, 1)]  # the edge ending at vertex k
    width = np.arctan2(cross(before, normals), np.einsum("ij,ij->i", before, normals))
    keep = width > _FLAT
    corner = np.flatnonzero(keep)
    poly_owner = obstacles.edge_owner[corner] + nd
    # Circle ids: the discs', then each polygon's kept corners in ring order.
    count = np.concatenate([np.ones(nd, dtype=np.int64), np.bincount(poly_owner - nd, minlength=n - nd)])
    first = np.concatenate([[0], np.cumsum(count)]).astype(np.int64)
    ids = nd + np.arange(len(corner))
    own_first = first[poly_owner]
    own_count = count[poly_owner]
    pos = ids - own_first
    x_axis = np.tile([[1.0, 0.0]], (nd, 1))
    centre = np.concatenate([obstacles.disc_xy, obstacles.edge_a[corner]])
    rho = np.concatenate([obstacles.disc_r + radius, np.full(len(corner), float(radius))])
    cone_a = np.concatenate([x_axis, before[corner]])
    cone_b = np.concatenate([x_axis, normals[corner]])
    cone_w = np.concatenate([np.full(nd, 2 * np.pi), width[corner]])
    owner = np.concatenate([np.arange(nd), poly_owner]).astype(np.int64)
    nxt = np.concatenate([np.full(nd, -1), own_first + (pos + 1) % np.maximum(own_count, 1)]).astype(np.int64)
    prv = np.concatenate([np.full(nd, -1), own_first + (pos - 1) % np.maximum(own_count, 1)]).astype(np.int64)
    lo, hi = obstacles.boxes[:, :2], obstacles.boxes[:, 2:]
    hull_c = (lo + hi) / 2
    hull_r = np.hypot(*(hi - lo).T) / 2 + radius
    if nd:
        hull_c[:nd] = obstacles.disc_xy
        hull_r[:nd] = obstacles.disc_r + radius
    # The core: the centre's distance to the nearest edge line, where it lies inside the polygon.
    core_r = hull_r.copy()
    if len(e):
        inward = cross(e, hull_c[nd + obstacles.edge_owner] - obstacles.edge_a) / np.maximum(
            np.linalg.norm(e, axis=1), 1e-300)
        depth = np.full(n - nd, np.inf)
        np.minimum.at(depth, obstacles.edge_owner, inward)
        core_r[nd:] = np.where(depth > 0, depth + radius, -1.0)
    nb_start, nb_ids = _neighbours(obstacles, (2 + NEAR_MARGIN) * radius)
    return dict(centre=centre, rho=rho, cone_a=cone_a, cone_b=cone_b, cone_w=cone_w, owner=owner, nxt=nxt, prv=prv,
                first=first, hull_c=hull_c, hull_r=hull_r, core_r=core_r, nb_start=nb_start, nb_ids=nb_ids)


def _neighbours(obstacles: Obstacles2D, reach: float) -> tuple[np.ndarray, np.ndarray]:
    """CSR (start (N + 1,), ids) of the other obstacles whose boxes lie within ``reach`` of each one's."""
    n = len(obstacles)
    if n < 2:
        return np.zeros(n + 1, dtype=np.int64), np.zeros(0, dtype=np.int64)
    b = obstacles.boxes
    tree = shapely.STRtree(shapely.box(b[:, 0], b[:, 1], b[:, 2], b[:, 3]))
    qi, ti = tree.query(shapely.box(b[:, 0] - reach, b[:, 1] - reach, b[:, 2] + reach, b[:, 3] + reach))
    keep = qi != ti
    qi, ti = qi[keep], ti[keep]
    order = np.lexsort((ti, qi))
    qi, ti = qi[order], ti[order]
    return np.searchsorted(qi, np.arange(n + 1)).astype(np.int64), ti.astype(np.int64)
