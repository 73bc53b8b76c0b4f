"""Drawing spawn/goal pairs on free floor, shared by generators.

A candidate is free when the disc of radius ``robot.inflation`` around it stays
inside the bounds and off every footprint. This is the generator's quick
screen; the feasibility layer proves the final choice with FCL.
"""

from __future__ import annotations

import math
from typing import Any, Mapping, Optional, Sequence

import numpy as np

from worldgen.errors import ParameterError
from worldgen.floats import round_float
from worldgen.params import Param
from worldgen.scene import Pose, Robot, Task
from worldgen.scene.footprint import FootprintIndex

__all__ = ["free_points", "sample_tasks", "region_bounds", "check_task_params", "TASK_PARAMS"]

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
    spawn: Optional[Sequence[float]] = None,
    goal: Optional[Sequence[float]] = None,
    region: Optional[float] = None,
) -> tuple[list[Task], Optional[str]]:
    """Draw ``n_tasks`` spawn/goal pairs; returns (tasks, None) or ([], reason).

    Goals lie at least ``min_distance`` from their spawn. Spawns (and goals) of
    different tasks are at least two footprint radii plus clearance apart, so
    many robots can start together without overlapping.

    ``spawn`` ([x, y, yaw]) and ``goal`` ([x, y]) fix the first task's ends
    instead of drawing them (a fixed pair skips ``min_distance``: the caller
    chose it); ``region`` h restricts drawn points to [-h, h] x [-h, h].
    """
    for label, fixed in (("spawn", spawn), ("goal", goal)):
        if fixed is not None and not _free(index, bounds, robot, fixed[:2]):
            return [], f"the fixed {label} ({fixed[0]:g}, {fixed[1]:g}) is not free for a {robot.inflation:g} m disc"
    pairs = _Pairs(2 * robot.inflation, min_distance, goal_tolerance, goal)
    if spawn is not None:
        pairs.fix_spawn(np.array(spawn[:2], dtype=float), round_float(spawn[2]))
    draw_bounds = region_bounds(bounds, region, robot)
    for _ in range(_BATCHES):
        if len(pairs.tasks) == n_tasks:
            return pairs.tasks, None
        pts = free_points(rng, index, draw_bounds, robot, _BATCH)
        yaws = rng.uniform(-math.pi, math.pi, len(pts))
        for p, yaw in zip(pts, yaws):
            if len(pairs.tasks) == n_tasks:
                break
            pairs.offer(p, round_float(yaw))
        if len(pairs.tasks) == n_tasks:
            return pairs.tasks, None
    return [], (
        f"found {len(pairs.tasks)} of {n_tasks} spawn/goal pairs at least {min_distance:g} m apart on free floor"
    )


class _Pairs:
    """Spawn/goal pairs taking shape from free points offered in turn: a spawn, then its goal, and so on."""

    def __init__(self, separation: float, min_distance: float, goal_tolerance: float, goal):
        self.separation, self.min_distance, self.goal_tolerance = separation, min_distance, goal_tolerance
        self.spawns: list[np.ndarray] = []
        self.goals: list[np.ndarray] = []
        self.tasks: list[Task] = []
        self.spawn_yaw = 0.0
        #: The first task's given goal, until that task is made.
        self.fixed_goal = None if goal is None else np.array(goal[:2], dtype=float)

    def fix_spawn(self, xy: np.ndarray, yaw: float) -> None:
        """The first task's spawn is given (a fixed pair skips min_distance: the caller chose it)."""
        self.spawns.append(xy)
        self.spawn_yaw = yaw
        if self.fixed_goal is not None:
            self._add(xy, yaw, self.fixed_goal, 0.0)

    def offer(self, p: np.ndarray, yaw: float) -> None:
        """Take ``p`` (heading ``yaw``) as the next spawn or goal where it keeps every distance."""
        if len(self.spawns) == len(self.tasks):  # looking for a spawn
            if not all(np.hypot(*(p - q)) >= self.separation for q in self.spawns):
                return
            if self.fixed_goal is not None:  # the first task's goal is given: its spawn is drawn
                if np.hypot(*(p - self.fixed_goal)) >= self.min_distance:
                    self.spawns.append(p)
                    self._add(p, yaw, self.fixed_goal, 0.0)
                return
            self.spawns.append(p)
            self.spawn_yaw = yaw
            return
        spawn_xy = self.spawns[-1]
        if np.hypot(*(p - spawn_xy)) < self.min_distance:
            return
        if all(np.hypot(*(p - q)) >= self.separation for q in self.goals + self.spawns[:-1]):
            self._add(spawn_xy, self.spawn_yaw, p, yaw)

    def _add(self, spawn_xy, spawn_yaw: float, goal_xy, goal_yaw: float) -> None:
        self.goals.append(goal_xy)
        self.tasks.append(_task(len(self.tasks), spawn_xy, spawn_yaw, goal_xy, goal_yaw, self.goal_tolerance))
        self.fixed_goal = None


def _task(i: int, spawn, spawn_yaw: float, goal, goal_yaw: float, goal_tolerance: float) -> Task:
    return Task(
        f"task_{i}",
        Pose(float(spawn[0]), float(spawn[1]), 0.0, 0.0, 0.0, spawn_yaw),
        Pose(float(goal[0]), float(goal[1]), 0.0, 0.0, 0.0, goal_yaw),
        goal_tolerance,
    )


def _free(index: FootprintIndex, bounds, robot: Robot, xy) -> bool:
    (x0, y0), (x1, y1) = bounds
    r = robot.inflation + _SLACK
    x, y = float(xy[0]), float(xy[1])
    inside = x0 + r <= x <= x1 - r and y0 + r <= y <= y1 - r
    return inside and not bool(index.blocked(np.array([[x, y]]), r)[0])


def region_bounds(bounds, region: Optional[float], robot: Robot):
    """The bounds within which drawn points keep to [-region, region]^2 (the disc may reach past it).

    ``free_points`` keeps the disc inside what it is given, so the region is
    widened by the disc's radius before it is intersected with ``bounds``.
    """
    if region is None:
        return bounds
    (x0, y0), (x1, y1) = bounds
    h = region + robot.inflation + _SLACK
    return ((max(x0, -h), max(y0, -h)), (min(x1, h), min(y1, h)))


def check_task_params(params: Mapping[str, Any], bounds) -> None:
    """Reject a fixed spawn/goal whose footprint leaves the floor, or a region with no room in it.

    Raises :class:`ParameterError` naming the parameter; whether the point is
    free of obstacles is the draw's business (obstacles may be random).
    """
    (x0, y0), (x1, y1) = bounds
    r = params["robot_radius"] + params["clearance"] + _SLACK
    floor = f"[{x0:g}, {x1:g}] x [{y0:g}, {y1:g}]"
    for name in ("spawn", "goal"):
        value = params.get(name)
        if value is None:
            continue
        x, y = value[0], value[1]
        if not (x0 + r <= x <= x1 - r and y0 + r <= y <= y1 - r):
            raise ParameterError(
                f"parameter '{name}' must keep the robot's {r - _SLACK:g} m disc (robot_radius + clearance) on the floor "
                f"{floor}, i.e. x in [{x0 + r:g}, {x1 - r:g}] and y in [{y0 + r:g}, {y1 - r:g}], got {value!r}")
    spawn = params.get("spawn")
    # pi as world.json writes it (3.141593) must pass, so that recorded params regenerate the world.
    if spawn is not None and not -3.1416 <= spawn[2] <= 3.1416:
        raise ParameterError(f"parameter 'spawn' yaw (third value) must be in [-3.1416, 3.1416] rad, got {spawn!r}")
    region = params.get("task_region")
    if region is not None:
        if min(region, x1 - r) < max(-region, x0 + r) or min(region, y1 - r) < max(-region, y0 + r):
            raise ParameterError(
                f"parameter 'task_region' must overlap the floor {floor} shrunk by the robot's disc, got {region!r}")


#: The task parameters every generator that draws tasks may take, under these names.
TASK_PARAMS = (
    Param("spawn", "triple", None, "fix the first task's spawn pose [x, y, yaw] instead of drawing it",
          -10000.0, 10000.0, optional=True, unit="m, m, rad"),
    Param("goal", "pair", None, "fix the first task's goal [x, y] instead of drawing it",
          -10000.0, 10000.0, optional=True, unit="m"),
    Param("task_region", "float", None, "draw spawns and goals only within [-h, h] x [-h, h] of the origin",
          0.0, 10000.0, optional=True, unit="m"),
)
