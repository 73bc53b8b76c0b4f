"""Graph search on the clearance field, then string-pulling: a safe, nearly taut path.

The grid search only has to find *which way round* the obstacles the shortest
path goes; :mod:`worldgen.feasibility.taut` then makes it exact. Moves are
16-connected (the 8 neighbours plus the knight moves), so the grid path's
length is within about 2.7 % of the straight line in any direction, and an edge
is allowed only when the field proves the whole move free:

    distance is 1-Lipschitz, so along a move of length L between centres with
    clearances da and db, the clearance never drops below (da + db - L) / 2.

String-pulling keeps the path provably free the same way: a shortcut is taken
only where samples along it, each bounded from its cell's exact value, stay
above the inflation radius.

That proof needs about two cells to spare, so gaps between obstacles that are
only a little wider than the disc would be invisible to the search; the
portals of :mod:`worldgen.feasibility.portals` (checked with exact distances)
are added to the graph as extra nodes so that the search can use them.
"""

from __future__ import annotations

import math
from typing import Optional, Sequence

import numpy as np
from scipy.sparse import csr_matrix
from scipy.sparse.csgraph import dijkstra

from worldgen.feasibility.field import DistanceField, Grid
from worldgen.feasibility.geometry import Obstacles2D
from worldgen.feasibility.portals import LINK_CELLS, Portal, exact_links

__all__ = ["MOVES", "grid_path", "field_clear", "string_pull"]

#: The 16 moves (di, dj) of the search, both directions of each.
MOVES = np.array(
    [(1, 0), (0, 1), (1, 1), (1, -1), (2, 1), (1, 2), (2, -1), (1, -2)]
    + [(-1, 0), (0, -1), (-1, -1), (-1, 1), (-2, -1), (-1, -2), (-2, 1), (-1, 2)],
    dtype=np.int64,
)



def field_clear(field: DistanceField, a: np.ndarray, b: np.ndarray, radius: float) -> np.ndarray:
    """(m,) bool: True where the field proves segment ``a[k]b[k]`` keeps more than ``radius``.

    Samples at spacing <= one cell; each sample's clearance is bounded below by
    its cell's exact value minus the distance to that cell's centre, and between
    samples by half the spacing.
    """
    g = field.grid
    a = np.asarray(a, dtype=float).reshape(-1, 2)
    b = np.asarray(b, dtype=float).reshape(-1, 2)
    length = np.hypot(*(b - a).T)
    step = min(g.hx, g.hy)
    n = np.maximum(np.ceil(length / step).astype(np.int64), 1)
    seg = np.repeat(np.arange(len(a)), n + 1)
    t = (np.arange(len(seg)) - np.repeat(np.cumsum(n + 1) - (n + 1), n + 1)) / np.repeat(n, n + 1)
    pts = a[seg] + t[:, None] * (b - a)[seg]
    i, j = g.cell_of(pts)
    rel = pts - g.centre_of(i, j)
    off = np.sqrt(rel[:, 0] ** 2 + rel[:, 1] ** 2)
    bound = field.values[i, j] - off - (length / n / 2)[seg]
    ok = np.ones(len(a), dtype=bool)
    np.logical_and.at(ok, seg, bound > radius)
    return ok


#: Bounds on the grid path's length, as multiples of the straight spawn-goal
#: distance, tried (each on a smaller grid) before searching the whole grid.
ELLIPSE_FACTORS = (1.25, 1.8)


def grid_path(field: DistanceField, start: np.ndarray, goal: np.ndarray, radius: float,
              obstacles: Obstacles2D, bounds, portals: Sequence[Portal] = ()) -> Optional[np.ndarray]:
    """(k, 2) points: start, cell centres (and portal ends), goal; a proven path; None if none.

    Moves between cells are proven by the field; the links of the start, the
    goal and the portal ends into the grid, and the portals themselves, by
    exact distances (see :mod:`worldgen.feasibility.portals`).

    Every path of length <= L lies in the ellipse |p - start| + |p - goal| <= L,
    so the search first runs on the cells of such an ellipse (a fraction of the
    floor) and keeps the answer when it is no longer than L: it is then the
    shortest on the whole grid. Otherwise L grows, and finally the whole grid is
    searched. In cluttered rooms the first ellipse almost always suffices.
    """
    straight = float(np.hypot(*(goal - start)))
    slack = 2 * (LINK_CELLS + 1) * math.hypot(field.grid.hx, field.grid.hy)
    for factor in ELLIPSE_FACTORS:
        limit = factor * straight + slack
        sub = _ellipse_field(field, start, goal, limit)
        if sub is None:
            break  # the ellipse covers the whole grid anyway
        found = _grid_path(sub, start, goal, radius, obstacles, bounds, portals)
        if found is not None and found[1] <= limit:
            return found[0]
    found = _grid_path(field, start, goal, radius, obstacles, bounds, portals)
    return None if found is None else found[0]


def _ellipse_field(field: DistanceField, start: np.ndarray, goal: np.ndarray, limit: float) -> Optional[DistanceField]:
    """The field cropped to the box around the ellipse of foci start, goal and major axis ``limit``,
    with cells outside the ellipse blocked; None when the crop would be most of the grid."""
    g = field.grid
    centre = (start + goal) / 2
    a = limit / 2
    c = float(np.hypot(*(goal - start))) / 2
    b = math.sqrt(max(a * a - c * c, 0.0))
    cos, sin = ((goal - start) / (2 * c)) if c > 0 else (1.0, 0.0)
    ex = math.sqrt((a * cos) ** 2 + (b * sin) ** 2)
    ey = math.sqrt((a * sin) ** 2 + (b * cos) ** 2)
    (i0,), (j0,) = g.cell_of(centre - [ex, ey])
    (i1,), (j1,) = g.cell_of(centre + [ex, ey])
    i1, j1 = i1 + 1, j1 + 1
    if (i1 - i0) * (j1 - j0) > 0.6 * g.nx * g.ny:
        return None
    sub = Grid((g.origin[0] + i0 * g.hx, g.origin[1] + j0 * g.hy), g.hx, g.hy, int(i1 - i0), int(j1 - j0))
    xs, ys = sub.centres()
    dx_s, dy_s = xs[:, None] - start[0], ys[None, :] - start[1]
    dx_g, dy_g = xs[:, None] - goal[0], ys[None, :] - goal[1]
    inside = np.sqrt(dx_s * dx_s + dy_s * dy_s) + np.sqrt(dx_g * dx_g + dy_g * dy_g) <= limit
    values = np.where(inside, field.values[i0:i1, j0:j1], -np.inf)
    return DistanceField(sub, values, field.cap)


def _grid_path(field: DistanceField, start: np.ndarray, goal: np.ndarray, radius: float,
               obstacles: Obstacles2D, bounds, portals: Sequence[Portal]):
    """(points, length) of the shortest proven path through the grid and the portals, or None.

    Nodes: the cells (0 .. n-1), the start (n), the goal (n+1), then both ends
    of every portal.
    """
    g = field.grid
    n = g.nx * g.ny
    if np.hypot(*(goal - start)) <= 1e-12:
        return np.array([start, goal]), 0.0
    ends = np.array([e for p in portals for e in p.ends], dtype=float).reshape(-1, 2)
    special = np.vstack([start, goal, ends])  # node n + k for special point k
    rows, cols, data = [], [], []
    # The proof of a move is symmetric in its two cells, so the first half of
    # MOVES (one direction of each) makes an undirected graph. Per move, on
    # shifted views of the field (no gathers): which cells may take it?
    half = MOVES[: len(MOVES) // 2]
    steps = np.hypot(half[:, 0] * g.hx, half[:, 1] * g.hy)
    pad = np.full((g.nx + 4, g.ny + 4), -np.inf)
    pad[2:-2, 2:-2] = field.values
    for k, (di, dj) in enumerate(half):
        cells = np.flatnonzero(field.values + pad[2 + di:2 + di + g.nx, 2 + dj:2 + dj + g.ny] > 2 * radius + steps[k])
        rows.append(cells)
        cols.append(cells + (di * g.ny + dj))  # the padding kept every allowed move on the grid
        data.append(np.full(len(cells), steps[k]))
    which, cell, length = exact_links(field, obstacles, bounds, special, radius)
    rows.append(n + which)
    cols.append(cell)
    data.append(length)
    # Special points to each other: the portals themselves, and any short clear hop.
    a, b = np.triu_indices(len(special), k=1)
    span = np.hypot(*(special[b] - special[a]).T)
    hop = span <= 2 * (LINK_CELLS + 1) * max(g.hx, g.hy)
    hop |= (a >= 2) & (b == a + 1) & (a % 2 == 0)  # a portal's two ends
    a, b, span = a[hop], b[hop], span[hop]
    clear = obstacles.segments_distance(special[a], special[b], radius)[0] > radius
    rows.append(n + a[clear])
    cols.append(n + b[clear])
    data.append(span[clear])
    graph = csr_matrix((np.concatenate(data), (np.concatenate(rows), np.concatenate(cols))),
                       shape=(n + len(special), n + len(special)))
    dist, pred = dijkstra(graph, directed=False, indices=n, return_predecessors=True)
    total = float(dist[n + 1])
    if not np.isfinite(total):
        return None
    chain = [n + 1]
    while pred[chain[-1]] != n:
        chain.append(int(pred[chain[-1]]))
    chain.append(n)
    idx = np.array(chain[::-1])
    pts = np.empty((len(idx), 2))
    is_cell = idx < n
    pts[is_cell] = g.centre_of(idx[is_cell] // g.ny, idx[is_cell] % g.ny)
    pts[~is_cell] = special[idx[~is_cell] - n]
    return pts, total


def string_pull(field: DistanceField, path: np.ndarray, radius: float, window: int = 64) -> np.ndarray:
    """Drop every waypoint that a field-proven straight shortcut makes unnecessary.

    From each kept point, the farthest later point within ``window`` steps
    reachable in one proven-free segment becomes the next one.
    """
    out = [0]
    i, n = 0, len(path) - 1
    while i < n:
        js = np.arange(i + 1, min(n, i + window) + 1)
        clear = field_clear(field, np.broadcast_to(path[i], (len(js), 2)), path[js], radius)
        # The next grid point is always reachable: the search only used proven moves.
        visible = js[clear]
        i = int(visible[-1]) if len(visible) else i + 1
        out.append(i)
    return path[out]
