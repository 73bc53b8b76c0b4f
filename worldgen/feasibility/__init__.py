"""Feasibility: prove a drawn world drivable for the robot footprint, with FCL.

``check(scene, tasks, robot)`` returns a :class:`FeasibilityReport`. The modules,
in the order the data flows through them:

- ``geometry``: footprints as arrays; exact point/segment distances to them;
- ``field``: the exact clearance of every grid cell centre;
- ``portals``: exactly checked crossings of gaps too narrow for the grid to prove;
- ``planner``: grid search (16-connected, field-proven moves, plus portals) and string-pulling;
- ``taut``: tightening to the exact taut path (tangents and arcs);
- ``visibility``: an exact local visibility graph, where tightening fails;
- ``passage``: the narrowest passage (bottleneck) of a task;
- ``collision``: FCL objects and broad-phased distance queries;
- ``verify``: sampling a path and proving it with FCL;
- ``check``: running it all and assembling the report.
"""

from worldgen.feasibility.check import check
from worldgen.feasibility.report import REQUIRED_CHECKS, Check, FeasibilityReport, TaskPath

__all__ = ["check", "Check", "FeasibilityReport", "TaskPath", "REQUIRED_CHECKS"]
