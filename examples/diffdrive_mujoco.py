"""A differential-drive robot follows the reference path in 20 cluttered worlds; each run is recorded as a
ROS 2 bag and the bags are judged by ``worldgen judge``: the loop of a Gazebo + nav2 test, closed without ROS.

    .venv/bin/python examples/diffdrive_mujoco.py [OUT_DIR [N_WORLDS]]

Each world's MJCF gets a robot added to it: a cylinder the size of world.json's
``robot`` footprint on a planar base (slide x, slide y, hinge yaw) driven by
velocity actuators. The controller has differential-drive (unicycle)
kinematics: it commands a forward speed ``v`` along the robot's heading and a
turn rate ``w``, never a sideways motion, which the planar joints then execute.
It is a pure-pursuit follower of the task's reference path from world.json.

The robot's geom has no contacts in MuJoCo (contype 0): a collision is judged by
the oracles from the recorded trajectory with FCL, exactly as for a run recorded
from any other simulator.

Each run is written as a real rosbag2 bag (mcap storage, Jazzy message definitions;
needs the ``ros`` extra) with the topics a Gazebo run records: ``/clock``, ``/odom``
zeroed at the spawn, ``/tf`` (map -> odom, odom -> base_footprint) and the
controller's ``/cmd_vel`` at its 50 Hz, into OUT_DIR/bags/, the worlds into
OUT_DIR/worlds/. The bags are then judged as ``worldgen judge OUT_DIR/bags/*
--pack OUT_DIR/worlds --criteria criteria.yaml --out OUT_DIR/report`` would judge
them (each bag names its world in its metadata) against the acceptance criteria
below and each world's scenario.yaml: the report folder holds report.json,
report.csv, report.md and a picture per run. The exit status is 1 when a criterion fails.

With ``--people`` (``examples/diffdrive_mujoco.py OUT_DIR N_WORLDS --people``) each world also has four
people who react to the robot (regular, surprised, scared, curious; docs/people.md), and the robot drives
the task's timed path instead: every control step the robot's pose and velocity feed the people's
reactions (``worldgen.people.react.Reactions``), and their mocap bodies follow, inside their tubes, at every
physics step. The people as they actually walked are written beside each bag
(OUT_DIR/people/<bag>.json, ``{name: [[t, x, y], ...]}``); the bag is judged against world.json's
recorded trajectories plus each tube (the report's ``social`` figures: ``min_tube_gap``), and the run is
checked against the people as they walked: no contact.
"""

from __future__ import annotations

import math
import sys
import tempfile
import time
from pathlib import Path

import mujoco
import numpy as np
from lxml import etree

import worldgen
from worldgen.export.xml import safe_parser
from worldgen.judge import judge, write_report
from worldgen.ros import write_run

CRITERIA = """
navigation:
  success_rate: 0.95        # at least 19 of 20 runs reach the goal in time without a collision
  path_efficiency: 1.25     # on average at most 25 % longer than the reference path
safety:
  collision_tolerance: 0
  obstacle_clearance: 0.02  # m between the footprint and any collider (the path keeps 0.05)
  max_velocity: 0.6         # m/s
performance:
  avg_time_to_goal: 40.0    # s
"""

SPEED = 0.5        # m/s forward
LOOKAHEAD = 0.2    # m along the path ahead of the robot's projection on it
CONTROL_EVERY = 10  # physics steps per control step (0.02 s at MuJoCo's 0.002 s)
RECORD_EVERY = 25   # physics steps per recorded sample (0.05 s)


def robot_xml(robot: dict, spawn) -> str:
    r, h = robot["radius"], robot["height"]
    x, y, yaw = spawn[0], spawn[1], spawn[5]
    return f"""
    <body name="robot" pos="0 0 {h / 2}">
      <joint name="robot_x" type="slide" axis="1 0 0" ref="0"/>
      <joint name="robot_y" type="slide" axis="0 1 0"/>
      <joint name="robot_yaw" type="hinge" axis="0 0 1"/>
      <geom name="robot_base" type="cylinder" size="{r} {h / 2}" mass="10" contype="0" conaffinity="0" rgba="0.9 0.4 0.1 1"/>
      <site name="robot_front" pos="{r} 0 0" size="0.02"/>
    </body>""", (x, y, yaw)


def with_robot(mjcf: str, meta: dict):
    """The world's MJCF with the robot added, and the initial qpos of its three joints."""
    root = etree.fromstring(mjcf.encode(), safe_parser())
    body, q0 = robot_xml(meta["robot"], meta["tasks"][0]["spawn"])
    root.find("worldbody").append(etree.fromstring(body, safe_parser()))
    actuators = root.find("actuator")
    if actuators is None:
        actuators = etree.SubElement(root, "actuator")
    for joint, kv in (("robot_x", 400.0), ("robot_y", 400.0), ("robot_yaw", 40.0)):
        etree.SubElement(actuators, "velocity", joint=joint, kv=str(kv), name=f"{joint}_vel")
    return etree.tostring(root, encoding="unicode"), q0


def lookahead_point(path: np.ndarray, xy: np.ndarray, progress: int) -> tuple[np.ndarray, int]:
    """The point LOOKAHEAD further along the path than xy's projection on segment ``progress`` (or later)."""
    while True:
        a, b = path[progress], path[progress + 1]
        seg = b - a
        s = float(np.clip(np.dot(xy - a, seg) / max(np.dot(seg, seg), 1e-12), 0.0, 1.0))
        if s < 1.0 or progress == len(path) - 2:
            break
        progress += 1  # past the end of this segment: follow the next one
    along = s * float(np.hypot(*seg)) + LOOKAHEAD
    for k in range(progress, len(path) - 1):
        length = float(np.hypot(*(path[k + 1] - path[k])))
        if along <= length:
            return path[k] + (path[k + 1] - path[k]) * (along / max(length, 1e-12)), progress
        along -= length
    return path[-1], progress


def pursue(path: np.ndarray, xy: np.ndarray, yaw: float, progress: int) -> tuple[float, float, int]:
    """Pure pursuit: (v, w) toward the path point LOOKAHEAD ahead of the robot's projection on the path."""
    target, progress = lookahead_point(path, xy, progress)
    dx, dy = target - xy
    err = (math.atan2(dy, dx) - yaw + math.pi) % (2 * math.pi) - math.pi
    w = 4.0 * err
    # Turn on the spot when far off heading (a differential drive can): the robot stays on the path.
    v = 0.0 if abs(err) > 0.3 else SPEED * math.cos(err) * min(1.0, float(np.hypot(dx, dy)) / LOOKAHEAD)
    return v, w, progress


def placed_robot(world):
    """MuJoCo's model and data of ``world`` with the robot at its first task's spawn, and the robot's joints."""
    xml, (x0, y0, yaw0) = with_robot(world.to_mjcf(), world.metadata)
    model = mujoco.MjModel.from_xml_string(xml)
    data = mujoco.MjData(model)
    joints = tuple(model.joint(n).qposadr[0] for n in ("robot_x", "robot_y", "robot_yaw"))
    data.qpos[list(joints)] = (x0, y0, yaw0)
    return model, data, joints


def drive(world) -> tuple[np.ndarray, np.ndarray]:
    """Simulate one run; return the recorded (n, 4) ``t, x, y, yaw`` trajectory and the (m, 3) ``t, v, w`` commands."""
    task = world.metadata["tasks"][0]
    model, data, (jx, jy, jyaw) = placed_robot(world)
    mujoco.mj_forward(model, data)
    path = np.asarray(task["path"]["waypoints"], dtype=float)
    goal = np.asarray(task["goal"][:2])
    steps = int(task["time_limit"] / model.opt.timestep)
    progress, rows, commands = 0, [], []
    for k in range(steps):
        xy = np.array([data.qpos[jx], data.qpos[jy]])
        yaw = float(data.qpos[jyaw])
        if k % RECORD_EVERY == 0:
            rows.append((data.time, xy[0], xy[1], yaw))
            if np.hypot(*(xy - goal)) < task["goal_tolerance"] / 2:
                break
        if k % CONTROL_EVERY == 0:
            v, w, progress = pursue(path, xy, yaw, progress)
            commands.append((data.time, v, w))
            data.ctrl[:] = (v * math.cos(yaw), v * math.sin(yaw), w)  # unicycle: no sideways motion
        mujoco.mj_step(model, data)
    commands.append((data.time, 0.0, 0.0))  # the robot is told to stop at the goal
    return np.array(rows), np.array(commands)


CATCH_UP = 0.58  # m/s, under the criteria's max_velocity
PEOPLE = {"n_people": 4, "people_duration": 20.0, "people_behaviour": "regular,surprised,scared,curious"}


def reactions_of(world):
    """The reacting people of an in-memory world, kept off its walls, and their mocap body ids."""
    from worldgen.feasibility.geometry import Obstacles2D
    from worldgen.people.behaviours import Tube
    from worldgen.people.places import PERSON_HEIGHT
    from worldgen.people.react import Reactions, wall_gap_of
    from worldgen.scene.footprint import scene_footprints

    people = [p for p in world.metadata.get("people") or [] if p.get("behaviour")]
    gap = wall_gap_of(Obstacles2D.from_footprints(scene_footprints(world.scene, PERSON_HEIGHT)), world.scene.bounds)
    reactions = Reactions([np.asarray(p["trajectory"], dtype=float) for p in people], [p["radius"] for p in people],
                          [p["behaviour"] for p in people], [Tube(**p["tube"]) for p in people], gap)
    return reactions, [p["name"] for p in people]


def drive_among_people(world) -> tuple[np.ndarray, np.ndarray, dict]:
    """One run along the timed path among reacting people: (trajectory, commands, {name: walked rows})."""
    from worldgen.scene.motion import drive_mocap

    meta = world.metadata
    task = meta["tasks"][0]
    model, data, (jx, jy, jyaw) = placed_robot(world)
    x0, y0 = data.qpos[jx], data.qpos[jy]
    reactions, names = reactions_of(world)
    mocap = [int(model.body(n).mocapid[0]) for n in names]
    timed = np.asarray(task["timed_path"], dtype=float)
    period = CONTROL_EVERY * model.opt.timestep
    rows, commands, walked = [], [], {n: [] for n in names}
    last = np.array([x0, y0])
    for k in range(int((task["arrival_time"] + 2.0) / model.opt.timestep)):
        xy, yaw = np.array([data.qpos[jx], data.qpos[jy]]), float(data.qpos[jyaw])
        if k % RECORD_EVERY == 0:
            rows.append((data.time, xy[0], xy[1], yaw))
        if k % CONTROL_EVERY == 0:  # the robot's pose feeds the people; then the timed path's next point
            reactions.step(period, xy, (xy - last) / period, meta["robot"]["radius"])
            last = xy
            for name, (px, py) in zip(names, reactions.p):
                walked[name].append([round(reactions.t, 6), float(px), float(py)])
            goal = np.array([np.interp(data.time + period, timed[:, 0], timed[:, c]) for c in (1, 2)])
            dx, dy = goal - xy
            err = (math.atan2(dy, dx) - yaw + math.pi) % (2 * math.pi) - math.pi if np.hypot(dx, dy) > 1e-6 else 0.0
            # The timed path's speed (0.5 m/s) and a little to catch up after turning a corner on the spot.
            v = 0.0 if abs(err) > 0.3 else min(CATCH_UP, float(np.hypot(dx, dy)) / period * math.cos(err))
            commands.append((data.time, v, err / period))
            data.ctrl[:] = (v * math.cos(yaw), v * math.sin(yaw), err / period)
        drive_mocap(model, data, meta, data.time)  # movers and impassive people on their tracks
        here = reactions.positions([(k % CONTROL_EVERY) / CONTROL_EVERY])[0]
        data.mocap_pos[mocap, :2] = here
        mujoco.mj_step(model, data)
    commands.append((data.time, 0.0, 0.0))
    return np.array(rows), np.array(commands), walked


def people_main(out_dir: str, n_worlds: int) -> int:
    """The --people run: drive, record the bags and the people as they walked, judge, check for contacts."""
    import json

    from worldgen.groundtruth.ground import Ground
    from worldgen.judge.proxemics import social_split

    out = Path(out_dir)
    bags, touched = [], 0
    for seed in range(n_worlds):
        world = worldgen.generate("cluttered", seed=seed, size=[10, 10], n_obstacles=8, **PEOPLE)
        world.write(out / "worlds", preview=False)
        trajectory, commands, walked = drive_among_people(world)
        task = world.metadata["tasks"][0]
        spawn = task["spawn"]
        bag = out / "bags" / f"{world.world_id}-{task['id']}-run0"
        write_run(bag, trajectory, commands=commands, spawn=(spawn[0], spawn[1], spawn[5]), storage="mcap",
                  distro="jazzy", world_id=world.world_id, task=task["id"], run=bag.name)
        (out / "people").mkdir(parents=True, exist_ok=True)
        (out / "people" / f"{bag.name}.json").write_text(json.dumps(walked))
        as_walked = dict(world.metadata, people=[dict(p, trajectory=walked.get(p["name"], p["trajectory"]),
                                                      recorded_trajectory=p["trajectory"])
                                                 for p in world.metadata["people"]])
        split = social_split(trajectory, Ground(as_walked, scene=world.scene))["by_behaviour"]["all"]
        touched += split["robot_on_person"] + split["person_on_robot"]
        print(f"{bag.name}: intimate {split['intimate']:.2f} s, personal {split['personal']:.2f} s, "
              f"contacts {split['robot_on_person'] + split['person_on_robot']}, "
              f"least gap to a tube {split['min_tube_gap']:.3f} m")
        bags.append(bag)
    result = judge(bags, CRITERIA, pack=out / "worlds")
    write_report(result, out / "report")
    print(f"{n_worlds} runs among reacting people: {touched} contacts; judged: {'PASS' if result.passed else 'FAIL'}")
    return 0 if result.passed and touched == 0 else 1


def main(out_dir: str, n_worlds: int = 20) -> int:
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    start = time.perf_counter()
    bags = []
    for seed in range(n_worlds):
        world = worldgen.generate("cluttered", seed=seed, size=[10, 10], n_obstacles=15)
        world.write(out / "worlds", preview=False)  # the report draws each run over map.pgm
        trajectory, commands = drive(world)
        task = world.metadata["tasks"][0]
        spawn = task["spawn"]
        bag = out / "bags" / f"{world.world_id}-{task['id']}-run0"
        write_run(bag, trajectory, commands=commands, spawn=(spawn[0], spawn[1], spawn[5]), storage="mcap",
                  distro="jazzy", world_id=world.world_id, task=task["id"], run=bag.name)
        bags.append(bag)
    result = judge(bags, CRITERIA, pack=out / "worlds")
    write_report(result, out / "report")
    report = result.report
    for c in report["criteria"]:
        measured = "n/a" if c["measured"] is None else f"{c['measured']:.6g}"
        print(f"{c['section'] + '.' + c['key']:<30} {c['op']} {c['required']!s:<8} {measured:<10} "
              f"{'PASS' if c['passed'] else 'FAIL'}")
    for line in report["failures"]:
        print("FAILED", line)
    s = report["summary"]
    print(f"{s['runs']} runs, {s['successes']} succeeded: {'PASS' if result.passed else 'FAIL'}")
    print(f"{n_worlds} worlds driven, recorded as bags and judged in {time.perf_counter() - start:.1f} s; "
          f"report in {out / 'report'}")
    return 0 if result.passed else 1


if __name__ == "__main__":
    args = [a for a in sys.argv[1:] if a != "--people"]
    run_main = people_main if "--people" in sys.argv[1:] else main
    sys.exit(run_main(args[0] if args else tempfile.mkdtemp(prefix="worldgen-diffdrive-"),
                      int(args[1]) if len(args) > 1 else 20))
