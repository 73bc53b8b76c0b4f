"""A schedule off the static path: the earliest way through space and time round agents on known schedules.

Scripted movers ignore the robot and may sweep along the task's static path, or cross its spawn or its goal;
a robot that keeps to the path (:func:`worldgen.people.timed.timed_path`) then has no way through, while a
robot that steps aside has. This is the certificate's sweep in the plane: the floor near the task (the
box round spawn, goal and static path, :data:`BORDER` wider) is a grid of cells ``h = speed x DT / sqrt 2``
apart, time is steps of :data:`DT`; in a step the robot waits or moves to one of its 8 neighbouring cells (at
most ``speed``). A cell is free of the static world when its centre is ``robot.inflation`` from every
footprint below the robot's top (doors at their open limit, as the static planner has them), plus the most
a straight move to a neighbour can dip towards a convex footprint; it is free of an agent at a step when its
centre is ``reach`` from every position the agent's tube allows round the step (sampled every half step),
``reach = inflation + the agent's radius + MARGIN + d + speed x DT / 2 + the fastest agent x DT / 4``, as
in worldgen/people/timed.py. A forward sweep keeps the cells
the robot can be in; the first step a goal cell (within a quarter of the goal's tolerance) is reachable is
the arrival; the rows are read back, waiting where the robot can and else keeping its last direction.

Like the certificate, the arrival is an upper bound at this resolution, and the rows a checkable witness.
"""

from __future__ import annotations

import math
from typing import Optional, Sequence

import numpy as np

__all__ = ["DT", "BORDER", "MARGIN", "spacetime_path"]

#: s between two steps of the sweep (and two rows of the schedule).
DT = 0.1
#: m the grid reaches beyond the box round spawn, goal and static path.
BORDER = 2.0
#: m kept beyond contact at every instant, over and above the sampling bound (worldgen.people.timed's).
MARGIN = 0.01
_SPARE = 1e-3
#: m added to every growth of a footprint: more than shapely's chords lose on a rounded corner.
_ROUNDING = 1e-3
_NEIGHBOURS = [(di, dj) for di in (-1, 0, 1) for dj in (-1, 0, 1)]


# long: one sweep, set up (grid, static floor, agents' reach) and read back in one place as timed_path is
def spacetime_path(footprints, bounds, spawn, goal, tolerance: float, waypoints, tracks: Sequence[np.ndarray],
                   radii: Sequence[float], tubes, inflation: float, speed: float, horizon: float,
                   room: float = 0.0) -> Optional[np.ndarray]:
    """(k, 3) ``t, x, y`` rows from ``spawn`` at t = 0 to within ``tolerance / 4`` of ``goal``, clear of
    ``footprints`` (:class:`~worldgen.scene.footprint.Footprint` s, the robot's) and of every
    agent's (``tracks``, (m, 3) rows that do not loop; ``radii``; ``tubes`` with ``d`` and ``tau``) tube, at
    most ``speed``, ``room`` m further from every agent; None when no such rows arrive within ``horizon`` s."""
    h = speed * DT / math.sqrt(2.0) * (1.0 - _SPARE)
    pts = np.vstack([np.asarray(waypoints, dtype=float).reshape(-1, 2), np.asarray(spawn[:2], float), goal[:2]])
    (bx0, by0), (bx1, by1) = bounds
    x0, y0 = max(pts[:, 0].min() - BORDER, bx0), max(pts[:, 1].min() - BORDER, by0)
    x1, y1 = min(pts[:, 0].max() + BORDER, bx1), min(pts[:, 1].max() + BORDER, by1)
    # The grid runs through the spawn: the robot starts on a cell, and its first move is a move like any other.
    sx, sy = float(spawn[0]), float(spawn[1])
    xs = sx + h * np.arange(math.ceil((x0 - sx) / h), math.floor((x1 - sx) / h) + 1)
    ys = sy + h * np.arange(math.ceil((y0 - sy) / h), math.floor((y1 - sy) / h) + 1)
    gx, gy = np.meshgrid(xs, ys)  # (ny, nx)
    grid = np.column_stack([gx.ravel(), gy.ravel()])
    edge = np.minimum.reduce([grid[:, 0] - bx0, bx1 - grid[:, 0], grid[:, 1] - by0, by1 - grid[:, 1]])
    # Between two neighbouring centres (a move of L <= h sqrt 2) the distance to one convex footprint, a
    # convex function along the move, dips below the ends' by at most L^2 / (8 inflation) (the dip past a
    # corner; none along a face): centres that much further out keep the whole move ``inflation`` off.
    least = inflation + 2.0 * h * h / (8.0 * inflation) + _ROUNDING
    static = ((edge >= least) & _clear_of(footprints, xs, ys, least)).reshape(gx.shape)
    near_spawn = np.zeros(gx.shape, dtype=bool)
    near_spawn[int(np.argmin(np.abs(ys - sy))), int(np.argmin(np.abs(xs - sx)))] = True
    # The spawn is the world's, proven clear of the static world; only the margin of a move is not.
    static |= near_spawn
    at_goal = (np.hypot(*(grid - np.asarray(goal[:2], float)).T) <= tolerance / 4).reshape(gx.shape) & static
    if not at_goal.any():
        return None
    fastest = max([_fastest(t) for t in tracks], default=0.0)
    # The robot's cell at a step stands for every instant within DT / 2 of it (it moves at most speed DT / 2
    # meanwhile); each agent is sampled every DT / 2, so every instant is within DT / 4 of a sample of it.
    reach = [inflation + room + float(r) + MARGIN + float(tube.d) + speed * DT / 2 + fastest * DT / 4
             for r, tube in zip(radii, tubes)]
    window = [0 if tube.tau <= 0 else math.ceil(tube.tau / DT + 0.5 - 1e-9) for tube in tubes]
    steps = int(math.ceil(horizon / DT))
    sets = [near_spawn & _free(0, xs, ys, tracks, reach, window)]  # a list: the sweep rarely runs to the horizon
    arrival = None
    for k in range(1, steps + 1):
        if not sets[-1].any():
            return None
        sets.append(_dilate(sets[-1]) & static & _free(k, xs, ys, tracks, reach, window))
        if (sets[k] & at_goal).any():
            arrival = k
            break
    if arrival is None:
        return None
    cells = [tuple(np.argwhere(sets[arrival] & at_goal)[0])]
    heading = (0, 0)
    for k in range(arrival, 0, -1):
        i, j = cells[-1]
        options = [(i - di, j - dj) for di, dj in [(0, 0), heading] + _NEIGHBOURS
                   if 0 <= i - di < gx.shape[0] and 0 <= j - dj < gx.shape[1] and sets[k - 1][i - di, j - dj]]
        nxt = options[0]
        heading = (i - nxt[0], j - nxt[1])
        cells.append(nxt)
    cells.reverse()
    rows = np.array([(k * DT, xs[j], ys[i]) for k, (i, j) in enumerate(cells)])
    return _thinned(rows)


def _clear_of(footprints, xs: np.ndarray, ys: np.ndarray, least: float) -> np.ndarray:
    """(ny * nx,) bool: grid points at least ``least`` from every footprint (a polygon or a disc).

    Each footprint grown by ``least`` + :data:`_ROUNDING` (shapely's rounded corners are chords, inside the
    true arcs by under 0.4 mm at 16 segments a quarter): a point outside the union is far enough."""
    import shapely

    gx, gy = np.meshgrid(xs, ys)
    if not footprints:
        return np.ones(gx.size, dtype=bool)
    shapes = [f.polygon if not f.is_disc else shapely.Point(f.centre).buffer(f.radius, quad_segs=16)
              for f in footprints]
    grown = shapely.union_all([shape.buffer(least + _ROUNDING, quad_segs=16) for shape in shapes])
    shapely.prepare(grown)
    return ~shapely.contains_xy(grown, gx.ravel(), gy.ravel())


def _fastest(track: np.ndarray) -> float:
    d = np.diff(np.asarray(track, dtype=float), axis=0)
    return float(np.max(np.hypot(d[:, 1], d[:, 2]) / np.maximum(d[:, 0], 1e-12))) if len(d) else 0.0


def _position(track: np.ndarray, t: np.ndarray) -> np.ndarray:
    """(len(t), 2) where a (m, 3) track that does not loop is at times ``t`` (standing before and after)."""
    return np.column_stack([np.interp(t, track[:, 0], track[:, 1]), np.interp(t, track[:, 0], track[:, 2])])


def _free(k: int, xs, ys, tracks, reach, window) -> np.ndarray:
    """(ny, nx) bool: no agent's position within its window of steps round step ``k`` within its reach."""
    free = np.ones((len(ys), len(xs)), dtype=bool)
    for track, r, w in zip(tracks, reach, window):
        p = _position(np.asarray(track, dtype=float), DT * np.arange(k - w - 0.5, k + w + 0.75, 0.5))
        lo, hi = p.min(axis=0) - r, p.max(axis=0) + r
        i0, i1 = np.searchsorted(ys, lo[1]), np.searchsorted(ys, hi[1], side="right")
        j0, j1 = np.searchsorted(xs, lo[0]), np.searchsorted(xs, hi[0], side="right")
        if i0 >= i1 or j0 >= j1:
            continue
        sx, sy = np.meshgrid(xs[j0:j1], ys[i0:i1])
        d2 = (sx[..., None] - p[:, 0]) ** 2 + (sy[..., None] - p[:, 1]) ** 2
        free[i0:i1, j0:j1] &= ~(d2.min(axis=-1) < r * r)
    return free


def _dilate(a: np.ndarray) -> np.ndarray:
    """The cells of ``a`` and their 8 neighbours."""
    out = a.copy()
    out[1:] |= a[:-1]
    out[:-1] |= a[1:]
    rows = out.copy()
    out[:, 1:] |= rows[:, :-1]
    out[:, :-1] |= rows[:, 1:]
    return out


def _thinned(rows: np.ndarray) -> np.ndarray:
    """``rows`` less those a straight constant-speed leg between their neighbours already says."""
    vel = np.diff(rows[:, 1:], axis=0) / np.diff(rows[:, 0])[:, None]
    same = np.all(np.abs(vel[1:] - vel[:-1]) < 1e-9, axis=1)
    return rows[np.r_[True, ~same, True]]
