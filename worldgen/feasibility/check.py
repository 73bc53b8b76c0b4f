"""Run every feasibility check for a scene's tasks and assemble the report.

Per task: the spawn and goal discs lie inside the bounds; the footprint
cylinder at spawn and goal keeps ``robot.clearance`` from every collider (FCL);
a path exists for the disc of radius ``robot.inflation``; and that path, sampled
every ``robot.radius / 4``, keeps the clearance everywhere (FCL). Results are
aggregated over tasks: a check passes only if it passes for every task, its
value is the worst figure, and its detail names the task that set it.

The path is planned in the plane (clearance field, grid search with portals
through narrow gaps, string-pulling, tightening, and where tightening fails an
exact local visibility graph; see the sibling modules) with a small safety margin
:data:`SAFETY` on top of the inflation radius, so rounding the written
waypoints to 6 decimals can never bring the footprint closer than required.
"""

from __future__ import annotations

import math
from typing import Optional, Sequence

import numpy as np

from worldgen.doors import door_joints, fixed_scene, open_scene
from worldgen.feasibility.collision import Colliders
from worldgen.feasibility.field import distance_field, grid_for
from worldgen.feasibility.geometry import Obstacles2D
from worldgen.feasibility.passage import bottleneck_radius, exact_width, extend_field
from worldgen.feasibility.planner import grid_path, string_pull
from worldgen.feasibility.portals import find_portals
from worldgen.feasibility.visibility import encloses, local_shortest
from worldgen.feasibility.report import Check, FeasibilityReport, TaskPath
from worldgen.feasibility.taut import tighten
from worldgen.feasibility.verify import verify_path
from worldgen.floats import DECIMALS
from worldgen.footprint import scene_footprints
from worldgen.scene import Robot, Scene, Task

__all__ = ["check", "resolution_for", "SAFETY"]

#: Extra margin (m) the planner keeps on top of the inflation radius: far above
#: the 6-decimal rounding of waypoints and FCL's solver tolerance, far below any
#: length that matters (it lengthens a path by well under 0.1 %).
SAFETY = 1e-4
#: Grid cell size as a fraction of the inflation radius, and its limits (m).
RESOLUTION_FRACTION = 1.0 / 3.0
RESOLUTION_LIMITS = (0.01, 0.25)
#: How far from the reference path (m) the fallback visibility graph looks for obstacles.
LOCAL_REACH = 0.5
#: Largest grid (cells); bigger floors get coarser cells instead.
MAX_CELLS = 1_000_000


def resolution_for(robot: Robot, bounds) -> float:
    """The grid cell size (m) used for ``robot`` on a floor of ``bounds``."""
    (x0, y0), (x1, y1) = bounds
    h = min(max(robot.inflation * RESOLUTION_FRACTION, RESOLUTION_LIMITS[0]), RESOLUTION_LIMITS[1])
    return max(h, math.sqrt((x1 - x0) * (y1 - y0) / MAX_CELLS))


def _bounds_margin(bounds, xy: np.ndarray) -> np.ndarray:
    """(n,) distance from each point to the nearest edge of the bounds (negative outside)."""
    (x0, y0), (x1, y1) = bounds
    return np.minimum(np.minimum(xy[:, 0] - x0, x1 - xy[:, 0]), np.minimum(xy[:, 1] - y0, y1 - xy[:, 1]))


def _p(xy) -> str:
    return f"({xy[0]:.3f}, {xy[1]:.3f})"


def check(scene: Scene, tasks: Sequence[Task], robot: Robot) -> FeasibilityReport:
    """Check every task of ``scene`` for ``robot``; never raises for an infeasible world.

    Doors (see :mod:`worldgen.doors`) are planned through at their open limit;
    spawn and goal must be free both so and as the doors start, and the
    informational ``reachable_initial_state`` is this same check run with every
    leaf held where it starts: ok when every task can be driven without opening
    any door, its value then the longest such path (m).
    """
    initial = scene
    scene = open_scene(initial)  # the scene itself when it has no door to open
    bounds = scene.bounds
    colliders = Colliders(scene)
    initial_colliders = colliders if scene is initial else Colliders(initial)
    obstacles = Obstacles2D.from_footprints(scene_footprints(scene, robot.height + robot.clearance))
    spawns = np.array([[t.spawn.x, t.spawn.y] for t in tasks], dtype=float).reshape(-1, 2)
    goals = np.array([[t.goal.x, t.goal.y] for t in tasks], dtype=float).reshape(-1, 2)
    radius = robot.inflation + SAFETY

    # inside_bounds: the inflated disc at spawn and goal within the floor area.
    margins = np.minimum(_bounds_margin(bounds, spawns), _bounds_margin(bounds, goals)) - robot.inflation
    inside = _aggregate("inside_bounds", tasks, margins, margins >= 0,
                        lambda i: f"{tasks[i].id}: spawn {_p(spawns[i])} / goal {_p(goals[i])} leave the "
                                  f"{robot.inflation:g} m disc {-margins[i]:.4f} m outside the bounds",
                        lambda v: f"smallest margin {v:.4f} m")

    # spawn_free / goal_free with FCL.
    free = {}
    for label, pts in (("spawn", spawns), ("goal", goals)):
        near = [colliders.nearest(robot, p[None, :]) for p in pts]
        if initial_colliders is not colliders:  # doors: free both as they start and opened
            near = [min(n, initial_colliders.nearest(robot, p[None, :]), key=lambda m: m.distance)
                    for n, p in zip(near, pts)]
        values = np.array([n.distance for n in near])
        free[label] = _aggregate(
            f"{label}_free", tasks, values, values >= robot.clearance,
            lambda i, near=near, pts=pts, label=label: (
                f"{tasks[i].id}: {label} {_p(pts[i])} is {near[i].distance:.4f} m from {near[i].name} "
                f"(needs >= {robot.clearance:g} m)"),
            lambda v: f"smallest clearance {v:.4f} m")

    # Planning in the plane.
    h = resolution_for(robot, bounds)
    grid = grid_for(bounds, h)
    ends = np.vstack([spawns, goals])
    clear2d = np.minimum(obstacles.points_distance(ends)[0], _bounds_margin(bounds, ends))
    start_clear, goal_clear = clear2d[: len(tasks)], clear2d[len(tasks):]
    endpoint_clear = np.minimum(start_clear, goal_clear)
    plannable = endpoint_clear > radius
    # Exact values are needed only near the inflation radius (planning proves moves
    # against it); the passage search reads farther out from a cheap extension.
    cap = radius + 2.5 * h
    field = distance_field(obstacles, bounds, grid, cap)
    wide = None  # the field extended beyond cap, made on first need
    portals = find_portals(obstacles, bounds, radius, h)

    paths: list[Optional[TaskPath]] = []
    passages: list[float] = []
    no_path: list[str] = []
    clearances = np.full(len(tasks), np.nan)
    clearance_detail: dict[int, str] = {}
    for i, task in enumerate(tasks):
        s, g = spawns[i], goals[i]
        if not plannable[i]:
            paths.append(None)
            which = "spawn" if start_clear[i] <= radius else "goal"
            no_path.append(f"{task.id}: the {which} is not free for a {robot.inflation:g} m disc")
            continue
        raw = grid_path(field, s, g, radius, obstacles, bounds, portals)
        if raw is None:
            paths.append(None)
            no_path.append(f"{task.id}: no path for a {robot.inflation:g} m disc from {_p(s)} to {_p(g)} "
                           f"(grid {grid.hx:.3f} m)")
            continue
        ref = string_pull(field, raw, radius)
        taut = tighten(obstacles, ref, radius, bounds, near=3 * h)
        if taut is None or _length(taut) >= _length(ref) or encloses(taut, ref, obstacles):
            # Tightening gave up, went nowhere, or settled round the wrong side of an obstacle
            # (then the grid's choice of way round is lost): search the obstacles around the
            # path with an exact local visibility graph instead. Rare, and slower.
            around = local_shortest(obstacles, ref, radius, bounds, reach=LOCAL_REACH)
            if around is not None:
                again = tighten(obstacles, around, radius, bounds, near=3 * h)
                if again is not None and _length(again) < _length(around) and not encloses(again, around, obstacles):
                    around = again
                if taut is None or _length(around) < _length(taut):
                    taut = around
        best = ref if taut is None or _length(taut) > _length(ref) else taut
        waypoints = np.round(best, DECIMALS)
        waypoints[0], waypoints[-1] = s, g
        nearest, samples = verify_path(colliders, robot, waypoints)
        clearance = nearest.distance
        if not np.isfinite(clearance):  # nothing to hit: the floor's edge is the only limit
            clearance = float(_bounds_margin(bounds, samples).min() - robot.radius)
        clearances[i] = clearance
        if clearance < robot.clearance:
            at = samples[nearest.index]
            clearance_detail[i] = (f"{task.id}: the path passes {clearance:.4f} m from {nearest.name} at {_p(at)} "
                                   f"(needs >= {robot.clearance:g} m)")
        paths.append(TaskPath(task.id, waypoints, _length(waypoints), clearance))
        high = float(endpoint_clear[i])
        if high > field.cap and wide is None:
            wide = extend_field(field)
        on = field if high <= field.cap else wide
        passage = exact_width(2.0 * bottleneck_radius(on, s, g, radius, high), on, obstacles, s, g)
        # A gap the grid cannot see (a portal) on the path is measured exactly: where the grid
        # found no route at all (passage stuck at its lower bound) the portal is the bottleneck.
        through = [p.width for p in portals if _passes(raw, p)]
        if through:
            passage = min(through) if passage <= 2 * radius + 1e-9 else max(passage, min(through))
        passages.append(passage)

    found = [p for p in paths if p is not None]
    path_exists = Check("path_exists", not no_path,
                        max(p.length for p in found) if found and not no_path else None,
                        "; ".join(no_path) if no_path else f"{len(found)} path(s), longest {max(p.length for p in found):.3f} m"
                        if found else "no tasks")
    if no_path:
        path_clearance = Check("path_clearance", False,
                               float(np.nanmin(clearances)) if found else None,
                               "no path to verify for " + ", ".join(d.split(":")[0] for d in no_path))
    else:
        path_clearance = _aggregate("path_clearance", tasks, clearances, clearances >= robot.clearance,
                                    lambda i: clearance_detail.get(i, ""),
                                    lambda v: f"smallest FCL clearance {v:.4f} m along the sampled paths")
    checks = (inside, free["spawn"], free["goal"], path_exists, path_clearance)
    narrowest = min(passages) if passages and not no_path else None
    informational = ()
    if door_joints(initial):
        informational = (_reachable_initial(initial, tasks, robot),)
    return FeasibilityReport(checks, tuple(paths), narrowest, "fcl", grid.hx, informational)


def _reachable_initial(initial: Scene, tasks, robot: Robot) -> Check:
    """Informational: can every task be driven with the doors as they start (closed and ajar leaves held)?

    The whole check again, on the scene whose door hinges are fixed; it never
    makes a world infeasible (the reference path assumes the doors opened).
    """
    report = check(fixed_scene(initial), tasks, robot)
    if report.feasible:
        longest = max(p.length for p in report.paths)
        return Check("reachable_initial_state", True, longest,
                     f"every task can be driven with the doors as they start; longest path {longest:.3f} m")
    failed = "; ".join(f"{c.name}: {c.detail}" for c in report.failed())
    return Check("reachable_initial_state", False, None,
                 f"not with the doors as they start ({failed}); informational: the reference path opens them")


def _passes(points: np.ndarray, portal) -> bool:
    """True when the grid path ``points`` runs through ``portal`` (holds both its ends)."""
    return all(bool(np.any(np.all(points == end, axis=1))) for end in portal.ends)


def _length(points: np.ndarray) -> float:
    return float(np.hypot(*np.diff(points, axis=0).T).sum())


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
