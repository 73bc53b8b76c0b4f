"""The grid a route off the static path is sought on (:mod:`worldgen.people.lattice`): its cells and the static
floor, one task at a time.

The floor near a task (the box round its spawn, goal and static path, :data:`BORDER` wider, inside the scene's
bounds) is cut into cells ``h`` apart through the spawn, ``h`` what the lattice's witness covers diagonally in a
step of :data:`DT` at :data:`PACE` of the top speed (a floor of more than :data:`MAX_CELLS` cells takes longer
steps and larger cells). A cell is free of the static world when its centre is ``robot.inflation`` from every
footprint below the robot's top (doors at their open limit, as the static planner has them), plus the most a
straight move to a neighbour can dip toward a convex footprint.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Optional

import numpy as np

__all__ = ["DT", "MAX_CELLS", "BORDER", "PACE", "GOAL_SHARE", "Floor", "floor_of"]

#: s between two steps of the lattice, at most.
DT = 0.1
#: Most cells a grid holds: a larger floor takes longer steps (and larger cells) instead, which bounds the
#: sweep's time (8 states a cell, every step) at some 10 ms a step.
MAX_CELLS = 60_000
#: m the grid reaches beyond the box round spawn, goal and static path.
BORDER = 2.0
#: Share of the top speed a diagonal move makes (the axes sqrt 2 slower): room for the exact sweep's speeding up.
PACE = 0.9
#: Share of the goal tolerance within which a cell counts as the goal's (the route then ends at the goal itself).
GOAL_SHARE = 0.25
#: m added to every growth of a footprint: more than shapely's chords lose on a rounded corner.
_ROUNDING = 1e-3


@dataclass(frozen=True, eq=False)
class Floor:
    """The grid of one task: ``xs`` (nx,) and ``ys`` (ny,) its coordinates (m), ``static`` (ny, nx) the cells free
    of the static world, ``at_goal`` the goal's cells, ``spawn`` the spawn's (row, column), ``ends`` the spawn's
    and the goal's (x, y), ``dt`` its step (s)."""

    xs: np.ndarray
    ys: np.ndarray
    static: np.ndarray
    at_goal: np.ndarray
    spawn: tuple[int, int]
    ends: tuple[tuple[float, float], tuple[float, float]]
    dt: float


def floor_of(footprints, bounds, spawn, goal, tolerance: float, waypoints, inflation: float,
             limits) -> Optional[Floor]:
    """The :class:`Floor` of a task from ``spawn`` to ``goal`` (x, y) whose static path is ``waypoints`` (k, 2),
    among ``footprints`` (the robot's, doors open) inside ``bounds``; None where no cell is the goal's."""
    dt = DT
    h = PACE * limits.max_speed * dt / math.sqrt(2.0)
    xs, ys = _axes(bounds, spawn, goal, waypoints, h)
    if len(xs) * len(ys) > MAX_CELLS:
        dt *= math.sqrt(len(xs) * len(ys) / MAX_CELLS)
        h = PACE * limits.max_speed * dt / math.sqrt(2.0)
        xs, ys = _axes(bounds, spawn, goal, waypoints, h)
    si, sj = int(np.argmin(np.abs(ys - spawn[1]))), int(np.argmin(np.abs(xs - spawn[0])))
    # Between neighbouring centres (a move of L <= h sqrt 2) the distance to a convex footprint dips below the
    # ends' by at most L^2 / (8 inflation): centres that much farther out keep the whole move off it.
    static = _clear_of(footprints, bounds, xs, ys, inflation + h * h / (4.0 * inflation) + _ROUNDING)
    static[si, sj] = True  # the spawn is the world's, proven clear
    gx, gy = np.meshgrid(xs, ys)
    at_goal = (np.hypot(gx - goal[0], gy - goal[1]) <= tolerance * GOAL_SHARE) & static
    if not at_goal.any():
        return None
    return Floor(xs, ys, static, at_goal, (si, sj), ((float(spawn[0]), float(spawn[1])), (float(goal[0]), float(goal[1]))),
                 dt)


def _axes(bounds, spawn, goal, waypoints, h: float) -> tuple[np.ndarray, np.ndarray]:
    """The grid's x and y coordinates: through the spawn, ``h`` apart, over the box round the task."""
    pts = np.vstack([np.asarray(waypoints, dtype=float).reshape(-1, 2), np.asarray(spawn[:2], float),
                     np.asarray(goal[:2], float)])
    (bx0, by0), (bx1, by1) = bounds
    x0, y0 = max(pts[:, 0].min() - BORDER, bx0), max(pts[:, 1].min() - BORDER, by0)
    x1, y1 = min(pts[:, 0].max() + BORDER, bx1), min(pts[:, 1].max() + BORDER, by1)
    sx, sy = float(spawn[0]), float(spawn[1])
    xs = sx + h * np.arange(math.ceil((x0 - sx) / h), math.floor((x1 - sx) / h) + 1)
    ys = sy + h * np.arange(math.ceil((y0 - sy) / h), math.floor((y1 - sy) / h) + 1)
    return xs, ys


def _clear_of(footprints, bounds, xs: np.ndarray, ys: np.ndarray, least: float) -> np.ndarray:
    """(ny, nx) bool: grid points at least ``least`` from every footprint (a polygon or a disc) and from the
    bounds. Each footprint is grown by ``least`` + :data:`_ROUNDING` (shapely's rounded corners are chords)."""
    import shapely

    gx, gy = np.meshgrid(xs, ys)
    (bx0, by0), (bx1, by1) = bounds
    inside = (gx - bx0 >= least) & (bx1 - gx >= least) & (gy - by0 >= least) & (by1 - gy >= least)
    if not footprints:
        return inside
    shapes = [f.polygon if not f.is_disc else shapely.Point(f.centre).buffer(f.radius, quad_segs=16)
              for f in footprints]
    grown = shapely.union_all([shape.buffer(least + _ROUNDING, quad_segs=16) for shape in shapes])
    shapely.prepare(grown)
    return inside & ~shapely.contains_xy(grown, gx, gy)
