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


def drive(world) -> tuple[np.ndarray, np.ndarray]:
    """Simulate one run; return the recorded (n, 4) ``t, x, y, yaw`` trajectory and the (m, 3) ``t, v, w`` commands."""
    meta = world.metadata
    task = meta["tasks"][0]
    xml, (x0, y0, yaw0) = with_robot(world.to_mjcf(), meta)
    model = mujoco.MjModel.from_xml_string(xml)
    data = mujoco.MjData(model)
    jx, jy, jyaw = (model.joint(n).qposadr[0] for n in ("robot_x", "robot_y", "robot_yaw"))
    data.qpos[[jx, jy, jyaw]] = (x0, y0, yaw0)
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
    sys.exit(main(sys.argv[1] if len(sys.argv) > 1 else tempfile.mkdtemp(prefix="worldgen-diffdrive-"),
                  int(sys.argv[2]) if len(sys.argv) > 2 else 20))
