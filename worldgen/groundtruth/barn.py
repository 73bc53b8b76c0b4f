"""BARN's five difficulty metrics, computed exactly as BARN's own code computes them.

BARN (Perille et al., "Benchmarking Metric Ground Navigation", SSRR 2020) ranks
worlds by five numbers that its generator's ``difficulty_quant.py``
(dperille/jackal-map-creation, commit 947fe6f, its last change) computes on a
C-space occupancy grid at the cells of a path. :func:`barn_metrics` is written
here from that algorithm, vectorised with numpy (BARN's pure-Python loops take
seconds on a 600 x 600 grid; this takes milliseconds), and returns the same
floats: ``tests/groundtruth/test_barn.py`` holds numbers obtained by running
BARN's unmodified code and requires agreement to 1e-9.

What BARN computes, per path cell (row, col), row 0 at the top; a cell is a
wall when its value is 1 (``== 1``: any other value is free):

- ``closest_wall``: the Euclidean distance (cells) to the nearest wall cell of
  the grid (the map's edge is not a wall); 0 on a wall cell. A grid without any
  wall gives ``(rows - 1) / 2`` in Python 2's integer division, as BARN's code
  (which imports ``Queue``: Python 2) does.
- ``average_visibility``: the mean over the 8 grid directions of the free run
  from the cell itself, each free cell counting the step's length (1 or sqrt 2),
  up to a wall or the map's edge (a ray leaving the map counts up to the edge);
  0 on a wall cell.
- ``dispersion``: along 16 step directions, the 8 grid ones and the 8 knight
  moves between them, whether a wall lies within ``disp_radius`` "steps", then
  the number of wall / no-wall changes around the circle; -1 on a wall cell.
  **BARN's quirk, kept on purpose**: it means a knight move to count two steps,
  but tests ``move[0] == 2 or move[1] == 2``, so only the four knight moves with
  a +2 component, (1, 2), (2, 1), (2, -1), (-1, 2), count two; the four with a
  -2 component, (1, -2), (-2, -1), (-1, -2), (-2, 1), count one and so look
  twice as far (radius 20: 20 knight moves, 2.24 m at 0.05 m, against 10).
- ``characteristic_dimension``: the shortest, over 4 axes (the 2 grid axes and
  2 diagonals), of the free run on both sides of the cell, the cell itself not
  counted, each cell weighing its step's length; -1 on a wall cell.
- ``tortuosity``: the sum of the Euclidean lengths between consecutive path
  cells over the distance between the first and the last cell.

Each of the first four is averaged over the path's cells in order. Sums are
formed in BARN's order (one step length added at a time, directions in BARN's
order, cells in path order), so the results are the same floats, not merely
close. :func:`cspace` is BARN's C-space (``gen_world_ca.JackalMap``: a cell is a
wall when the robot's square window, anchored at its top-left, meets a wall)
and :func:`chain` turns a polyline into an 8-connected chain of cells, the kind
of path BARN's A* returns.
"""

from __future__ import annotations

import math
from typing import Literal, Optional

import numpy as np

from worldgen.errors import ParameterError

__all__ = ["barn_metrics", "cspace", "chain", "kernel_cells", "world_inputs", "world_metrics", "NAMES",
           "DISPERSION_MOVES", "DISP_RADIUS", "BARN_COMMIT"]

#: The commit of dperille/jackal-map-creation whose ``difficulty_quant.py`` this follows.
BARN_COMMIT = "947fe6f497b12fe47c11dc43d8192ef99c050d7c"
#: BARN's names, in the order of ``avg_all_metrics``.
NAMES = ("closest_wall", "average_visibility", "dispersion", "characteristic_dimension", "tortuosity")
#: BARN's 16 dispersion directions (row, col), in its order around the circle.
DISPERSION_MOVES = ((0, 1), (1, 2), (1, 1), (2, 1), (1, 0), (2, -1), (1, -1), (1, -2),
                    (0, -1), (-2, -1), (-1, -1), (-1, -2), (-1, 0), (-2, 1), (-1, 1), (-1, 2))
#: BARN's dispersion radius, in cells (``difficulty_quant.main``'s ``disp_radius``).
DISP_RADIUS = 3
#: BARN's visibility directions in its loop order (row step outer, column step inner).
_VIS_MOVES = tuple((dr, dc) for dr in (-1, 0, 1) for dc in (-1, 0, 1) if (dr, dc) != (0, 0))
#: BARN's characteristic-dimension axes, in its order.
_AXES = ((0, 1), (1, 1), (1, 0), (1, -1))


def barn_metrics(grid, path_cells, disp_radius) -> dict[str, Optional[float]]:
    """BARN's five metrics of ``path_cells`` on ``grid``, in cells, as BARN's code returns them.

    ``grid``: rows of 0/1 (1 = wall), row 0 at the top. ``path_cells``: (row, col)
    integer cells inside the grid, in path order. ``disp_radius``: the dispersion
    radius in BARN's steps. ``tortuosity`` is None when the path starts and ends
    in the same cell (BARN's code divides by zero there).
    """
    try:
        occ = np.asarray(grid) == 1
    except ValueError:  # ragged rows
        occ = np.zeros(0, dtype=bool)
    if occ.ndim != 2 or occ.size == 0:
        raise ParameterError(f"grid must be a non-empty 2-D array of rows of 0/1 of one length, got {occ.ndim} "
                             f"dimension(s) and {occ.size} cells")
    cells = np.asarray(path_cells)
    if cells.ndim != 2 or cells.shape[1:] != (2,) or len(cells) == 0 or not np.issubdtype(cells.dtype, np.integer):
        raise ParameterError(f"path_cells must be a non-empty list of integer (row, col) pairs, got shape {cells.shape}")
    rows, cols = occ.shape
    r, c = cells[:, 0].astype(np.int64), cells[:, 1].astype(np.int64)
    if r.min() < 0 or c.min() < 0 or r.max() >= rows or c.max() >= cols:
        raise ParameterError(f"path_cells must lie inside the {rows} x {cols} grid, got rows {r.min()}..{r.max()}, "
                             f"cols {c.min()}..{c.max()}")
    if not isinstance(disp_radius, (int, float, np.integer, np.floating)) or not math.isfinite(disp_radius):
        raise ParameterError(f"disp_radius must be a finite number of steps, got {disp_radius!r}")
    wall = occ[r, c]
    runs = _free_runs(occ, r, c)  # {(dr, dc): free cells after the path cell along (dr, dc)}
    longest = max(rows, cols) + 1
    table = {1: np.arange(longest + 1, dtype=float), 2: _steps(math.sqrt(2), longest)}
    return {
        "closest_wall": _mean(_closest_wall(occ, r, c, wall, runs)),
        "average_visibility": _mean(_visibility(runs, wall, table)),
        "dispersion": _mean(_dispersion(occ, r, c, wall, disp_radius)),
        "characteristic_dimension": _mean(_char_dim(runs, wall, table, rows + cols)),
        "tortuosity": _tortuosity(r, c),
    }


def cspace(occupied, kernel: int) -> np.ndarray:
    """BARN's C-space of an obstacle grid: (rows - k + 1, cols - k + 1) of 0/1, a cell 1 when the
    k x k window whose top-left corner it is meets an occupied cell (``JackalMap``'s construction)."""
    occ = np.asarray(occupied, dtype=bool)
    if occ.ndim != 2 or not 1 <= kernel <= min(occ.shape):
        raise ParameterError(f"kernel must be in [1, {min(occ.shape)}] cells for a {occ.shape} grid, got {kernel!r}")
    # Rows then columns, each "any of k consecutive cells" as the OR of two overlapping windows of the
    # largest power of two p <= k, themselves made by doubling: log2(k) passes over booleans (a tenth
    # of the running sums' time on a 400 x 400 map).
    return _window_any(_window_any(occ, kernel, 0), kernel, 1).astype(np.uint8)


def _window_any(a: np.ndarray, k: int, axis: int) -> np.ndarray:
    """Along ``axis``, whether any of the ``k`` cells from each position on is set (length n - k + 1)."""
    a = np.moveaxis(a, axis, 0)
    p = 1
    while 2 * p <= k:
        a = a[:-p] | a[p:]  # now: any of the 2p cells from each position
        p *= 2
    n = a.shape[0] - (k - p)
    return np.moveaxis(a[:n] | a[k - p:k - p + n], 0, axis)


def kernel_cells(robot_radius: float, resolution: float) -> int:
    """BARN's robot kernel for a disc robot: the odd square of cells that holds the disc, 2h + 1
    with h = ceil(radius / resolution) (BARN's generator defaults to 3 cells, ``def_kernel_size``)."""
    return 2 * max(0, math.ceil(robot_radius / resolution - 1e-9)) + 1


def world_inputs(occupied, origin, resolution: float, robot_radius: float, waypoints,
                 kernel: Optional[int] = None) -> tuple[np.ndarray, np.ndarray]:
    """BARN's inputs for one path of a world: (C-space grid, 8-connected chain of its cells).

    ``occupied``: the map (rows, cols) with row 0 at the bottom, as :class:`OccupancyMap`;
    ``origin``: its lower-left corner (m); ``waypoints``: the path's polyline (k, 2) in metres.
    The grid is :func:`cspace` of the map flipped to BARN's orientation (row 0 at the top)
    with :func:`kernel_cells`; the path is the chain through the waypoints' map cells, each
    moved by the kernel's half-width to the C-space cell whose window is centred on it and
    kept inside the C-space (a cell nearer the map's edge than the half-width has no C-space
    cell of its own: BARN's C-space is smaller than its map by the kernel). ``kernel`` replaces
    :func:`kernel_cells`; 1 gives the uninflated map and the chain in map cells.
    """
    grid, half = _grid(occupied, resolution, robot_radius, kernel)
    return grid, _cells(grid, half, len(occupied), origin, resolution, waypoints)


def _grid(occupied, resolution: float, robot_radius: float, kernel: Optional[int]) -> tuple[np.ndarray, int]:
    """(BARN's C-space of the map, the kernel's half-width): the part of :func:`world_inputs` every path shares."""
    occ = np.asarray(occupied, dtype=bool)[::-1]
    rows, cols = occ.shape
    k = min(kernel_cells(robot_radius, resolution) if kernel is None else kernel, rows, cols)
    return cspace(occ, k), k // 2


def _cells(grid: np.ndarray, half: int, rows: int, origin, resolution: float, waypoints) -> np.ndarray:
    """The chain of C-space cells of one path's waypoints (see :func:`world_inputs`)."""
    w = np.asarray(waypoints, dtype=float).reshape(-1, 2)
    col = np.floor((w[:, 0] - origin[0]) / resolution).astype(np.int64)
    row = rows - 1 - np.floor((w[:, 1] - origin[1]) / resolution).astype(np.int64)
    cells = chain(np.c_[row, col]) - half
    cells = np.c_[np.clip(cells[:, 0], 0, grid.shape[0] - 1), np.clip(cells[:, 1], 0, grid.shape[1] - 1)]
    keep = np.r_[True, (cells[1:] != cells[:-1]).any(axis=1)]
    return cells[keep]


def world_metrics(occupied, origin, resolution: float, robot_radius: float, paths,
                  disp_radius=DISP_RADIUS) -> dict[str, Optional[float]]:
    """BARN's five metrics of a world: :func:`barn_metrics` on :func:`world_inputs` of each path
    (polylines; None for a task without one), averaged over the paths; each None without a path
    (tortuosity also where every path starts and ends in one cell)."""
    found = [p for p in paths if p is not None]
    per = []
    if found:
        grid, half = _grid(occupied, resolution, robot_radius, None)  # one C-space for all
        per = [barn_metrics(grid, _cells(grid, half, len(occupied), origin, resolution, p), disp_radius) for p in found]
    out: dict[str, Optional[float]] = {}
    for name in NAMES:
        values = [v for m in per if (v := m[name]) is not None]
        out[name] = float(np.mean(values)) if values else None
    return out


def chain(cells) -> np.ndarray:
    """(m, 2) 8-connected chain through the given (row, col) cells in order: between two
    consecutive cells, the cells of the digital straight line joining them (each step one
    of the 8 grid moves, diagonal where the line is), without repeats."""
    pts = np.asarray(cells, dtype=np.int64).reshape(-1, 2)
    out = [pts[:1]]
    for a, b in zip(pts[:-1], pts[1:]):
        n = int(np.abs(b - a).max())
        if n == 0:
            continue
        t = np.arange(1, n + 1)
        # The point a + (b - a) t / n, rounded half up in absolute coordinates (exact integers):
        # the same segment gives the same cells whichever way it is read.
        num = a[None, :] * n + (b - a)[None, :] * t[:, None]
        line = (2 * num + n) // (2 * n)
        out.append(line)
    return np.vstack(out)


# -- the metrics ------------------------------------------------------------------------------

def _mean(values: np.ndarray) -> float:
    """BARN's ``total = 0.0; total += v`` over the path, then ``total / len(path)``."""
    return float(np.add.accumulate(np.asarray(values, dtype=float))[-1]) / len(values)


def _steps(step: float, n: int) -> np.ndarray:
    """[0, step, step + step, ...]: k steps added one at a time (BARN's loop), for k = 0..n."""
    return np.r_[0.0, np.add.accumulate(np.full(n, step))]


def _closest_wall(occ, r, c, wall, runs) -> np.ndarray:
    rows, cols = occ.shape
    if not occ.any():
        return np.full(len(r), float((rows - 1) // 2))  # BARN's fallback, Python 2's division
    # BARN's best-first search pops cells by Euclidean distance from the start and stops at the
    # first wall: the nearest wall cell of the grid. Exactly: the wall a free run along one of the 8
    # moves stops at (when it stops inside the grid) bounds that distance, so only the columns within
    # the bound can hold the nearest wall; in each, the nearest wall above and below the cell is found by
    # binary search, and the least dx^2 + dy^2 taken (integers throughout, so the square root is BARN's
    # math.sqrt of the same integer). A cell with no such run looks at every column.
    bound = np.full(len(r), cols, dtype=np.int64)  # columns either side to look at
    for (dr, dc), run in runs.items():
        k = run.astype(np.int64) + 1
        stop_r, stop_c = r + k * dr, c + k * dc
        inside = (stop_r >= 0) & (stop_r < rows) & (stop_c >= 0) & (stop_c < cols)
        # The wall at k steps is k (or k sqrt(2) on a diagonal) away: columns beyond that cannot be nearer.
        reach = k if dr == 0 or dc == 0 else np.ceil(k * math.sqrt(2)).astype(np.int64)
        bound = np.where(inside, np.minimum(bound, reach), bound)
    bound = np.where(wall, 0, bound)
    lo, hi = np.maximum(c - bound, 0), np.minimum(c + bound, cols - 1)
    counts = hi - lo + 1
    cell = np.repeat(np.arange(len(r)), counts)
    col = np.repeat(lo, counts) + (np.arange(counts.sum()) - np.repeat(np.cumsum(counts) - counts, counts))
    row = r[cell]
    keys = np.flatnonzero(occ.T)  # column-major: sorted by column, then row
    here = col * rows + row
    far = rows + cols  # farther than any wall of the grid
    below = _to_wall(keys, here, rows - row, side="left")  # the wall at or below (row + k) the cell
    above = _to_wall(keys, here, row + 1, side="right")
    below = np.where(below < rows - row, below, far)
    above = np.where(above < row + 1, above, far)
    dy = np.minimum(below, above)
    dx = col - c[cell]
    d2 = np.full(len(r), np.iinfo(np.int64).max)
    np.minimum.at(d2, cell, dx * dx + dy * dy)
    return np.where(wall, 0.0, np.sqrt(d2.astype(float)))


def _free_runs(occ, r, c) -> dict[tuple[int, int], np.ndarray]:
    """For each of the 8 grid moves, the free cells after each path cell before a wall or the edge.

    The walls of each family of lines (rows, columns, both diagonals) as one sorted array of keys
    (line id, position along the line); each path cell's next and previous wall on its line by binary
    search, the edge of the grid counting as a wall (a run stops there as at a wall). A wall cell's
    runs are -1 (its own cell stops them)."""
    rows, cols = occ.shape
    flat = np.flatnonzero(occ)  # row-major: sorted by row, then column
    wr, wc = flat // cols, flat % cols
    out = {}
    # (move, line id and position of the walls, of the path cells; cells to the edge forwards, backwards)
    families = (
        ((0, 1), wr, wc, r, c, cols - c, c + 1),
        ((1, 0), wc, wr, c, r, rows - r, r + 1),
        ((1, 1), wc - wr + rows, wr, c - r + rows, r, np.minimum(rows - r, cols - c), np.minimum(r + 1, c + 1)),
        ((1, -1), wc + wr, wr, c + r, r, np.minimum(rows - r, c + 1), np.minimum(r + 1, cols - c)),
    )
    span = rows + cols + 1  # more than any line id or position
    for move, wall_line, wall_pos, line, pos, to_edge, back_edge in families:
        on = np.zeros(span, dtype=bool)
        on[line] = True
        keep = on[wall_line]  # only the lines through path cells
        keys = wall_line[keep].astype(np.int64) * span + wall_pos[keep]
        if move != (0, 1):  # the rows' keys come sorted
            keys.sort()
        here = line.astype(np.int64) * span + pos
        out[move] = np.minimum(_to_wall(keys, here, span - pos, side="left"), to_edge) - 1
        out[(-move[0], -move[1])] = np.minimum(_to_wall(keys, here, pos + 1, side="right"), back_edge) - 1
    return out


def _to_wall(keys: np.ndarray, here: np.ndarray, limit: np.ndarray, side: Literal["left", "right"]) -> np.ndarray:
    """Steps from each key ``here`` to the nearest of the sorted ``keys`` ahead (``side="left"``: at or
    after it) or behind (``"right"``: at or before it); ``limit`` (or more) where that is on another line."""
    if len(keys) == 0:
        return limit
    i = np.searchsorted(keys, here, side=side)
    if side == "left":
        steps = keys[np.minimum(i, len(keys) - 1)] - here
        return np.where((i < len(keys)) & (steps < limit), steps, limit)
    steps = here - keys[np.maximum(i - 1, 0)]
    return np.where((i > 0) & (steps < limit), steps, limit)


def _visibility(runs, wall, table) -> np.ndarray:
    total = np.zeros(len(wall))
    for dr, dc in _VIS_MOVES:  # BARN's order, one direction's run added at a time
        total = total + table[abs(dr) + abs(dc)][runs[(dr, dc)] + 1]  # the cell itself counts
    return np.where(wall, 0.0, total / 8)


def _char_dim(runs, wall, table, limit: int) -> np.ndarray:
    best = np.full(len(wall), float(limit))
    for dr, dc in _AXES:
        best = np.minimum(best, table[abs(dr) + abs(dc)][runs[(dr, dc)] + runs[(-dr, -dc)]])
    return np.where(wall, -1.0, best)


def _dispersion(occ, r, c, wall, radius) -> np.ndarray:
    rows, cols = occ.shape
    blocked = np.zeros((len(r), len(DISPERSION_MOVES)), dtype=bool)
    # The loop takes steps while count < radius: ceil(radius / inc) of them; past the map's edge a
    # straight walk never comes back, so no more than the map's size matter.
    most = min(max(math.ceil(radius), 0), max(rows, cols)) if radius > 0 else 0
    if most == 0:
        return np.where(wall, -1, 0)
    pad = 2 * most  # off-grid cells, free, as far as any walk reaches (BARN stops there: no wall)
    grid = np.pad(occ, pad).ravel()
    width = cols + 2 * pad
    at = (r + pad) * width + c + pad
    for k, (dr, dc) in enumerate(DISPERSION_MOVES):
        inc = 2 if dr == 2 or dc == 2 else 1  # BARN's test, quirk included (see the module docs)
        steps = min(math.ceil(radius / inc), most)
        i = np.arange(1, steps + 1)
        blocked[:, k] = grid[at[:, None] + (dr * width + dc) * i[None, :]].any(axis=1)
    changes = (blocked != np.roll(blocked, -1, axis=1)).sum(axis=1)
    return np.where(wall, -1, changes)


def _tortuosity(r, c) -> Optional[float]:
    dr, dc = np.diff(r), np.diff(c)
    arc = float(np.add.accumulate(np.r_[0.0, np.sqrt((dr * dr + dc * dc).astype(float))])[-1])
    chord = math.sqrt(float((r[-1] - r[0]) ** 2 + (c[-1] - c[0]) ** 2))
    return arc / chord if chord > 0 else None
