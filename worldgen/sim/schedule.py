"""What ``worldgen drive`` follows: a world's certificate where it has things that move, else the static path.

- A world with people or movers has its certificate, world.json ``tasks[].timed_path`` (docs/people.md,
  re-proved by ``worldgen check``): the drive follows it as written.
- Otherwise (a static world, a task without a certificate in a world written infeasible on purpose, or the
  ``straight`` test hook) the static path.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Optional

import numpy as np

__all__ = ["Plan", "plan_for"]


@dataclass(frozen=True, eq=False)
class Plan:
    """``kind``: ``"timed_path"`` (world.json's certificate), ``"static"`` (the static path) or ``"straight"``
    (spawn -> goal, the test hook); ``rows`` the (k, 3) ``t, x, y`` schedule (None for a path); ``waypoints``
    (m, 2) the path; ``speed`` the schedule's top speed (m/s); ``note`` says what the plan rests on."""

    kind: str
    waypoints: np.ndarray
    speed: float
    rows: Optional[np.ndarray] = None
    note: str = ""


def plan_for(meta: dict, task: dict, speed: float, straight: bool = False) -> Plan:
    """The plan the drive follows in task ``task`` of world.json ``meta`` (see the module's docstring);
    ``speed`` (m/s) where world.json's robot states no ``max_speed``."""
    spawn, goal = task["spawn"], task["goal"]
    if straight:
        return Plan("straight", np.array([spawn[:2], goal[:2]], dtype=float), speed, note="spawn -> goal")
    waypoints = np.asarray(task["path"]["waypoints"], dtype=float)
    if task.get("timed_path"):
        top = float(meta["robot"].get("max_speed", speed))
        return Plan("timed_path", waypoints, top, np.asarray(task["timed_path"], dtype=float),
                    "world.json's tasks[].timed_path")
    return Plan("static", waypoints, speed, note="tasks[].path.waypoints")
