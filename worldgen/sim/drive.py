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
from typing import Callable, Optional

import numpy as np

from worldgen.envs.policies import PathFollower, TimedFollower
from worldgen.errors import OutputError, ParameterError
from worldgen.groundtruth.folder import WorldFolder, open_world, robot_of
from worldgen.scene.robot import MAX_SPEED, RobotDescription
from worldgen.sim.ramped import BRAKING, braked, ramped_follower
from worldgen.sim.schedule import Plan, plan_for

__all__ = ["SIMS", "LOOKAHEAD", "CONTROL_PERIOD", "STUCK_SECONDS", "STUCK_MOVE", "STUCK_TURN", "TURN_RATE", "CATCH_UP",
           "TIMED_TURN_RATE", "LAG", "ON_THE_SPOT", "BRAKING", "braked", "RUN_TOPICS", "Outcome", "controller",
           "drive", "record_run", "run_loop", "steps_per_command"]

#: The topics a simulated run is recorded with (write_run's names), the simulator's own pose (``/ground_truth``)
#: among them.
RUN_TOPICS = ("clock", "odom", "tf", "cmd_vel", "ground_truth")
#: Simulators ``worldgen drive --sim`` knows.
SIMS = ("gazebo", "mujoco")
LOOKAHEAD = 0.3        # m along the path ahead of the robot's projection on it
#: s between commands: 20 Hz, nav2 controller_server's default controller_frequency.
CONTROL_PERIOD = 0.05
#: rad/s, the largest turn rate the path follower asks for (the robot's own turn rate where that is lower).
TURN_RATE = 2.0
STUCK_SECONDS = 2.0
STUCK_MOVE = 0.02      # m
#: rad: a robot that turned this much on the spot in STUCK_SECONDS is turning, not stuck (a half turn at the
#: robot's default 1 rad/s takes 3.1 s).
STUCK_TURN = 0.1
#: On a schedule, the follower may go this many times the schedule's top speed to catch up with it, never beyond
#: the robot's own max_speed.
CATCH_UP = 1.5
#: rad/s, the turn rate the timed follower may ask for (the robot's own turn rate where that is lower).
TIMED_TURN_RATE = 8.0
#: m: a robot this close to where its schedule has it is waiting with the schedule, not stuck.
LAG = 0.1
#: m: within this of where the schedule has it a command ahead, the robot stands (and turns to where it goes next).
ON_THE_SPOT = 0.01


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
    #: What the robot followed (worldgen.sim.schedule.Plan's kind: timed_path, static or straight).
    plan: str = "static"
    #: The simulator's own contacts of the robot, (t, name), door leaves left out (MuJoCo; None in Gazebo,
    #: whose bridge reports none), the doors whose opener the robot triggered, and its contacts with leaves.
    contacts: Optional[list] = None
    doors_opened: list = field(default_factory=list)
    door_contacts: Optional[list] = None


def steps_per_command(dt: float) -> int:
    """Physics steps of ``dt`` s between two commands: :data:`CONTROL_PERIOD` rounded to whole steps."""
    return max(1, round(CONTROL_PERIOD / dt))


def controller(plan: Plan, speed: Optional[float] = None, robot: Optional[RobotDescription] = None,
               turn_accel: Optional[float] = None, accel: Optional[float] = None
               ) -> Callable[[float, float, float, float], tuple[float, float]]:
    """``(t, x, y, yaw) -> (v, w)`` for ``plan`` (t the simulator's time, world.json's rows' clock): on a schedule
    (within :data:`CATCH_UP` x its top speed and :data:`TIMED_TURN_RATE`) the environment's
    :class:`~worldgen.envs.policies.TimedFollower`, or :func:`worldgen.sim.ramped.ramped_follower` for a robot whose
    rates ramp; on a path the environment's :class:`~worldgen.envs.policies.PathFollower` (at ``speed``, default
    the plan's); never beyond ``robot``'s max_speed and turn rate where a robot description is given.

    ``turn_accel`` (rad/s^2) and ``accel`` (m/s^2) are how fast the robot's turn rate and speed can change (None:
    at once, as MuJoCo's servos take a twist); given either (Gazebo's DiffDrive), a schedule is followed by the
    ramped follower."""
    v_cap, w_cap = (robot.max_speed, robot.turn_rate) if robot is not None else (math.inf, math.inf)
    if plan.rows is not None:
        v_max, w_max = min(CATCH_UP * plan.speed, v_cap), min(TIMED_TURN_RATE, w_cap)
        if turn_accel is not None or accel is not None:
            return ramped_follower(plan.rows, v_max, w_max, CONTROL_PERIOD, turn_accel, accel)
        timed = TimedFollower(plan.rows, v_max=v_max, w_max=w_max, period=CONTROL_PERIOD)
        rows = plan.rows

        def act(t: float, x: float, y: float, yaw: float) -> tuple[float, float]:
            dx, dy = timed.at(t + CONTROL_PERIOD) - (x, y)
            if math.hypot(dx, dy) > ON_THE_SPOT:
                v, w = timed.action(x, y, yaw, t)
                return float(v), float(w)
            # Where the schedule waits (or the goal): stand, facing where it goes next, so that setting off costs
            # no turn (heading for a point millimetres away would only jitter).
            ahead = rows[(rows[:, 0] > t) & (np.hypot(rows[:, 1] - x, rows[:, 2] - y) > LAG / 2)]
            if not len(ahead):
                return 0.0, 0.0
            err = (math.atan2(ahead[0, 2] - y, ahead[0, 1] - x) - yaw + math.pi) % (2.0 * math.pi) - math.pi
            return 0.0, float(np.clip(err / CONTROL_PERIOD, -w_max, w_max))

        return act
    pursuit = PathFollower(plan.waypoints.tolist(), v_max=min(plan.speed if speed is None else speed, v_cap),
                           w_max=min(TURN_RATE, w_cap), lookahead=LOOKAHEAD)
    # tuple() of a generator is typed tuple[float, ...]; the follower's action is always (v, w)
    return lambda t, x, y, yaw: tuple(float(a) for a in pursuit.action(x, y, yaw))  # type: ignore[return-value]


def run_loop(backend, task: dict, straight: bool = False, speed: float = MAX_SPEED,
             plan: Optional[Plan] = None, robot: Optional[RobotDescription] = None) -> tuple[np.ndarray, np.ndarray, str]:
    """Drive ``task`` in a started-or-not ``backend``: the (n, 4) trajectory, (m, 3) commands and why it ended.

    ``plan`` (default: the static path, or spawn -> goal when ``straight``, at ``speed``) says what to follow;
    ``robot`` (the world's robot description) bounds what the controller asks. On a
    schedule the robot is stuck only when it stands while the schedule has it more than :data:`LAG` away:
    waiting where the schedule waits is no sign of being stuck."""
    spawn, goal = task["spawn"], np.asarray(task["goal"][:2], dtype=float)
    if plan is None:
        plan = Plan("straight" if straight else "static",
                    np.asarray([spawn[:2], goal] if straight else task["path"]["waypoints"], dtype=float), speed)
    act = controller(plan, speed, robot, getattr(backend, "turn_accel", None), getattr(backend, "accel", None))
    give_way = getattr(backend, "give_way", None)
    pose = (spawn[0], spawn[1], spawn[2], spawn[5])
    commands = []
    if getattr(backend, "first_steps", None):
        # Gazebo's first pose comes a command after time 0: the command of that first period is the one for the
        # spawn, where the robot stands at time 0 (standing through it put the robot 0.05 s behind a schedule
        # that sets off at once, 2.5 cm at 0.5 m/s, which a robot at its top speed never makes up).
        first = act(0.0, spawn[0], spawn[1], spawn[5])
        commands.append((0.0, *first))
        t, x, y, yaw = backend.start(pose, first)
    else:
        t, x, y, yaw = backend.start(pose)
    per = steps_per_command(backend.dt)
    limit = float(task["time_limit"])
    rows = [(t, x, y, yaw)]
    still_since, still_at, still_yaw, ended = t, (x, y), yaw, "time_limit"
    while t < limit:
        if math.hypot(x - goal[0], y - goal[1]) < float(task["goal_tolerance"]) / 2:
            ended = "goal"
            break
        if math.hypot(x - still_at[0], y - still_at[1]) > STUCK_MOVE or abs(_turned(yaw, still_yaw)) > STUCK_TURN \
                or _on_schedule(plan, t, x, y):
            still_since, still_at, still_yaw = t, (x, y), yaw
        elif t - still_since > STUCK_SECONDS:
            ended = "stuck"
            break
        # The schedule's clock is the simulator's: its movers and actors, and the judge, play world.json's rows
        # from time 0, and Gazebo's first pose comes a command after it (MuJoCo's at 0).
        v, w = act(t, x, y, yaw)
        if give_way is not None:  # a door opening onto the robot (worldgen.sim.mujoco)
            v = give_way(x, y, yaw, v, per * backend.dt)
        commands.append((t, v, w))
        t, x, y, yaw = backend.step(v, w, per)
        rows.append((t, x, y, yaw))
    commands.append((t, 0.0, 0.0))  # told to stop
    return np.array(rows), np.array(commands), ended


def _turned(yaw: float, before: float) -> float:
    """The turn (rad, in [-pi, pi)) from heading ``before`` to ``yaw``."""
    return (yaw - before + math.pi) % (2.0 * math.pi) - math.pi


def _on_schedule(plan: Plan, t: float, x: float, y: float) -> bool:
    """Whether the robot is within :data:`LAG` of where ``plan``'s schedule has it at ``t`` (False on a path)."""
    if plan.rows is None:
        return False
    r = plan.rows
    return math.hypot(x - float(np.interp(t, r[:, 0], r[:, 1])), y - float(np.interp(t, r[:, 0], r[:, 2]))) < LAG


def _backend(sim: str, world: WorldFolder, gz_release: Optional[str] = None, plan: Optional[Plan] = None):
    meta = world.metadata
    if sim == "mujoco":
        from worldgen.sim.mujoco import MujocoBackend

        people = meta.get("people") or []
        return MujocoBackend(world.file_bytes("mjcf"), meta,
                             _scene_of(world) if any(p.get("behaviour") for p in people) else None)
    from worldgen.export.robot import dimensions, robot_sdf
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
    # The DiffDrive changes its speed at most the robot's acceleration (worldgen.export.robot), its turn rate at
    # that over half the track (a wheel's rim).
    description = world.robot_description
    accel = description.acceleration
    turn_accel = accel / (dimensions(description).wheel_separation / 2.0)
    # The pull doors on the plan's way get a joint controller in a copy of the world (worldgen.sim.gazebo_doors);
    # a build without the system refuses here, before anything starts.
    from worldgen.sim.gazebo_doors import GazeboDoors, plan_points, pulled_doors, world_with_openers

    pulled = pulled_doors(meta.get("doors") or [], plan_points(plan)) if plan is not None else []
    if not pulled:
        backend = GazeboBackend(sdf, robot, dt=dt, first_steps=per, install=install)
    else:
        text, topics = world_with_openers(sdf, pulled, install)
        doors = GazeboDoors(pulled, robot_of(meta).radius, _room_behind(world))
        backend = GazeboBackend(sdf, robot, dt=dt, first_steps=per, install=install, world_text=text,
                                doors=doors, door_topics=tuple(topics))
    backend.turn_accel, backend.accel = turn_accel, accel
    return backend


def _room_behind(world: WorldFolder) -> Callable[[float, float, float, float], bool]:
    """``(t, x, y, yaw) -> bool``: whether the robot can back 3 cm plus a command at the back-off speed with
    nothing in the way, asked of world.json as the judge asks it (walls, obstacles, movers and people; door
    leaves left out): the drive has no ray query in Gazebo (MuJoCo's backend casts rays)."""
    from worldgen.groundtruth.ground import load
    from worldgen.judge.figures import collisions
    from worldgen.sim.mujoco import BACK_OFF

    ground = load(world)

    def room(t: float, x: float, y: float, yaw: float) -> bool:
        back = 0.03 + BACK_OFF * CONTROL_PERIOD
        ends = [(t, x, y, yaw), (t + CONTROL_PERIOD, x - back * math.cos(yaw), y - back * math.sin(yaw), yaw)]
        return not collisions(np.array(ends), ground)

    return room


def drive(world, out, *, sim: str = "mujoco", task: Optional[str] = None, straight: bool = False,
          speed: Optional[float] = None, gz_release: Optional[str] = None) -> Outcome:
    """Drive ``world`` in ``sim``, write the bag into the new folder ``out``/<bag name>, judge it.

    The robot is the world's robot description (``open_world(world).robot_description``: world.json's
    ``robot`` and ``sensors.lidar``), in MuJoCo as in Gazebo; ``speed`` (m/s) is the static path's, at most the
    robot's ``max_speed`` (default: that); a schedule runs at the robot's ``max_speed``.

    ``world`` is a world folder, a :class:`~worldgen.World` or a pack's world (read through
    :func:`worldgen.groundtruth.folder.open_world`); Gazebo loads world.sdf from disk, so there it must
    be written (a World) or in a pack folder (not an archive). ``gz_release`` picks the Gazebo release
    (:func:`worldgen.sim.gazebo_install.locate`: ``WORLDGEN_GAZEBO_SETUP``'s install, else Fortress's)."""
    from worldgen.judge import judge

    if sim not in SIMS:
        raise ParameterError(f"option '--sim' must be one of {', '.join(SIMS)}, got {sim!r}")
    if gz_release is not None and sim != "gazebo":
        raise ParameterError(f"option '--gz-release' {gz_release} names a Gazebo release: add --sim gazebo")
    opened = open_world(world, "argument WORLD")
    meta = opened.metadata
    robot = opened.robot_description
    if speed is None:
        speed = robot.max_speed
    if not (0 < speed <= robot.max_speed):
        raise ParameterError(f"option '--speed' must be in (0, {robot.max_speed:g}] m/s (the world's robot's "
                             f"max_speed), got {speed!r}")
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
    plan = plan_for(meta, chosen, speed, straight)
    wall["plan"] = time.perf_counter() - started
    backend = _backend(sim, opened, gz_release, plan)
    try:
        trajectory, commands, ended = run_loop(backend, chosen, straight, speed, plan, robot)
    finally:
        backend.close()
    wall["drive"] = time.perf_counter() - started - wall["plan"]
    record_run(bag, trajectory, commands, meta, chosen, run_part)
    wall["record"] = time.perf_counter() - started - wall["plan"] - wall["drive"]
    result = judge([bag], world=world)
    wall["judge"] = time.perf_counter() - started - sum(wall.values())
    run = result.report["runs"][0]
    return Outcome(bag, ended, bool(result.passed), _verdict(run, ended), run,
                   float(trajectory[-1, 0] - trajectory[0, 0]), wall, plan.kind,
                   getattr(backend, "contacts", None), list(getattr(backend, "doors_opened", [])),
                   getattr(backend, "door_contacts", None))


def _scene_of(world: WorldFolder):
    """The world's scene: a World's own, else the world regenerated from its recorded generator, seed and
    parameters (it must give the recorded ``content_hash``)."""
    if world.scene is not None:
        return world.scene
    from worldgen.api import generate

    meta = world.metadata
    again = generate(meta["generator"], meta["seed"],
                     allow_infeasible=meta["feasibility"].get("allow_infeasible", False), **meta["params"])
    if again.content_hash != meta["content_hash"]:
        raise ParameterError(f"world {meta['world_id']} does not regenerate with this worldgen version "
                             f"({again.content_hash} != {meta['content_hash']}); its reacting people need its scene")
    return again.scene


def record_run(bag: Path, trajectory, commands, meta: dict, task: dict, run: str) -> Path:
    """The (n, 4) ``t, x, y, yaw`` trajectory and (m, 3) ``t, v, w`` commands of a simulated run as a rosbag2
    folder at ``bag`` naming its world, task and run (the topics :data:`RUN_TOPICS`), complete or absent:
    written aside, then moved in whole. What `worldgen drive` and a campaign's policy episode record."""
    import tempfile

    from worldgen.files import write_folder_atomically
    from worldgen.ros import write_run

    spawn = task["spawn"]
    with tempfile.TemporaryDirectory(prefix="worldgen-run-") as tmp:
        written = write_run(Path(tmp) / bag.name, trajectory, spawn=(spawn[0], spawn[1], spawn[5]), commands=commands,
                            topics=RUN_TOPICS, world_id=meta["world_id"], task=task["id"], run=run)
        blobs = {str(p.relative_to(written)): p.read_bytes() for p in sorted(written.rglob("*")) if p.is_file()}
    return write_folder_atomically(bag.parent, bag.name, blobs)


def _verdict(run: dict, ended: str) -> str:
    return f"{'PASS' if run.get('success') else 'FAIL'}: ended at {ended}; " + json.dumps(
        {k: run[k] for k in sorted(run) if not isinstance(run[k], (list, dict))}, sort_keys=True)
