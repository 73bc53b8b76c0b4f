"""Run every feasibility check for a scene's tasks and assemble the report.

Per task: the spawn and goal discs lie inside the bounds; the footprint
cylinder at spawn and goal keeps ``robot.clearance`` from every collider (FCL);
the exact shortest path exists for the disc of radius ``robot.inflation``
(:mod:`~worldgen.feasibility.planner`, in the configuration space of
:mod:`~worldgen.feasibility.cspace`); and the written path keeps the clearance
along its whole length, proven by FCL on the volume the footprint sweeps
(:mod:`~worldgen.feasibility.verify`). Results are aggregated over tasks: a
check passes only if it passes for every task, its value is the worst figure,
and its detail names the task that set it.

The planner keeps a small safety margin :data:`~worldgen.scene.footprint.SAFETY` on top of the inflation
radius: FCL counts touching as collision, and the written waypoints are rounded
to 6 decimals. Half of it pays for the polygons written round arcs.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Optional, Sequence

import numpy as np

from worldgen.feasibility.collision import Colliders
from worldgen.feasibility.cspace import ConfigSpace
from worldgen.feasibility.exact import exact_planner
from worldgen.feasibility.geometry import Obstacles2D
from worldgen.feasibility.passage import narrowest_passage
from worldgen.feasibility.report import CHECKER, Check, FeasibilityReport, TaskPath
from worldgen.feasibility.route import waypoints
from worldgen.feasibility.terrain import terrain_check
from worldgen.feasibility.verify import verify_path
from worldgen.floats import DECIMALS
from worldgen.scene import Robot, Scene, Task
from worldgen.scene.doors import door_joints, fixed_scene, open_scene
from worldgen.scene.drivable import terrain_footprints
from worldgen.scene.footprint import SAFETY, robot_footprints

__all__ = ["check"]


def _bounds_margin(bounds, xy: np.ndarray) -> np.ndarray:
    """(n,) distance from each point to the nearest edge of the bounds (negative outside)."""
    (x0, y0), (x1, y1) = bounds
    return np.minimum(np.minimum(xy[:, 0] - x0, x1 - xy[:, 0]), np.minimum(xy[:, 1] - y0, y1 - xy[:, 1]))


def _p(xy) -> str:
    return f"({xy[0]:.3f}, {xy[1]:.3f})"


def check(scene: Scene, tasks: Sequence[Task], robot: Robot) -> FeasibilityReport:
    """Check every task of ``scene`` for ``robot``; never raises for an infeasible world.

    Doors (see :mod:`worldgen.scene.doors`) are planned through at their open limit;
    spawn and goal must be free both so and as the doors start, and the
    informational ``reachable_initial_state`` is this same check run with every
    leaf held where it starts: ok when every task can be driven without opening
    any door, its value then the longest such path (m).
    """
    initial = scene
    scene = open_scene(initial)  # the scene itself when it has no door to open
    colliders = Colliders(scene)
    initial_colliders = colliders if scene is initial else Colliders(initial)
    spawns = np.array([[t.spawn.x, t.spawn.y] for t in tasks], dtype=float).reshape(-1, 2)
    goals = np.array([[t.goal.x, t.goal.y] for t in tasks], dtype=float).reshape(-1, 2)
    inside = _inside_bounds(scene.bounds, tasks, robot, spawns, goals)
    free = {label: _free(label, tasks, robot, pts, colliders, initial_colliders)
            for label, pts in (("spawn", spawns), ("goal", goals))}
    plans = _Plans.of(scene, tasks, robot, colliders, spawns, goals)
    checks: tuple[Check, ...] = (inside, free["spawn"], free["goal"], plans.path_exists(),
                                 plans.path_clearance(tasks, robot))
    on_terrain: tuple = ()
    if scene.terrain is not None:  # only then, so that flat worlds keep their reports
        drivable, figures = terrain_check(scene, tasks, robot, plans.paths)
        checks, on_terrain = checks + (drivable,), tuple(figures)
    narrowest = min(plans.passages) if plans.passages and not plans.no_path else None
    informational: tuple[Check, ...] = ()
    if door_joints(initial):
        informational = (_reachable_initial(initial, tasks, robot),)
    return FeasibilityReport(checks, tuple(plans.paths), narrowest, CHECKER, informational, terrain=on_terrain)


def _inside_bounds(bounds, tasks, robot: Robot, spawns: np.ndarray, goals: np.ndarray) -> Check:
    """inside_bounds: the inflated disc at spawn and goal within the floor area."""
    margins = np.minimum(_bounds_margin(bounds, spawns), _bounds_margin(bounds, goals)) - robot.inflation
    return _aggregate("inside_bounds", tasks, margins, margins >= 0,
                      lambda i: f"{tasks[i].id}: spawn {_p(spawns[i])} / goal {_p(goals[i])} leave the "
                                f"{robot.inflation:g} m disc {-margins[i]:.4f} m outside the bounds",
                      lambda v: f"smallest margin {v:.4f} m")


def _free(label: str, tasks, robot: Robot, pts: np.ndarray, colliders, initial_colliders) -> Check:
    """spawn_free / goal_free with FCL; with doors, free both as they start and opened."""
    near = [colliders.nearest(robot, p[None, :]) for p in pts]
    if initial_colliders is not colliders:
        near = [min(n, initial_colliders.nearest(robot, p[None, :]), key=lambda m: m.distance)
                for n, p in zip(near, pts)]
    values = np.array([n.distance for n in near])
    return _aggregate(
        f"{label}_free", tasks, values, values >= robot.clearance,
        lambda i: (f"{tasks[i].id}: {label} {_p(pts[i])} is {near[i].distance:.4f} m from {near[i].name} "
                   f"(needs >= {robot.clearance:g} m)"),
        lambda v: f"smallest clearance {v:.4f} m")


@dataclass
class _Plans:
    """Each task's exact shortest path in the configuration space of the disc, proven with FCL."""

    paths: list[Optional[TaskPath]] = field(default_factory=list)
    passages: list[float] = field(default_factory=list)
    no_path: list[str] = field(default_factory=list)
    clearances: np.ndarray = field(default_factory=lambda: np.zeros(0))
    clearance_detail: dict[int, str] = field(default_factory=dict)

    @classmethod
    def of(cls, scene: Scene, tasks, robot: Robot, colliders, spawns: np.ndarray, goals: np.ndarray) -> "_Plans":
        bounds = scene.bounds
        # Ground the robot cannot drive is an obstacle like any other (worldgen.scene.drivable).
        obstacles = Obstacles2D.from_footprints(robot_footprints(scene, robot) + terrain_footprints(scene, robot))
        cspace = ConfigSpace.build(obstacles, robot.inflation + SAFETY, bounds)
        planner = exact_planner(cspace, len(tasks))
        slack = cspace.points_clearance(np.vstack([spawns, goals]))
        start_slack, goal_slack = slack[: len(tasks)], slack[len(tasks):]
        out = cls(clearances=np.full(len(tasks), np.nan))
        for i, task in enumerate(tasks):
            s, g = spawns[i], goals[i]
            if start_slack[i] < 0 or goal_slack[i] < 0:
                out.paths.append(None)
                which = "spawn" if start_slack[i] < 0 else "goal"
                out.no_path.append(f"{task.id}: the {which} is not free for a {robot.inflation:g} m disc")
                continue
            route = planner.shortest(s, g)
            if route is None:
                out.paths.append(None)
                out.no_path.append(f"{task.id}: no path for a {robot.inflation:g} m disc from {_p(s)} to {_p(g)}")
                continue
            line = np.round(waypoints(cspace, route, SAFETY / 2), DECIMALS)
            line[0], line[-1] = s, g
            nearest = verify_path(colliders, robot, line)
            clearance = nearest.distance
            if not np.isfinite(clearance):  # nothing to hit: the floor's edge is the only limit
                clearance = float(_bounds_margin(bounds, line).min() - robot.radius)
            out.clearances[i] = clearance
            if clearance < robot.clearance:
                out.clearance_detail[i] = (f"{task.id}: the path passes {clearance:.4f} m from {nearest.name} at "
                                           f"{_p(nearest.where)} (needs >= {robot.clearance:g} m)")
            out.paths.append(TaskPath(task.id, line, route.length, clearance))
            out.passages.append(narrowest_passage(obstacles, bounds, s, g))
        return out

    def path_exists(self) -> Check:
        found = [p for p in self.paths if p is not None]
        if self.no_path:
            return Check("path_exists", False, None, "; ".join(self.no_path))
        longest = max((p.length for p in found), default=None)
        return Check("path_exists", True, longest,
                     f"{len(found)} path(s), longest {longest:.3f} m" if found else "no tasks")

    def path_clearance(self, tasks, robot: Robot) -> Check:
        if self.no_path:
            found = any(p is not None for p in self.paths)
            return Check("path_clearance", False, float(np.nanmin(self.clearances)) if found else None,
                         "no path to verify for " + ", ".join(d.split(":")[0] for d in self.no_path))
        return _aggregate("path_clearance", tasks, self.clearances, self.clearances >= robot.clearance,
                          lambda i: self.clearance_detail.get(i, ""),
                          lambda v: f"smallest FCL clearance {v:.4f} m along the swept paths")


def _reachable_initial(initial: Scene, tasks, robot: Robot) -> Check:
    """Informational: can every task be driven with the doors as they start (closed and ajar leaves held)?

    The whole check again, on the scene whose door hinges are fixed; it never
    makes a world infeasible (the reference path assumes the doors opened).
    """
    report = check(fixed_scene(initial), tasks, robot)
    if report.feasible:
        longest = max(p.length for p in report.paths if p is not None)  # feasible: every task has one
        return Check("reachable_initial_state", True, longest,
                     f"every task can be driven with the doors as they start; longest path {longest:.3f} m")
    failed = "; ".join(f"{c.name}: {c.detail}" for c in report.failed())
    return Check("reachable_initial_state", False, None,
                 f"not with the doors as they start ({failed}); informational: the reference path opens them")


def _aggregate(name: str, tasks, values: np.ndarray, ok: np.ndarray, fail_detail, ok_detail) -> Check:
    """One check over all tasks: value = the worst figure, detail names the failing task."""
    values = np.asarray(values, dtype=float)
    finite = np.isfinite(values)
    if not len(tasks):
        return Check(name, False, None, "no tasks")
    worst = int(np.argmin(np.where(finite, values, np.inf)))
    value = float(values[worst]) if finite[worst] else None
    if not np.all(ok):
        first = int(np.argmin(ok))
        return Check(name, False, value, fail_detail(first))
    return Check(name, True, value, ok_detail(value) if value is not None else "nothing to hit")
