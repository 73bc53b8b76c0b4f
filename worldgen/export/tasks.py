"""The task block: one builder of a task's ground truth, read by world.json (``tasks[]``), scenario.yaml
(its limits and doors) and the RL environment (its episode's task, without rendering any file)."""

from __future__ import annotations

import math
from typing import Any, Mapping, Optional

import numpy as np

from worldgen.floats import finite_or_none
from worldgen.scene.doors import door_joints, leaves_in_the_way
from worldgen.scene.robot import MAX_SPEED

__all__ = ["TIME_FACTOR", "TIME_MARGIN", "DOOR_TIME", "time_limit", "robot_speed", "leaves_on_path", "task_entry"]

#: time_limit = TIME_FACTOR x path length / robot_speed + TIME_MARGIN: twice the time an
#: ideal run needs, plus a fixed allowance for start-up and turning on the spot; at least the task's
#: certified arrival among people and movers + TIME_MARGIN.
TIME_FACTOR = 2.0
TIME_MARGIN = 10.0
#: Added to time_limit for each door leaf the path needs moved (pushing or pulling it open).
DOOR_TIME = 10.0


def time_limit(length: float, robot_speed: float, doors: int = 0) -> float:
    """A generous time bound (s) for a path of ``length`` m at ``robot_speed`` m/s that must open ``doors`` leaves."""
    return TIME_FACTOR * length / robot_speed + TIME_MARGIN + DOOR_TIME * doors


def robot_speed(params: Mapping[str, Any]) -> float:
    """The speed (m/s) a world's time limits assume: its ``robot_speed`` parameter, or that parameter's default
    (the robot description's, worldgen.scene.robot.MAX_SPEED)."""
    return params.get("robot_speed", MAX_SPEED)


def leaves_on_path(world, path) -> list[str]:
    """The door leaves, as they start, that the robot's footprint meets along ``path`` (none without a path)."""
    if path is None or not door_joints(world.scene):
        return []
    return leaves_in_the_way(world.scene, path.waypoints, world.robot.radius, world.robot.height)


def task_entry(world, task, path, leaves: Optional[list] = None) -> dict:
    """world.json's ``tasks[]`` entry of ``task`` with its proven ``path`` (None: no path), floats unrounded."""
    leaves = leaves_on_path(world, path) if leaves is None else leaves
    spawn, goal = task.spawn, task.goal
    out = {
        "id": task.id,
        "spawn": spawn.as_list(),
        "goal": goal.as_list(),
        "goal_tolerance": task.goal_tolerance,
        "straight_line_distance": math.hypot(goal.x - spawn.x, goal.y - spawn.y),
        "path": None,
        "time_limit": None,
        "requires_door_open": bool(leaves),
    }
    if path is not None:
        out["path"] = {
            "waypoints": np.asarray(path.waypoints, dtype=float).reshape(-1, 2).tolist(),
            "length": float(path.length),
            "min_clearance": finite_or_none(path.min_clearance),
        }
        out["time_limit"] = time_limit(float(path.length), robot_speed(world.params), len(leaves))
        certificate = _certificate(world, task)
        if certificate is not None:
            # A run that keeps to its certificate is never out of time: waiting for a gap among people and
            # movers may take longer than twice the path at full speed.
            out["time_limit"] = max(out["time_limit"], certificate.arrival + TIME_MARGIN)
    return out


def _certificate(world, task):
    """The task's timed path among the world's people and movers (worldgen.people.timed), or None."""
    certificates = getattr(world.feasibility, "timed_paths", ())
    for other, certificate in zip(world.tasks, certificates):
        if other.id == task.id:
            return certificate
    return None

