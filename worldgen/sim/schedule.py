"""What ``worldgen drive`` follows: a timed path where a world has things that move, else the static path.

- A world with people and no movers has its certificate, world.json ``tasks[].timed_path``
  (docs/people.md): the drive follows it as written.
- A world with movers (``dynamic_obstacles``, scripts that loop for ever) has no certificate among them
  (world.json carries none yet), so the drive works one out before it starts, with the certificate's own
  sweep (:func:`worldgen.people.timed.timed_path`) along the task's static path: each mover's loop is
  unrolled over the task's time limit into a track that does not loop, so it is one more impassive walker
  on a known schedule; people (with their tubes, if they react) are taken in the same sweep. The sweep keeps
  the robot's disc, grown by :data:`TRACKING` for the follower's lag, ``robot.clearance + 0.01 m`` off every
  mover and tube at every instant; where no such schedule exists it tries again without :data:`TRACKING`.
  The guarantee is the certificate's: a robot on the schedule never touches a mover that keeps to its script;
  what is not guaranteed is the follower's keeping to the schedule (measured in benchmarks/bench_drive_dynamic.py).
- Otherwise (a static world, or the ``straight`` test hook) the static path.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any, Callable, Optional

import numpy as np

from worldgen.groundtruth.folder import robot_description_of, robot_of

__all__ = ["TRACKING", "CATCH_UP", "Plan", "plan_for", "unrolled"]

#: m added to the robot's inflation in a schedule worked out among movers: room for the follower's lag behind
#: it (the lag that turning at a corner within the robot's turn rate costs).
TRACKING = 0.1
#: On a schedule the follower may go this many times the schedule's top speed to catch up with it, never beyond
#: the robot's max_speed: a schedule worked out off the path (worldgen.sim.spacetime) turns at every row on
#: the spot, which a robot within its turn rate cannot, so it runs at the robot's max_speed / CATCH_UP and
#: leaves the robot room to catch up after each turn.
CATCH_UP = 1.5


@dataclass(frozen=True, eq=False)
class Plan:
    """``kind``: ``"timed_path"`` (world.json's certificate), ``"movers"`` (a schedule worked out here among
    movers and people), ``"static"`` (the static path) or ``"straight"`` (spawn -> goal, the test hook);
    ``"spacetime"`` (one worked out off the path, worldgen.sim.spacetime);
    ``rows`` the (k, 3) ``t, x, y`` schedule (None for a path); ``waypoints`` (m, 2) the path;
    ``speed`` the schedule's top speed (m/s); ``note`` says what the plan rests on."""

    kind: str
    waypoints: np.ndarray
    speed: float
    rows: Optional[np.ndarray] = None
    note: str = ""


def unrolled(track: np.ndarray, horizon: float) -> np.ndarray:
    """A looping (k, 3) ``t, x, y`` script as a track that does not loop, played until ``horizon`` s: the
    loop's rows again and again, each copy shifted by the script's period (a row that repeats the one before
    at the same time is left out)."""
    track = np.asarray(track, dtype=float).reshape(-1, 3)
    period = float(track[-1, 0])
    if period <= 0.0 or len(track) < 2:
        return track
    copies = max(1, math.ceil(horizon / period) + 1)
    rows = np.vstack([track + np.array([k * period, 0.0, 0.0]) for k in range(copies)])
    keep = np.r_[True, ~((np.diff(rows[:, 0]) == 0.0) & np.all(np.diff(rows[:, 1:], axis=0) == 0.0, axis=1))]
    return rows[keep]


def plan_for(meta: dict, task: dict, speed: float, straight: bool = False,
             scene_of: Optional[Callable[[], Any]] = None) -> Plan:
    """The plan the drive follows in task ``task`` of world.json ``meta`` (see the module's docstring);
    ``speed`` (m/s) the static path's (a schedule runs at the robot's ``max_speed``: world.json's, else its
    documented default, :func:`worldgen.groundtruth.folder.robot_description_of`); ``scene_of`` gives the world's scene
    for a schedule off the path (worldgen.sim.spacetime), which is not tried without it."""
    spawn, goal = task["spawn"], task["goal"]
    if straight:
        return Plan("straight", np.array([spawn[:2], goal[:2]], dtype=float), speed, note="spawn -> goal")
    waypoints = np.asarray(task["path"]["waypoints"], dtype=float)
    top = robot_description_of(meta).max_speed
    movers = meta.get("dynamic_obstacles") or []
    if movers:
        plan = _among_movers(meta, task, waypoints, top, scene_of)
        if plan is not None:
            return plan
    if task.get("timed_path"):
        return Plan("timed_path", waypoints, top, np.asarray(task["timed_path"], dtype=float),
                    "world.json's tasks[].timed_path")
    return Plan("static", waypoints, speed, note="tasks[].path.waypoints" + (
        "; no schedule clears the movers along it" if movers else ""))


def _among_movers(meta: dict, task: dict, waypoints: np.ndarray, top: float, scene_of) -> Optional[Plan]:
    """A schedule along ``waypoints`` clear of every mover's unrolled loop and every person (their tubes
    too), first with :data:`TRACKING` of room, then without; else one off the path (worldgen.sim.spacetime,
    with :data:`TRACKING` of room); None when none exists."""
    from worldgen.people.behaviours import Tube
    from worldgen.people.timed import Limits, timed_path

    horizon = float(task["time_limit"])
    movers = meta.get("dynamic_obstacles") or []
    people = meta.get("people") or []
    tracks = [unrolled(m["trajectory"], horizon) if m.get("loop") else np.asarray(m["trajectory"], dtype=float)
              for m in movers]
    tracks += [np.asarray(p["trajectory"], dtype=float) for p in people]
    radii = [float(m["radius"]) for m in movers] + [float(p["radius"]) for p in people]
    tubes = [Tube(0.0, 0.0)] * len(movers) + [
        Tube(float(p["tube"]["d"]), float(p["tube"]["tau"])) if p.get("tube") else Tube(0.0, 0.0) for p in people]
    robot = robot_description_of(meta)
    # The robot's own limits (its top speed is ``top``): the turns and speed changes it can make.
    limits = Limits(top, robot.turn_rate, robot.acceleration)
    inflation = robot.footprint.inflation
    for room in (TRACKING, 0.0):
        # From the spawn's heading: the robot turns onto the first leg within its turn rate before it sets off.
        found = timed_path(waypoints, tracks, radii, inflation + room, limits, tubes, heading=float(task["spawn"][5]))
        # Past the horizon the unrolled movers stand still: a schedule that ends there proves nothing.
        if found is not None and found.arrival <= horizon:
            return Plan("movers", waypoints, top, found.rows,
                        f"a schedule among {len(movers)} mover(s) and {len(people)} person(s), "
                        f"{room * 100:g} cm of room for the follower, arrival {found.arrival:.2f} s")
    if scene_of is None:
        return None
    from worldgen.scene.doors import open_scene
    from worldgen.scene.footprint import robot_footprints
    from worldgen.sim.spacetime import spacetime_path

    scene = scene_of()
    robot_ = robot_of(meta)
    footprints = robot_footprints(open_scene(scene), robot_)
    for room in (TRACKING, 0.0):
        rows = spacetime_path(footprints, scene.bounds, task["spawn"], task["goal"], float(task["goal_tolerance"]),
                              waypoints, tracks, radii, tubes, inflation, top / CATCH_UP, horizon, room)
        if rows is not None:
            return Plan("spacetime", waypoints, top / CATCH_UP, rows,
                        f"a schedule off the path among {len(movers)} mover(s) and {len(people)} person(s), "
                        f"{room * 100:g} cm of room for the follower, arrival {rows[-1, 0]:.2f} s")
    return None
