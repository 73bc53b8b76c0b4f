"""The certificate off the static path: where the sweep along a task's path finds no timed path (a mover pacing
along a corridor's centreline, a person standing on it once the walk ends), a route that steps aside, timed by
the same sweep (docs/people.md, "Off the path").

1. :func:`worldgen.people.lattice.lattice_route` finds a witness through space and time among the agents, a
   robot on a grid of cells that waits, moves and turns on the spot no faster than the robot, keeping
   ``room`` more than the certificate from every agent; its route is the polyline through the cells where
   it turns.
2. The route is proven clear of the static geometry by FCL, the robot's disc swept along it keeping
   ``robot.clearance`` (and 10 um more, for world.json's 6-decimal rows), as the static path was; near a
   door not open it keeps within :data:`DOOR_STRAY` of the static path (:func:`_strays`).
3. :func:`worldgen.people.timed.timed_path` times the route exactly as it times a static path: top speed,
   acceleration, every corner turned on the spot at the turn rate (none passed moving: ``worldgen check``
   re-derives those from the recorded static path only), and the same reach from every person, tube and
   looping mover. What it finds is the certificate, checked by ``worldgen check`` from world.json alone like
   any other; the witness only says where to look.

Each of :data:`ROOMS` is tried in turn until one gives a certificate: a wide room leaves the exact timing
(slower through its turns and starts than the witness) slack to pass the agents the witness passed, a narrow
one finds ways a wide one cannot.
"""

from __future__ import annotations

import math
from dataclasses import replace
from typing import Optional, Sequence

import numpy as np

from worldgen.feasibility.report import FeasibilityReport
from worldgen.people.behaviours import Tube
from worldgen.people.grid import PACE, floor_of
from worldgen.people.lattice import Agents, lattice_reachable, lattice_route
from worldgen.people.timed import MARGIN, TRACKING, Limits, TimedPath, agents_of, timed_check, timed_path

__all__ = ["ROOMS", "AFTER", "DOOR_STRAY", "MAX_WORK", "off_path", "certify_off_path"]

#: m the witness keeps from every agent beyond the certificate's reach, tried in turn.
ROOMS = (0.15, 0.05)
#: s the witness may take beyond the time everyone stops (or the slowest loop comes round) and twice the
#: static path at the witness's axis speed.
AFTER = 10.0
#: m a route may stray from the static path within a door's reach (its hinge, its leaf's width and the robot's
#: inflation): about where a doorway's own slack puts it.
DOOR_STRAY = 0.15
#: Most cell-steps a witness is sought over (its stored states take a byte each): 2,000 steps of a 10 x 3 m
#: corridor, 200 s; a longer horizon is cut there.
MAX_WORK = 60_000_000


def off_path(scene, colliders, task, waypoints, robot, limits: Limits, tracks: Sequence[np.ndarray],
             radii: Sequence[float], tubes: Sequence[Tube], loops: Sequence[bool]) -> Optional[TimedPath]:
    """A timed path for ``task`` off its static path ``waypoints`` (k, 2) among the agents (``tracks``,
    ``radii``, ``tubes``, ``loops``), within ``limits``, its route clear of ``colliders`` (the scene's,
    doors open) by FCL; None where no room of :data:`ROOMS` gives one."""
    from worldgen.feasibility.verify import verify_path
    from worldgen.scene.doors import door_records, open_scene
    from worldgen.scene.footprint import robot_footprints

    spawn, goal = task.spawn, task.goal
    w = np.asarray(waypoints, dtype=float).reshape(-1, 2)
    # A leaf at its open limit stands where the static world has it; a closed or ajar one is moved by the robot.
    doors = [(d["hinge"][0], d["hinge"][1], d["width"] + robot.inflation) for d in door_records(scene)
             if d["state"] != "open"]
    floor = floor_of(robot_footprints(open_scene(scene), robot), scene.bounds, (spawn.x, spawn.y), (goal.x, goal.y),
                     float(task.goal_tolerance), w, robot.inflation, limits)
    if floor is None:
        return None
    length = float(np.hypot(*np.diff(w, axis=0).T).sum())
    end = max([float(t[-1, 0]) for t in tracks] + [0.0])
    steps = math.ceil((end + 2.0 * length / (PACE * limits.max_speed / math.sqrt(2.0)) + AFTER) / floor.dt)
    steps = min(steps, MAX_WORK // floor.static.size)  # a slow mover's long loop would hold every step's states
    keep = robot.inflation + MARGIN + TRACKING
    among = {room: Agents(floor, tracks, radii, tubes, loops, keep, room, limits.max_speed) for room in ROOMS}
    # A wider room blocks more: where a robot that turns in no time finds no way at the narrowest, none does.
    if not lattice_reachable(among[min(ROOMS)], steps):
        return None
    for room in ROOMS:
        route = lattice_route(among[room], float(spawn.yaw), limits, steps)
        if route is None or _strays(route, w, doors) or \
                verify_path(colliders, robot, route).distance < robot.clearance + 1e-5:
            continue  # a narrower room may find a way a wider one blocks
        timed = timed_path(route, tracks, radii, robot.inflation, limits, tubes, heading=float(spawn.yaw),
                           loops=[bool(x) for x in loops])
        if timed is not None:
            return timed
    return None


def _strays(route: np.ndarray, waypoints: np.ndarray, doors) -> bool:
    """Whether ``route`` (m, 2) comes farther than :data:`DOOR_STRAY` from the static path ``waypoints`` anywhere
    within the disc of a door not open (``doors``: (x, y, r), its hinge and its leaf's width plus the robot's
    inflation).

    Such a leaf stands where the static world has it, open, only once the robot has pushed or pulled it there,
    and the static path is the way through that the drive opens: a route that stepped into an ajar push leaf's
    sweep from beside it pressed the leaf shut on the robot, stuck (door seed 101, certified off the path by
    force in benchmarks/bench_offpath.py)."""
    import shapely

    if not doors:
        return False
    seg = np.diff(route, axis=0)
    n = np.maximum(1, np.ceil(np.hypot(*seg.T) / 0.02)).astype(int)
    pts = np.vstack([route[i] + seg[i] * np.linspace(0.0, 1.0, k, endpoint=False)[:, None] for i, k in enumerate(n)]
                    + [route[-1:]])
    inside = np.zeros(len(pts), dtype=bool)
    for x, y, r in doors:
        inside |= np.hypot(pts[:, 0] - x, pts[:, 1] - y) <= r
    if not inside.any():
        return False
    line = shapely.LineString(waypoints) if len(waypoints) > 1 else shapely.Point(waypoints[0])
    return bool((shapely.distance(shapely.points(pts[inside]), line) > DOOR_STRAY).any())


def certify_off_path(report: FeasibilityReport, scene, tasks, robot, limits: Limits,
                     behaviours: Optional[Sequence[str]] = None) -> FeasibilityReport:
    """``report`` (:func:`worldgen.people.timed.certify`'s) with a timed path off the static path for every task
    that has a static path and no timed path along it, and its ``timed_path`` check made again: passed when
    every task now has one. ``behaviours`` as for ``certify``."""
    agents, tracks, radii, loops, tubes = agents_of(scene, behaviours)
    colliders = None
    found, moved, missing = list(report.timed_paths), 0, []
    for q, (task, path) in enumerate(zip(tasks, report.paths)):
        if found[q] is not None or path is None:
            if path is None:
                missing.append(f"{task.id}: no static path")
            continue
        if colliders is None:
            from worldgen.feasibility.collision import Colliders
            from worldgen.scene.doors import open_scene

            colliders = Colliders(open_scene(scene))
        found[q] = off_path(scene, colliders, task, path.waypoints, robot, limits, tracks, radii, tubes, loops)
        moved += found[q] is not None
        if found[q] is None:
            missing.append(f"{task.id}: they leave no way through at <= {limits.max_speed:g} m/s, along the path "
                           "or off it")
    checks = tuple(c for c in report.checks if c.name != "timed_path")
    return replace(report, checks=checks + (timed_check(agents, found, missing, off=moved),), timed_paths=tuple(found))
