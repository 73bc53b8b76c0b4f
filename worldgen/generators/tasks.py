"""Drawing spawn/goal pairs on free floor, shared by generators.

A candidate is free when the disc of radius ``robot.inflation`` around it stays
inside the bounds and off every footprint. This is the generator's quick
screen; the feasibility layer proves the final choice with FCL.
"""

from __future__ import annotations

import math
from typing import Optional

import numpy as np

from worldgen.floats import round_float
from worldgen.footprint import FootprintIndex
from worldgen.scene import Pose, Robot, Task

__all__ = ["free_points", "sample_tasks"]

_BATCH = 256
_BATCHES = 16
#: Screened points keep this much more than the inflation radius, so that
#: rounding the written coordinates can never tip a free point into contact.
_SLACK = 1e-3


def free_points(rng: np.random.Generator, index: FootprintIndex, bounds, robot: Robot, count: int) -> np.ndarray:
    """(k, 2) points drawn uniformly in the shrunk bounds and screened free; k <= count."""
    (x0, y0), (x1, y1) = bounds
    r = robot.inflation + _SLACK
    if x1 - x0 <= 2 * r or y1 - y0 <= 2 * r:
        return np.zeros((0, 2))
    xy = np.column_stack([rng.uniform(x0 + r, x1 - r, count), rng.uniform(y0 + r, y1 - r, count)])
    xy = np.round(xy, 6)
    return xy[~index.blocked(xy, r)]


def sample_tasks(
    rng: np.random.Generator,
    index: FootprintIndex,
    bounds,
    robot: Robot,
    n_tasks: int,
    min_distance: float,
    goal_tolerance: float,
) -> tuple[list[Task], Optional[str]]:
    """Draw ``n_tasks`` spawn/goal pairs; returns (tasks, None) or ([], reason).

    Goals lie at least ``min_distance`` from their spawn. Spawns (and goals) of
    different tasks are at least two footprint radii plus clearance apart, so
    many robots can start together without overlapping.
    """
    separation = 2 * robot.inflation
    spawns: list[np.ndarray] = []
    goals: list[np.ndarray] = []
    tasks: list[Task] = []
    for _ in range(_BATCHES):
        pts = free_points(rng, index, bounds, robot, _BATCH)
        yaws = rng.uniform(-math.pi, math.pi, len(pts))
        for p, yaw in zip(pts, yaws):
            if len(tasks) == n_tasks:
                break
            if len(spawns) == len(tasks):  # looking for a spawn
                if all(np.hypot(*(p - q)) >= separation for q in spawns):
                    spawns.append(p)
                    spawn_yaw = round_float(yaw)
                continue
            spawn = spawns[-1]
            if np.hypot(*(p - spawn)) < min_distance:
                continue
            if not all(np.hypot(*(p - q)) >= separation for q in goals + spawns[:-1]):
                continue
            goals.append(p)
            tasks.append(
                Task(
                    f"task_{len(tasks)}",
                    Pose(float(spawn[0]), float(spawn[1]), 0.0, 0.0, 0.0, spawn_yaw),
                    Pose(float(p[0]), float(p[1]), 0.0, 0.0, 0.0, round_float(yaw)),
                    goal_tolerance,
                )
            )
        if len(tasks) == n_tasks:
            return tasks, None
    return [], (
        f"found {len(tasks)} of {n_tasks} spawn/goal pairs at least {min_distance:g} m apart on free floor"
    )
