"""Feasibility: prove a drawn world drivable for the robot footprint, with FCL.

Placeholder until the planner lands: ``check(scene, tasks, robot)`` returns a
:class:`FeasibilityReport`.
"""

from worldgen.feasibility.report import REQUIRED_CHECKS, Check, FeasibilityReport, TaskPath

__all__ = ["check", "Check", "FeasibilityReport", "TaskPath", "REQUIRED_CHECKS"]


def check(scene, tasks, robot) -> FeasibilityReport:  # replaced by the real checker
    raise NotImplementedError("feasibility.check is being built")
