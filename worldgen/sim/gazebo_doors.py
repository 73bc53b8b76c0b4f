"""Pull doors in ``worldgen drive --sim gazebo``: the same rule as in MuJoCo, played by a joint system of Gazebo's.

In MuJoCo (worldgen.sim.mujoco, as the environment's default ``doors="auto"``) a door the robot comes to from
the side its leaf swings into (world.json ``doors[].passage.normal`` points there) opens by a hinge motor once
the robot's centre is within :data:`~worldgen.sim.mujoco.DOOR_TRIGGER` of the doorway's centre: the motor's
target ramps from the leaf's angle to its open limit at :data:`~worldgen.sim.mujoco.DOOR_SPEED`, a stiff,
critically damped servo (natural frequency :data:`~worldgen.envs.doors.OPENER_OMEGA`, scaled by the leaf's
inertia about the hinge, its torque bounded by the hinge's effort) follows the target.

Gazebo plays the same: world.sdf is run as a copy with the release's joint position controller
(worldgen.export.contract's ``DOOR_OPENER``) on the hinge of each door the drive's plan pulls (the rule above
walked along the plan before the run: a controller holds its leaf at the joint's zero, the leaf's initial
angle, so a door the robot pushes must have none), its gains those of MuJoCo's servo for that leaf. During
the run the same rule on the simulator's pose of the robot triggers it; from then on the drive bridge sends
the ramp's target once a command (the target at the command's end). world.sdf itself is not changed: its
bytes are the exporter's (and the golden bytes'), and a world without pull doors runs as written.

While a leaf swings open towards the robot, the robot gives way as in MuJoCo: it stands rather than enter the
leaf's sweep, and backs out of it at :data:`~worldgen.sim.mujoco.BACK_OFF` when it stands inside, unless
backing brings it nearer the hinge or into the open leaf's place, or something is behind it. Gazebo gives
the drive no ray query: "behind it" is asked of world.json instead (``room_behind``: the judge's collision
check of the footprint moved back, walls, obstacles, movers and people where world.json has them). The
leaf's angle is not read back: the leaf counts as swinging until :data:`SETTLE` s after the ramp reached the
open limit (the servo trails the ramp by about ``2 DOOR_SPEED / OPENER_OMEGA`` rad).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path
from typing import Callable, Optional, Sequence

import numpy as np
from lxml import etree

from worldgen.envs.doors import OPENER_OMEGA
from worldgen.export.contract import DOOR_COMMAND_TOPIC, WORLD_SYSTEMS
from worldgen.export.xml import safe_parser
from worldgen.floats import fmt
from worldgen.sim.gazebo_install import GazeboInstall, GazeboMissingError
from worldgen.sim.mujoco import BACK_OFF, DOOR_SPEED, DOOR_TRIGGER, GIVE_WAY, _open_leaf_end, _to_segment

__all__ = ["SETTLE", "Trigger", "pulled_doors", "plan_points", "opener_library", "GazeboDoors", "world_with_openers",
           "leaf_inertia"]

#: s after the ramp reaches the open limit that the leaf still counts as swinging (the servo settles in about
#: 4 / OPENER_OMEGA = 0.2 s; twice that and more for the trailing angle).
SETTLE = 0.5


class Trigger:
    """The ``"auto"`` rule of worldgen.envs.doors.Openers.update, without a simulator: a door with a doorway
    opens when the robot's centre enters the disc of ``trigger`` m about the doorway's centre on the side its
    passage normal points to, and never once the robot entered that disc from the other side (until it leaves)."""

    def __init__(self, doors: Sequence[dict], trigger: float = DOOR_TRIGGER):
        self.doors = [d for d in doors if d.get("passage")]
        self.trigger = float(trigger)
        self.opened: list[str] = []
        self._pushing: set[str] = set()

    def update(self, x: float, y: float) -> list[dict]:
        """The doors the robot at (x, y) now triggers (each once)."""
        new = []
        for d in self.doors:
            name = str(d["name"])
            if name in self.opened:
                continue
            rel = np.array([x, y]) - np.asarray(d["passage"]["center"], dtype=float)
            if math.hypot(*rel) > self.trigger:
                self._pushing.discard(name)
                continue
            if name in self._pushing or float(rel @ np.asarray(d["passage"]["normal"], dtype=float)) <= 0.0:
                self._pushing.add(name)
                continue
            self.opened.append(name)
            new.append(d)
        return new


def plan_points(plan) -> np.ndarray:
    """(k, 2) points along a drive's plan (worldgen.sim.schedule.Plan), no two more than 2 cm apart."""
    pts = np.asarray(plan.rows[:, 1:3] if plan.rows is not None else plan.waypoints, dtype=float)
    out = [pts[:1]]
    for a, b in zip(pts[:-1], pts[1:]):
        n = max(1, math.ceil(float(np.hypot(*(b - a))) / 0.02))
        out.append(a + np.outer(np.arange(1, n + 1) / n, b - a))
    return np.vstack(out)


def pulled_doors(doors: Sequence[dict], points: np.ndarray) -> list[dict]:
    """The doors of world.json ``doors[]`` that the rule opens for a robot going along ``points``, in order."""
    trigger = Trigger(doors)
    return [d for p in points for d in trigger.update(float(p[0]), float(p[1]))]


def opener_library(install: GazeboInstall) -> Optional[Path]:
    """The shared library of the install's door opener system (on its system plugin path, or in a
    ``*/plugins`` folder beside its libraries), or None when the build has none."""
    filename, _ = install.release.door_opener()
    env = install.env
    folders = [Path(p) for p in env.get(install.release.plugin_path_var, "").split(":") if p]
    for lib in (Path(p) for p in env.get("LD_LIBRARY_PATH", "").split(":") if p):
        folders += [lib, *sorted(lib.glob("*/plugins"))]
    for folder in folders:
        if (folder / f"lib{filename}.so").is_file():
            return folder / f"lib{filename}.so"
    return None


def _rotation(rpy: Sequence[float]) -> np.ndarray:
    (cr, sr), (cp, sp), (cy, sy) = ((math.cos(a), math.sin(a)) for a in rpy)
    return np.array([[cy * cp, cy * sp * sr - sy * cr, cy * sp * cr + sy * sr],
                     [sy * cp, sy * sp * sr + cy * cr, sy * sp * cr - cy * sr],
                     [-sp, cp * sr, cp * cr]])


def _pose(element) -> tuple[np.ndarray, np.ndarray]:
    """(xyz, R) of an element's ``<pose>`` (identity without one)."""
    text = element.findtext("pose") if element is not None else None
    v = [float(f) for f in text.split()] if text else [0.0] * 6
    return np.array(v[:3]), _rotation(v[3:6])


def leaf_inertia(model, joint) -> float:
    """kg m^2: the moment of inertia about a revolute ``joint``'s axis of its child link (SDF elements of one
    model), what MuJoCo's opener scales its gains by (the joint pose is in the child link's frame, SDFormat's
    default; a link without ``<inertial>`` has SDFormat's mass 1 and unit inertia)."""
    link = model.find(f"link[@name='{joint.findtext('child')}']")
    inertial = link.find("inertial") if link is not None else None
    mass = float(inertial.findtext("mass") or 1.0) if inertial is not None else 1.0
    tensor = inertial.find("inertia") if inertial is not None else None
    k = {key: float(tensor.findtext(key) or 0.0) if tensor is not None else float(key in ("ixx", "iyy", "izz"))
         for key in ("ixx", "ixy", "ixz", "iyy", "iyz", "izz")}
    com, com_rot = _pose(inertial)
    about_com = com_rot @ np.array([[k["ixx"], k["ixy"], k["ixz"]], [k["ixy"], k["iyy"], k["iyz"]],
                                    [k["ixz"], k["iyz"], k["izz"]]]) @ com_rot.T
    at, rot = _pose(joint)
    axis = rot @ np.array([float(f) for f in (joint.findtext("axis/xyz") or "0 0 1").split()])
    axis /= np.linalg.norm(axis)
    arm = com - at
    arm -= (arm @ axis) * axis
    return float(axis @ about_com @ axis + mass * (arm @ arm))


def world_with_openers(sdf: Path, doors: Sequence[dict], install: GazeboInstall) -> tuple[bytes, list[str]]:
    """world.sdf's text with the release's joint position controller on the hinge of each of ``doors``, and
    the controllers' target topics in that order. Mesh URIs relative to the world's folder are made absolute
    (the copy lives elsewhere). GazeboMissingError in one line when the install has no such system."""
    filename, name = install.release.door_opener()
    if opener_library(install) is None:
        raise GazeboMissingError(
            f"Gazebo {install.version} ({install.setup}) has no {name} system (lib{filename}.so), which opens "
            f"the pull door{'s' if len(doors) > 1 else ''} {', '.join(str(d['name']) for d in doors)} on this task's "
            "way: drive it in a build that has one (shared/gazebo's Harmonic, or Fortress 6.7 through "
            "WORLDGEN_GAZEBO_SETUP) or with --sim mujoco")
    root = etree.parse(str(sdf), safe_parser()).getroot()
    world = root.find("world")
    if world is not None and world.find("plugin") is None:  # the server's defaults, named (WORLD_SYSTEMS)
        for k, system in enumerate(WORLD_SYSTEMS):
            file, cls = install.release.plugin(*system)
            world.insert(k, etree.Element("plugin", {"filename": file, "name": cls}))
    for uri in root.iter("uri"):
        text = (uri.text or "").strip()
        if text and "://" not in text and not Path(text).is_absolute():
            uri.text = str((sdf.parent / text).resolve())
    topics = []
    for d in doors:
        joint = next((j for j in root.iter("joint") if j.get("name") == d["joint"]), None)
        if joint is None:
            raise GazeboMissingError(f"{sdf} has no joint {d['joint']} for door {d['name']}")
        model = joint.getparent()
        inertia = leaf_inertia(model, joint)
        effort = float(joint.findtext("axis/limit/effort") or -1.0)
        topic = DOOR_COMMAND_TOPIC.format(model=model.get("name"), joint=d["joint"])
        plugin = etree.SubElement(model, "plugin", {"filename": filename, "name": name})
        for key, value in (("joint_name", d["joint"]), ("topic", topic),
                           ("p_gain", fmt(inertia * OPENER_OMEGA ** 2)), ("i_gain", "0"),
                           ("d_gain", fmt(2.0 * inertia * OPENER_OMEGA)),
                           # MuJoCo bounds the opener's torque by the hinge's effort (none: unbounded)
                           ("cmd_max", fmt(effort if effort > 0 else 1e6)),
                           ("cmd_min", fmt(-effort if effort > 0 else -1e6))):
            etree.SubElement(plugin, key).text = value
        topics.append(topic)
    return etree.tostring(root, xml_declaration=True, encoding="UTF-8"), topics


@dataclass
class _Door:
    door: dict
    open: float           # the open limit, rad from the joint's zero (the leaf's initial angle)
    limit: float          # the open limit, rad from closed (world.json's limits)
    since: Optional[float] = None  # when the robot triggered it (simulation time)


class GazeboDoors:
    """The openers of one Gazebo drive: :meth:`targets` says what to send each command, :meth:`give_way` how fast
    the robot may go. ``doors`` are world.json's, each with a controller in the world run (:func:`world_with_openers`);
    ``room_behind(t, x, y, yaw)`` says whether the robot may back away (None: it never backs)."""

    def __init__(self, doors: Sequence[dict], radius: float,
                 room_behind: Optional[Callable[[float, float, float, float], bool]] = None):
        self.radius = float(radius)
        self.room_behind = room_behind
        self._doors = []
        for d in doors:
            lo, hi = d["limits"]
            opened = lo if abs(lo) > abs(hi) else hi  # the open limit (worldgen.scene.doors.open_angle)
            self._doors.append(_Door(d, float(opened) - float(d.get("angle", 0.0)), float(opened)))
        self._trigger = Trigger([d.door for d in self._doors])

    @property
    def opened(self) -> list[str]:
        """The doors the robot triggered, in order."""
        return list(self._trigger.opened)

    def targets(self, t: float, x: float, y: float, ahead: float) -> list[tuple[int, float]]:
        """(index, target angle) for each triggered door's controller, the robot at (x, y) at time ``t`` and the
        command lasting ``ahead`` s: the ramp's angle at the command's end."""
        fresh = {str(d["name"]) for d in self._trigger.update(x, y)}
        out = []
        for k, d in enumerate(self._doors):
            if str(d.door["name"]) in fresh:
                d.since = t
            if d.since is not None:
                swung = DOOR_SPEED * (t + ahead - d.since)
                out.append((k, math.copysign(min(abs(d.open), swung), d.open)))
        return out

    def give_way(self, t: float, x: float, y: float, yaw: float, v: float, ahead: float) -> float:
        """``v``, unless a triggered leaf still swings and the robot is on the side it swings into: within its
        sweep (its width plus the robot's radius plus GIVE_WAY about the hinge) it backs away at -BACK_OFF where
        that takes it further from the hinge, clear of the open leaf, with room behind, else stands; about to
        enter the sweep, it stands."""
        p = np.array([x, y])
        heading = np.array([math.cos(yaw), math.sin(yaw)])
        for d in self._doors:
            if d.since is None or t > d.since + abs(d.open) / DOOR_SPEED + SETTLE:
                continue
            passage = d.door["passage"]
            if float((p - passage["center"]) @ np.asarray(passage["normal"], dtype=float)) <= 0:
                continue
            hinge = np.asarray(d.door["hinge"][:2], dtype=float)
            reach = float(d.door["width"]) + self.radius + GIVE_WAY
            now = float(np.hypot(*(p - hinge)))
            if now < reach:
                back = p - 0.01 * heading
                away = np.hypot(*(back - hinge)) > now and \
                    _to_segment(back, hinge, _open_leaf_end(d.door, d.limit)) > self.radius + GIVE_WAY
                return -BACK_OFF if away and self.room_behind is not None and self.room_behind(t, x, y, yaw) else 0.0
            if np.hypot(*(p + max(v, 0.0) * ahead * heading - hinge)) < reach:
                return 0.0
        return v
