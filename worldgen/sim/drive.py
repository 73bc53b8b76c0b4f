"""``worldgen drive``: a robot drives a task's reference path in a simulator, the run is recorded as a rosbag2
bag and judged, the loop of a Gazebo + nav2 test closed without ROS.

    >>> import worldgen
    >>> from worldgen.sim.drive import drive
    >>> folder = worldgen.generate("minimal", seed=2).write("worlds", preview=False)
    >>> outcome = drive(folder, "runs", sim="mujoco")            # or sim="gazebo"
    >>> outcome.passed, outcome.ended, outcome.run["collisions"], outcome.bag.name
    (True, 'goal', [], 'minimal-s2-...__task_0__mujoco')

The controller is the environment's reference-path follower (:class:`worldgen.envs.policies.PathFollower`:
pure pursuit with differential-drive kinematics), fed back from the simulator's own pose of the robot
every control step: a forward speed along the heading and a turn rate toward the point :data:`LOOKAHEAD`
further along the path than the robot's projection on it, turning on the spot when far off heading.
It stops at the goal (within half its tolerance), at the time limit, or when the robot has been stuck
(it moved less than :data:`STUCK_MOVE` in :data:`STUCK_SECONDS`). ``straight=True`` drives spawn -> goal in
a straight line instead of the path: a test hook that drives into whatever stands between them.

The run is written with :func:`worldgen.ros.write_run` (mcap, Jazzy definitions): ``/clock``, ``/odom`` and ``/tf``
(the pose since the spawn, no drift), ``/cmd_vel`` (the controller's commands) and ``/ground_truth`` (the
simulator's pose in the map frame, what ``read_run`` reads first), then judged with
:func:`worldgen.judge.judge` against the world's scenario (default criteria: the run meets it).
"""

from __future__ import annotations

import json
import math
import time
from dataclasses import dataclass, field
from pathlib import Path
from typing import Optional

import numpy as np

from worldgen.envs.policies import PathFollower
from worldgen.errors import OutputError, ParameterError
from worldgen.groundtruth.folder import WorldFolder, open_world

__all__ = ["SIMS", "SPEED", "LOOKAHEAD", "CONTROL_PERIOD", "STUCK_SECONDS", "STUCK_MOVE", "TURN_RATE", "Outcome",
           "drive", "run_loop", "steps_per_command"]

#: Simulators ``worldgen drive --sim`` knows.
SIMS = ("gazebo", "mujoco")
SPEED = 0.5            # m/s forward
LOOKAHEAD = 0.3        # m along the path ahead of the robot's projection on it
#: s between commands: 20 Hz, nav2 controller_server's default controller_frequency.
CONTROL_PERIOD = 0.05
#: rad/s, the largest turn rate the controller asks for.
TURN_RATE = 2.0
STUCK_SECONDS = 2.0
STUCK_MOVE = 0.02      # m


@dataclass
class Outcome:
    """One drive: how the loop ended, the bag, the judge's verdict, and the wall time of each phase."""

    bag: Path
    ended: str                      # "goal", "time_limit" or "stuck"
    passed: bool
    verdict: str
    run: dict
    sim_seconds: float
    wall: dict = field(default_factory=dict)


def steps_per_command(dt: float) -> int:
    """Physics steps of ``dt`` s between two commands: :data:`CONTROL_PERIOD` rounded to whole steps."""
    return max(1, round(CONTROL_PERIOD / dt))


def run_loop(backend, task: dict, straight: bool = False, speed: float = SPEED) -> tuple[np.ndarray, np.ndarray, str]:
    """Drive ``task`` in a started-or-not ``backend``: the (n, 4) trajectory, (m, 3) commands and why it ended."""
    spawn, goal = task["spawn"], np.asarray(task["goal"][:2], dtype=float)
    path = [spawn[:2], goal] if straight else task["path"]["waypoints"]
    pursuit = PathFollower(path, v_max=speed, w_max=TURN_RATE, lookahead=LOOKAHEAD)
    t, x, y, yaw = backend.start((spawn[0], spawn[1], spawn[2], spawn[5]))
    per = steps_per_command(backend.dt)
    limit = t + float(task["time_limit"])
    rows, commands = [(t, x, y, yaw)], []
    still_since, still_at, ended = t, (x, y), "time_limit"
    while t < limit:
        if math.hypot(x - goal[0], y - goal[1]) < float(task["goal_tolerance"]) / 2:
            ended = "goal"
            break
        if math.hypot(x - still_at[0], y - still_at[1]) > STUCK_MOVE:
            still_since, still_at = t, (x, y)
        elif t - still_since > STUCK_SECONDS:
            ended = "stuck"
            break
        v, w = (float(a) for a in pursuit.action(x, y, yaw))
        commands.append((t, v, w))
        t, x, y, yaw = backend.step(v, w, per)
        rows.append((t, x, y, yaw))
    commands.append((t, 0.0, 0.0))  # told to stop
    return np.array(rows), np.array(commands), ended


def _backend(sim: str, world: WorldFolder, gz_release: Optional[str] = None):
    meta = world.metadata
    if sim == "mujoco":
        from worldgen.sim.mujoco import MujocoBackend

        return MujocoBackend(world.file_bytes("mjcf"), meta)
    from worldgen.export.robot import robot_sdf
    from worldgen.sim.bridge import GazeboBackend, world_step
    from worldgen.sim.gazebo_install import locate

    sdf = world.file("sdf")
    # The ground truth is published once a command, at its last step: OdometryPublisher publishes when the
    # time since its last message reaches its period, so a period half a step short of a command's steps
    # lands on every command's end (the first at the end of the first), and no other message wakes the bridge.
    dt = world_step(sdf)
    per = steps_per_command(dt)
    # The robot is written for the release that runs it: its plugins' names are that release's.
    install = locate(release=gz_release)
    robot = robot_sdf(meta, gz_release=install.release.name, sensors=False, odom_rate=1.0 / ((per - 0.5) * dt))
    return GazeboBackend(sdf, robot, dt=dt, first_steps=per, install=install)


def drive(world, out, *, sim: str = "mujoco", task: Optional[str] = None, straight: bool = False,
          speed: float = SPEED, gz_release: Optional[str] = None) -> Outcome:
    """Drive ``world`` in ``sim``, write the bag into the new folder ``out``/<bag name>, judge it.

    ``world`` is a world folder, a :class:`~worldgen.World` or a pack's world (read through
    :func:`worldgen.groundtruth.folder.open_world`); Gazebo loads world.sdf from disk, so there it must
    be written (a World) or in a pack folder (not an archive). ``gz_release`` picks the Gazebo release
    (:func:`worldgen.sim.gazebo_install.locate`: ``WORLDGEN_GAZEBO_SETUP``'s install, else Fortress's)."""
    from worldgen.judge import judge

    if sim not in SIMS:
        raise ParameterError(f"option '--sim' must be one of {', '.join(SIMS)}, got {sim!r}")
    if gz_release is not None and sim != "gazebo":
        raise ParameterError(f"option '--gz-release' {gz_release} names a Gazebo release: add --sim gazebo")
    if not (0 < speed <= 2.0):
        raise ParameterError(f"option '--speed' must be in (0, 2] m/s, got {speed!r}")
    opened = open_world(world, "argument WORLD")
    meta = opened.metadata
    chosen = opened.task(task, "option '--task'")
    # The bag is named as the judge names the run, <world_id>__<task>__<run>; the run part names only what
    # differs between drives of one task (the simulator, the straight hook), never the world again.
    run_part = f"{sim}{'-straight' if straight else ''}"
    bag = Path(out) / f"{meta['world_id']}__{chosen['id']}__{run_part}"
    if bag.exists():
        raise ParameterError(f"option '--out': '{bag}' exists already; a run is written into a new folder")
    if Path(out).exists() and not Path(out).is_dir():
        raise OutputError(f"output folder '{out}' is not a folder")
    wall = {}
    started = time.perf_counter()
    backend = _backend(sim, opened, gz_release)
    try:
        trajectory, commands, ended = run_loop(backend, chosen, straight, speed)
    finally:
        backend.close()
    wall["drive"] = time.perf_counter() - started
    _write_bag(bag, trajectory, commands, meta, chosen, run_part)
    wall["record"] = time.perf_counter() - started - wall["drive"]
    result = judge([bag], world=world)
    wall["judge"] = time.perf_counter() - started - wall["drive"] - wall["record"]
    run = result.report["runs"][0]
    return Outcome(bag, ended, bool(result.passed), _verdict(run, ended), run,
                   float(trajectory[-1, 0] - trajectory[0, 0]), wall)


def _write_bag(bag: Path, trajectory, commands, meta: dict, task: dict, run: str) -> None:
    """The run as a rosbag2 folder at ``bag``, complete or absent: written aside, then moved in whole."""
    import tempfile

    from worldgen.files import write_folder_atomically
    from worldgen.ros import write_run

    spawn = task["spawn"]
    with tempfile.TemporaryDirectory(prefix="worldgen-drive-") as tmp:
        write_run(Path(tmp) / bag.name, trajectory, spawn=(spawn[0], spawn[1], spawn[5]), commands=commands,
                  topics=("clock", "odom", "tf", "cmd_vel", "ground_truth"), world_id=meta["world_id"],
                  task=task["id"], run=run)
        blobs = {str(p.relative_to(Path(tmp) / bag.name)): p.read_bytes()
                 for p in sorted((Path(tmp) / bag.name).rglob("*")) if p.is_file()}
    write_folder_atomically(bag.parent, bag.name, blobs)


def _verdict(run: dict, ended: str) -> str:
    return f"{'PASS' if run.get('success') else 'FAIL'}: ended at {ended}; " + json.dumps(
        {k: run[k] for k in sorted(run) if not isinstance(run[k], (list, dict))}, sort_keys=True)
