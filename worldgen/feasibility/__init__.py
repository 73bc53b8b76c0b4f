"""Feasibility: prove a drawn world drivable for the robot footprint, exactly, and verify it with FCL.

``check(scene, tasks, robot)`` returns a :class:`FeasibilityReport`. The modules,
in the order the data flows through them:

- ``geometry``: footprints as arrays; exact point/segment distances to them;
- ``cspace``: the configuration space: obstacles grown by the robot's disc (corner
  circles with their cones), the bounds shrunk by it, exact segment and arc clearances;
- ``tangents``: common tangents between corner circles, the edges of the tangent graph;
- ``planner``: the exact shortest path (lazy A* over the tangent graph) and its polyline;
- ``roadmap``: the same paths over the whole tangent graph built once (many queries in one space);
- ``exact``: the one interface of the two (``ExactPlanner``) and ``exact_planner``, which picks one
  by the number of queries coming;
- ``passage``: the exact narrowest passage (the widest disc that gets through);
- ``collision``: FCL objects and broad-phased distance queries;
- ``verify``: the FCL proof of a path, on the volume the footprint sweeps along it;
- ``check``: running it all and assembling the report;
- ``crowd``: people walked by the social force model round the exact geometry (docs/people.md);
- ``timed``: the timed path among them, the certificate ``pipeline.attempt`` adds with people.
"""

from worldgen.feasibility.check import check
from worldgen.feasibility.report import REQUIRED_CHECKS, Check, FeasibilityReport, TaskPath

__all__ = ["check", "Check", "FeasibilityReport", "TaskPath", "REQUIRED_CHECKS"]
