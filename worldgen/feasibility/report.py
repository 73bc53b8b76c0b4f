"""The feasibility report: every check that ran, its result, and the proven paths."""

from __future__ import annotations

from dataclasses import dataclass
from typing import Optional

import numpy as np

__all__ = ["Check", "TaskPath", "FeasibilityReport", "REQUIRED_CHECKS", "CHECKER"]

#: The method behind every report: paths planned exactly on the tangent graph of the configuration
#: space, then proven with FCL along their swept volume (docs/feasibility.md).
CHECKER = "exact_tangent_graph+fcl"

#: Checks every report carries, in this order (docs/world-json.md names them).
REQUIRED_CHECKS = ("inside_bounds", "spawn_free", "goal_free", "path_exists", "path_clearance")


@dataclass(frozen=True)
class Check:
    """One check. ``value`` is the figure it judged (e.g. a clearance in m), None if none."""

    name: str
    ok: bool
    value: Optional[float] = None
    detail: str = ""


@dataclass(frozen=True, eq=False)
class TaskPath:
    """A proven path for one task.

    ``waypoints`` (k, 2) float, first = spawn, last = goal; ``length`` m;
    ``min_clearance`` m from the footprint's edge (radius robot.radius) to the
    nearest obstacle, measured with FCL along the whole path.
    """

    task_id: str
    waypoints: np.ndarray
    length: float
    min_clearance: float


@dataclass(frozen=True, eq=False)
class FeasibilityReport:
    """``feasible`` is True only when every check passed.

    ``paths`` has one entry per task (None where no path was found);
    ``narrowest_passage`` is the widest disc diameter that still gets from
    spawn to goal of the hardest task (m); ``checker`` names the method that
    proved the paths (:data:`CHECKER`).
    """

    checks: tuple[Check, ...]
    paths: tuple[Optional[TaskPath], ...]
    narrowest_passage: Optional[float]
    checker: str
    #: Checks that inform but never decide ``feasible`` (e.g. ``reachable_initial_state``
    #: for doors: the reference path assumes them open).
    informational: tuple[Check, ...] = ()
    #: With people: per task, the certificate among them (a TimedPath of
    #: :mod:`worldgen.people.timed`, None where there is none); () without people.
    timed_paths: tuple = ()
    #: On terrain: per task, the terrain along its path (a PathTerrain of
    #: :mod:`worldgen.feasibility.terrain`, None where there is no path); () on flat ground.
    terrain: tuple = ()

    @property
    def feasible(self) -> bool:
        return all(c.ok for c in self.checks)

    def failed(self) -> list[Check]:
        return [c for c in self.checks if not c.ok]

    def check(self, name: str) -> Check:
        for c in self.checks:
            if c.name == name:
                return c
        raise KeyError(name)
