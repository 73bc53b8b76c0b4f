"""The robot: a differential-drive body added to a world's MJCF, compiled into MuJoCo.

The body is the world's robot description (:class:`~worldgen.scene.robot.RobotDescription`, read by
:func:`worldgen.groundtruth.folder.robot_description_of`: the same numbers robot.sdf and robot.urdf
carry): a cylinder of the footprint's ``radius`` whose top is at its ``height``, of the
description's mass, on a planar base of three joints (slide x, slide y, hinge yaw about z),
starting at the task's spawn (x, y, yaw; the joints' values are the world pose, so
``data.qpos`` reads it directly). Its bottom is lifted
:data:`FLOOR_GAP` off the floor, so it never rests on it: every contact it makes
is with something else.

Three velocity servos act through a site at the body's centre, in the body's
own frame (a site transmission): forward speed ``v`` along the heading, turn
rate ``w`` about z (their ranges the robot's ``max_speed`` and ``turn_rate`` unless the caller
overrides them: :func:`servo_limits`), and a lateral servo held at 0, so the base moves as a
unicycle (differential drive) and never sideways. The servos are stiff (time
constant :data:`TIME_CONSTANT`) and integrated implicitly by MuJoCo's
``implicitfast``, so the base follows the commanded (v, w) within a few
milliseconds, while contacts with walls, boxes and movers are real MuJoCo
contacts that stop it.

The body is appended to the world's MJCF as an lxml tree (the exporter's own
tree for a generated world, a pack's world.mjcf.xml parsed with worldgen's safe
parser), which MuJoCo then compiles once (``MjModel.from_xml_string``). The
other way, ``mujoco.MjSpec`` (MJCF text parsed by MuJoCo, the body added through
its API, compiled), costs the same: benchmarks/bench_env.py measures both on the
same ``drl_arena`` worlds, alternating which goes first: 1.5 to 1.6 ms a world
each (MJCF, robot, compile and MjData; medians over 100 worlds, one core), with
no consistent winner between runs. The lxml way needs no MjSpec API, which has
changed between MuJoCo 3 releases.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any, Optional, Sequence

import numpy as np
from lxml import etree

from worldgen.errors import SceneError
from worldgen.floats import fmt, fmt_seq
from worldgen.scene.robot import BODY_MASS, RobotDescription

__all__ = ["ROBOT", "FLOOR_GAP", "TIME_CONSTANT", "ROBOT_MASS", "RobotModel", "add_robot", "servo_limits",
           "compile_world"]

#: Name of the robot's body and geom in the compiled model (prefix of its joints, site and actuators).
ROBOT = "nav_robot"
#: Gap (m) between the floor and the robot's bottom: the base never touches the floor.
FLOOR_GAP = 0.005
#: Time constant (s) of the velocity servos: how fast the base reaches a commanded (v, w).
TIME_CONSTANT = 0.01
#: Mass (kg) of the robot's body (a uniform cylinder): the description's default, worldgen.scene.robot.BODY_MASS
#: (this name is kept for the code that imported it from here).
ROBOT_MASS = BODY_MASS
_RGBA = (0.95, 0.45, 0.1, 1.0)


@dataclass(frozen=True, eq=False)
class RobotModel:
    """A compiled world with the robot in it, and the indices the environment reads every step.

    ``qpos`` / ``qvel``: the addresses of the x, y, yaw joints; ``ctrl``: the
    forward, lateral and turn actuators; ``floor``: geom ids contacts with which
    are ignored; ``mocap``: the mocap index of each mover, in world.json order.
    """

    model: Any  # mujoco.MjModel and MjData: mujoco ships no type information
    data: Any
    body: int
    geom: int
    qpos: np.ndarray
    qvel: np.ndarray
    ctrl: np.ndarray
    floor: frozenset
    mocap: np.ndarray

    def pose(self) -> tuple[float, float, float]:
        """(x, y, yaw) of the robot now."""
        q = self.data.qpos
        return float(q[self.qpos[0]]), float(q[self.qpos[1]]), float(q[self.qpos[2]])


def servo_limits(robot: RobotDescription, v_range: Optional[Sequence[float]] = None,
                 w_max: Optional[float] = None) -> tuple[tuple[float, float], float]:
    """(``v_range``, ``w_max``) of the servos for ``robot``: its own limits, forward from standstill to
    ``max_speed`` (m/s) and turns up to ``turn_rate`` (rad/s), each replaced by the caller's where given."""
    v = (0.0, robot.max_speed) if v_range is None else (float(v_range[0]), float(v_range[1]))
    return v, robot.turn_rate if w_max is None else float(w_max)


def add_robot(root, radius: float, height: float, v_range: tuple[float, float], w_max: float,
              mass: float = BODY_MASS) -> None:
    """Add the robot's body, site and servos to an MJCF ``<mujoco>`` lxml element (changed in place).

    ``v_range`` (m/s) and ``w_max`` (rad/s) become the servos' control ranges (:func:`servo_limits` gives
    a description's); ``mass`` (kg) is the body's.
    """
    if root.find(f".//*[@name='{ROBOT}']") is not None:
        raise SceneError(f"the world already has an element named {ROBOT!r}; the environment's robot needs that name")
    if height <= FLOOR_GAP:
        raise SceneError(f"robot height {height!r} m must exceed the floor gap {FLOOR_GAP} m")
    half = (height - FLOOR_GAP) / 2.0
    body = etree.SubElement(root.find("worldbody"), "body", name=ROBOT, pos=fmt_seq((0.0, 0.0, FLOOR_GAP + half)))
    for axis, kind, suffix in (("1 0 0", "slide", "x"), ("0 1 0", "slide", "y"), ("0 0 1", "hinge", "yaw")):
        etree.SubElement(body, "joint", name=f"{ROBOT}_{suffix}", type=kind, axis=axis, limited="false")
    etree.SubElement(body, "geom", name=ROBOT, type="cylinder", size=fmt_seq((radius, half)), mass=fmt(mass),
                     rgba=fmt_seq(_RGBA))
    etree.SubElement(body, "site", name=f"{ROBOT}_base", pos="0 0 0")
    actuators = root.find("actuator")
    if actuators is None:
        actuators = etree.SubElement(root, "actuator")
    kv_linear = mass / TIME_CONSTANT
    kv_turn = mass * radius * radius / 2.0 / TIME_CONSTANT  # the cylinder's inertia about z
    for suffix, gear, kv, limits in (("forward", "1 0 0 0 0 0", kv_linear, v_range),
                                     ("lateral", "0 1 0 0 0 0", kv_linear, None),
                                     ("turn", "0 0 0 0 0 1", kv_turn, (-w_max, w_max))):
        attrs = {"name": f"{ROBOT}_{suffix}", "site": f"{ROBOT}_base", "gear": gear, "kv": fmt(kv)}
        if limits is not None:
            attrs.update(ctrllimited="true", ctrlrange=fmt_seq(limits))
        etree.SubElement(actuators, "velocity", attrs)


def compile_world(root, spawn, floor_names, mover_names) -> RobotModel:
    """Compile ``root`` (an MJCF with the robot added) and put the robot at ``spawn`` = (x, y, yaw)."""
    import mujoco

    model = mujoco.MjModel.from_xml_string(etree.tostring(root, encoding="unicode"))
    qpos = np.array([model.joint(f"{ROBOT}_{s}").qposadr[0] for s in ("x", "y", "yaw")])
    qvel = np.array([model.joint(f"{ROBOT}_{s}").dofadr[0] for s in ("x", "y", "yaw")])
    data = mujoco.MjData(model)
    # The body sits at the origin with its joints at 0 (MuJoCo places a slide or hinge at qpos - qpos0),
    # so the joints read world x, y and yaw; the robot starts at the spawn.
    data.qpos[qpos] = spawn
    floor = frozenset(int(model.geom(n).id) for n in floor_names)
    mocap = np.array([model.body(n).mocapid[0] for n in mover_names], dtype=int)
    ctrl = np.array([model.actuator(f"{ROBOT}_{s}").id for s in ("forward", "lateral", "turn")])
    return RobotModel(model, data, int(model.body(ROBOT).id), int(model.geom(ROBOT).id), qpos, qvel, ctrl, floor, mocap)
