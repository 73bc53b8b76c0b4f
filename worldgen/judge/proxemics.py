"""The social figures users compare across crowd simulators, split by how the people behave.

One run (``t, x, y[, yaw]`` rows) among a world's people (world.json ``people[]``; in the environment,
the trajectories the reacting people actually walked) gives, per behaviour (``people[].behaviour``,
absent: ``impassive``) and over everyone (``all``):

- ``intimate`` / ``personal`` / ``social`` (s): how long the nearest person's gap (centre distance less
  both radii, as HuNavSim's evaluator measures it) was under 0.45 m, in [0.45, 1.2) m, in [1.2, 3.6) m:
  Hall's proximity zones (E. T. Hall, *The Hidden Dimension*, 1966), the bands and the gap of
  HuNavSim's ``intimate/personal/social_space_intrusions`` (which give a share of samples; the share
  of the run is ``seconds / duration``); the bands are settable (``zones``);
- ``robot_on_person`` / ``person_on_robot``: contacts (the gap first below 0) split by who moved into
  whom, HuNavSim's two collision counts; here (ours) whoever closed the gap faster over the sample
  before the contact, the robot's velocity or the person's along the line between their centres;
- ``min_tube_gap`` (m, reacting people only): the least gap between the robot and the person's whole
  tube (recorded positions within ``tau`` of the time, widened by ``d``): at or above 0, the robot kept
  clear of anywhere the person could have reacted to be; how a bag is judged when only the recorded
  trajectories are known.

And of the robot alone: ``time_not_moving`` (s, HuNavSim's: speed under 0.01 m/s and turning under
0.02 rad/s), ``path_irregularity`` (rad/m: the turning beyond the one turn to face the goal, per metre
travelled; S. Guzzi et al. 2013, as listed by Y. Gao and C.-M. Huang, *Evaluation of socially-aware
robot navigation*, Frontiers in Robotics and AI 8, 2022) and ``path_efficiency_optimal`` (the exact
shortest path's length over the length travelled, in (0, 1]; SocNavBench's path efficiency, against
worldgen's exact optimum rather than a planner's).
"""

from __future__ import annotations

import math
from typing import Optional, Sequence

import numpy as np

from worldgen.groundtruth.ground import as_trajectory, load

__all__ = ["ZONES", "STILL_SPEED", "STILL_TURN", "social_split"]

#: Hall's zones as HuNavSim bands the gap (m): intimate below 0.45, personal below 1.2, social below 3.6.
ZONES = (0.45, 1.2, 3.6)
#: HuNavSim's "not moving": slower than this (m/s) and turning slower than STILL_TURN (rad/s).
STILL_SPEED, STILL_TURN = 0.01, 0.02
_DT = 0.05


def social_split(trajectory, world, task: Optional[str] = None, zones: Sequence[float] = ZONES) -> dict:
    """The figures of the module's docstring for one run: ``{"by_behaviour": {name: {...}}, "time_not_moving",
    "path_irregularity", "path_efficiency_optimal"}``; ``by_behaviour`` is {} without people."""
    from worldgen.scene.motion import positions_at

    ground = load(world)
    raw = np.asarray(trajectory, dtype=float)
    traj = as_trajectory(trajectory)
    out: dict = {**_robot_figures(raw, traj, ground.task(task)), "by_behaviour": {}}
    people = ground.meta.get("people") or []
    if not people or len(traj) < 1:
        return out
    t0, t1 = float(traj[0, 0]), float(traj[-1, 0])
    times = np.union1d(traj[:, 0], np.arange(t0, t1, _DT)) if t1 > t0 else traj[:1, 0]
    pts = np.c_[times, np.interp(times, traj[:, 0], traj[:, 1]), np.interp(times, traj[:, 0], traj[:, 2])]
    tracks = [np.asarray(p["trajectory"], dtype=float) for p in people]
    centres = positions_at(tracks, [False] * len(tracks), times)  # (samples, people, 2)
    radii = np.array([float(p["radius"]) for p in people])
    gap = np.hypot(centres[..., 0] - pts[:, 1:2], centres[..., 1] - pts[:, 2:3]) - radii - ground.robot.radius
    kinds = [str(p.get("behaviour", "impassive")) for p in people]
    step = np.r_[np.diff(times), 0.0]
    hits = _contacts(pts, centres, gap)
    tube = _tube_gaps(pts, people, gap, ground.robot.radius)
    for name in sorted(set(kinds)) + ["all"]:
        cols = [j for j, k in enumerate(kinds) if name in (k, "all")]
        near = np.maximum(gap[:, cols].min(axis=1), 0.0)
        figures: dict[str, Optional[float]] = {band: float(step[(near >= lo) & (near < hi)].sum())
                   for band, lo, hi in zip(("intimate", "personal", "social"), (-1.0, *zones[:2]), zones)}
        figures["robot_on_person"] = sum(1 for j, robot in hits if j in cols and robot)
        figures["person_on_robot"] = sum(1 for j, robot in hits if j in cols and not robot)
        gaps = [tube[j] for j in cols if tube[j] is not None]
        figures["min_tube_gap"] = min(gaps) if gaps else None
        out["by_behaviour"][name] = figures
    return out


def _contacts(pts: np.ndarray, centres: np.ndarray, gap: np.ndarray) -> list[tuple[int, bool]]:
    """(person, the robot moved into the person) for every contact that begins in the run."""
    touching = gap < 0.0
    start = touching & ~np.r_[np.zeros((1, gap.shape[1]), dtype=bool), touching[:-1]]
    found = []
    for k, j in zip(*np.nonzero(start)):
        b = max(int(k) - 1, 0)
        dt = max(float(pts[k, 0] - pts[b, 0]), 1e-12)
        line = centres[k, j] - pts[k, 1:]
        line = line / max(float(np.hypot(*line)), 1e-12)
        robot = float(np.dot(pts[k, 1:] - pts[b, 1:], line)) / dt  # toward the person
        person = -float(np.dot(centres[k, j] - centres[b, j], line)) / dt  # toward the robot
        found.append((int(j), robot >= person))
    return found


def _tube_gaps(pts: np.ndarray, people: list, gap: np.ndarray, robot_radius: float) -> list:
    """Per person: the least gap to its tube (its ``tube`` of world.json), or None without one."""
    from worldgen.people.behaviours import tube_distance

    out: list = []
    for j, p in enumerate(people):
        tube = p.get("tube")
        if tube is None:
            out.append(None)
            continue
        near = np.flatnonzero(gap[:, j] < float(tube["d"]) + 2.0 * float(tube["tau"]) * 3.0 + 1.0)
        if not len(near):
            out.append(float(gap[:, j].min()) - float(tube["d"]))
            continue
        dist = tube_distance(pts[near, 1:], pts[near, 0], np.asarray(p.get("recorded_trajectory", p["trajectory"]),
                                                                  dtype=float), float(tube["tau"]))
        out.append(float((dist - float(p["radius"]) - robot_radius - float(tube["d"])).min()))
    return out


def _robot_figures(raw: np.ndarray, traj: np.ndarray, task: dict) -> dict:
    dt = np.diff(traj[:, 0])
    step = np.hypot(*np.diff(traj[:, 1:3], axis=0).T)
    travelled = float(step.sum())
    heading = raw[:, 3] if raw.ndim == 2 and raw.shape[1] == 4 else _motion_heading(traj, step)
    turn = np.abs((np.diff(heading) + math.pi) % (2 * math.pi) - math.pi)
    moving = dt > 0
    with np.errstate(divide="ignore", invalid="ignore"):
        still = moving & (step / np.where(moving, dt, 1.0) < STILL_SPEED) & (turn / np.where(moving, dt, 1.0) < STILL_TURN)
    goal = np.asarray(task["goal"][:2], dtype=float)
    face = math.atan2(goal[1] - traj[0, 2], goal[0] - traj[0, 1])
    needed = abs((face - float(heading[0]) + math.pi) % (2 * math.pi) - math.pi) if len(heading) else 0.0
    optimum = float(task["path"]["length"]) if task.get("path") else None
    return {"time_not_moving": float(dt[still].sum()),
            "path_irregularity": max(float(turn.sum()) - needed, 0.0) / travelled if travelled > 0 else 0.0,
            "path_efficiency_optimal": (min(optimum / travelled, 1.0) if travelled > 0 else None)
            if optimum is not None else None}


def _motion_heading(traj: np.ndarray, step: np.ndarray) -> np.ndarray:
    """The direction of travel at each row (the last move's, held while standing)."""
    d = np.diff(traj[:, 1:3], axis=0)
    heading = np.zeros(len(traj))
    last = 0.0
    for k in range(len(d)):
        if step[k] > 1e-9:
            last = math.atan2(d[k, 1], d[k, 0])
        heading[k + 1] = last
    heading[0] = heading[1] if len(heading) > 1 else 0.0
    return heading
