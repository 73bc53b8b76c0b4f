"""The robot in MuJoCo, as the drive loop steps it: the environment's differential-drive body
(:mod:`worldgen.envs.robot`) built from the world's robot description (world.json's ``robot`` and
``sensors.lidar`` through :func:`worldgen.groundtruth.folder.robot_description_of`: its size and mass, its
servos' ranges its ``max_speed`` forward and back and its ``turn_rate``, as robot.sdf's DiffDrive limits
them in Gazebo) added to a world folder's MJCF, with real contacts against walls, obstacles,
door leaves, movers and people, everything that moves driven as the environment drives it:

- movers (world.json ``dynamic_obstacles``) and impassive people walk their scripts (mocap bodies placed
  before every physics step), and people with a ``behaviour`` react to the robot through the environment's
  :class:`~worldgen.envs.reacting.Walkers` (once a command, from the robot's position and its velocity over
  the command before, inside their tubes);
- doors open as the environment's default ``doors="auto"`` opens them (:mod:`worldgen.envs.doors`): a door
  the robot comes to from the side its leaf swings into (a pull door) swings open by its hinge motor once
  the robot is within :data:`DOOR_TRIGGER` of the doorway; a push door is pushed open by the robot.

In a world with terrain the robot is :mod:`worldgen.envs.terrain`'s base, whose height and tilt follow its
feet's contacts with the ground (:attr:`MujocoBackend.heights` records how high it rides).

Every contact of the robot's body (the floor left out) is kept in :attr:`MujocoBackend.contacts`, door
leaves apart in :attr:`MujocoBackend.door_contacts`. Deterministic: the same world and commands give the
same poses, bit for bit, in any process.
"""

from __future__ import annotations

import math
from pathlib import Path
from typing import Any, Optional, Union

import numpy as np
from lxml import etree

from worldgen.envs.config import SETTINGS
from worldgen.envs.doors import Openers, add_openers
from worldgen.envs.reacting import Walkers
from worldgen.envs.robot import compile_world
from worldgen.envs.terrain import add_base, settle
from worldgen.export.xml import safe_parser
from worldgen.groundtruth.folder import robot_description_of
from worldgen.judge.figures import DOOR_DEBOUNCE

__all__ = ["MujocoBackend", "DOOR_MODE", "DOOR_TRIGGER", "DOOR_SPEED", "GIVE_WAY", "BACK_OFF",
           "OPEN_WITHIN", "movers_of"]

_DEFAULTS = {p.name: p.default for p in SETTINGS}
#: m beyond a leaf's sweep (its width, plus the robot's radius) the robot keeps while the leaf swings open.
GIVE_WAY = 0.05
#: m/s the robot backs away from the hinge when a leaf opens onto where it stands.
BACK_OFF = 0.2
#: rad: a leaf this close to its open limit is open.
OPEN_WITHIN = 0.1
#: How doors open: the environment's default (worldgen.envs.doors), and its trigger distance (m) and speed (rad/s).
DOOR_MODE = str(_DEFAULTS["doors"])
DOOR_TRIGGER = float(_DEFAULTS["door_trigger"])
DOOR_SPEED = float(_DEFAULTS["door_speed"])


def movers_of(meta: dict) -> list:
    """Everything that moves, in the MJCF's order: world.json's ``dynamic_obstacles``, then its ``people``
    (who do not loop)."""
    return list(meta.get("dynamic_obstacles") or []) + [dict(p, loop=False) for p in meta.get("people") or []]


class MujocoBackend:
    """:meth:`start` puts the robot at the spawn; :meth:`step` holds (v, w) for N physics steps.

    ``mjcf`` is the world's MJCF, its bytes (a world need not be on disk: a World, a pack archive's) or its path;
    ``scene`` the world's :class:`~worldgen.scene.Scene`, needed only where people react (their steps aside
    keep off its footprints)."""

    def __init__(self, mjcf: Union[bytes, Path], meta: dict, scene: Any = None):
        root = etree.fromstring(mjcf if isinstance(mjcf, bytes) else Path(mjcf).read_bytes(), safe_parser())
        #: The robot driven (world.json's, worldgen.scene.robot.RobotDescription) and its footprint.
        self.description = robot = robot_description_of(meta)
        self.robot = robot.footprint
        #: Whether the world has terrain: then the robot is the terrain base (worldgen.envs.terrain).
        self.terrain = bool(meta.get("terrain"))
        self._floor = add_base(root, self.robot, (-robot.max_speed, robot.max_speed), robot.turn_rate, self.terrain,
                               {e["name"] for e in meta["entities"] if e["role"] == "floor"})
        self._centre = 0.0
        self._doors = list(meta.get("doors") or [])
        add_openers(root, self._doors, DOOR_MODE)
        self._root = root
        self._leaves = frozenset(str(d["name"]) for d in self._doors)
        movers = movers_of(meta)
        self._names = [str(m["name"]) for m in movers]
        self.walkers = Walkers(movers, _wall_gap(scene) if any(m.get("behaviour") for m in movers) else None)
        self._sim: Any = None
        self._openers: Optional[Openers] = None
        self._last: tuple[float, float, float] = (0.0, 0.0, 0.0)
        self._touching: frozenset = frozenset()
        self._leaf_last: dict[str, float] = {}
        #: (t, name) of every contact of the robot that began, door leaves left out; and the pushes on a leaf
        #: (a contact with a leaf that began more than the judge's DOOR_DEBOUNCE after the last, as the env counts).
        self.contacts: list[tuple[float, str]] = []
        self.door_contacts: list[tuple[float, str]] = []
        self.dt = 0.0
        #: On terrain: (t, rise) after every command, the robot's centre's height over where it stands on
        #: flat ground (the ramp it is on, give or take its tilt).
        self.heights: list[tuple[float, float]] = []

    @property
    def doors_opened(self) -> list[str]:
        """The doors whose opener the robot triggered, in order."""
        return list(self._openers.opened) if self._openers is not None else []

    def start(self, spawn: tuple[float, float, float, float]) -> tuple[float, float, float, float]:
        import mujoco

        x, y, _, yaw = spawn
        sim: Any = compile_world(self._root, (x, y, yaw), self._floor, self._names)
        self._sim = sim
        if self.terrain:
            self._centre = settle(sim, self.robot)
            self.heights = [(float(sim.data.time), self._rise())]
        self.dt = float(sim.model.opt.timestep)
        self.walkers.reset()
        if len(self.walkers):
            self.walkers.place(sim.data, sim.mocap, self.walkers.positions(np.zeros(1))[0])
        self._openers = Openers(sim.model, sim.data, self._doors, DOOR_MODE, DOOR_TRIGGER, DOOR_SPEED)
        mujoco.mj_forward(sim.model, sim.data)
        self._last = (float(sim.data.time), x, y)
        return (float(sim.data.time), *sim.pose())

    def give_way(self, x: float, y: float, yaw: float, v: float, ahead: float) -> float:
        """The forward speed the robot at (x, y, yaw) asking ``v`` may take for the next ``ahead`` s: ``v``,
        unless a leaf its opener swings is still short of open and the robot stands in its sweep on the side
        it swings into (then it backs away from the hinge at :data:`BACK_OFF`, or stands if backing brings
        it nearer) or would enter it (then it stands): a leaf opening onto the robot presses on it, and the
        robot pressing back keeps it shut."""
        sim, openers = self._sim, self._openers
        if sim is None or openers is None or not openers.opened:
            return v
        p = np.array([x, y])
        heading = np.array([math.cos(yaw), math.sin(yaw)])
        for d in self._doors:
            if d["name"] not in openers.opened or not d.get("passage"):
                continue
            lo, hi = d["limits"]
            opened = lo if abs(lo) > abs(hi) else hi
            angle = float(sim.data.qpos[sim.model.joint(d["joint"]).qposadr[0]])
            # Open once within OPEN_WITHIN of its limit, or past it: a leaf pushed beyond its limit (joint limits
            # are soft) is as open (door seed 189 of bench_drive_dynamic: pushed to 2.1 rad of 1.57, it held the
            # robot waiting for ever).
            short = (opened - angle) * math.copysign(1.0, opened)
            if short <= OPEN_WITHIN or float((p - d["passage"]["center"]) @ d["passage"]["normal"]) <= 0:
                continue
            hinge, reach = np.asarray(d["hinge"][:2], dtype=float), float(d["width"]) + self.robot.radius + GIVE_WAY
            now = float(np.hypot(*(p - hinge)))
            if now < reach:
                back = p - 0.01 * heading
                away = np.hypot(*(back - hinge)) > now and _to_segment(back, hinge, _open_leaf_end(d, opened)) > \
                    self.robot.radius + GIVE_WAY
                return -BACK_OFF if away and self._room_behind(x, y, yaw) else 0.0
            if np.hypot(*(p + max(v, 0.0) * ahead * heading - hinge)) < reach:
                return 0.0
        return v

    def _room_behind(self, x: float, y: float, yaw: float) -> bool:
        """Whether nothing (a wall, an obstacle, a mover, a person) is within 3 cm of the robot's back: rays
        from its centre at half its height, straight back and 30 degrees either side."""
        import mujoco

        sim = self._sim
        reach = self.robot.radius / math.cos(math.radians(30.0)) + 0.03
        for off in (-30.0, 0.0, 30.0):
            a = yaw + math.pi + math.radians(off)
            hit = mujoco.mj_ray(sim.model, sim.data, np.array([x, y, self.robot.height / 2]),
                                np.array([math.cos(a), math.sin(a), 0.0]), None, 1, sim.body, np.zeros(1, np.int32))
            if 0 <= hit < reach:
                return False
        return True

    def step(self, v: float, w: float, n: int) -> tuple[float, float, float, float]:
        import mujoco

        sim = self._sim
        assert sim is not None and self._openers is not None
        model, data = sim.model, sim.data
        n = int(n)
        x, y, _ = sim.pose()
        if len(self._openers):
            self._openers.update(x, y)
        data.ctrl[sim.ctrl] = (v, 0.0, w)
        where = None
        if len(self.walkers):
            # As the environment does: people react to the robot where it is, moving as it did over the last command.
            t0, x0, y0 = self._last
            dt = float(data.time) - t0
            velocity = ((x - x0) / dt, (y - y0) / dt) if dt > 0 else (0.0, 0.0)
            where = self.walkers.period(float(data.time), self.dt, n, (x, y), velocity, self.robot.radius)
        self._last = (float(data.time), x, y)
        for k in range(n):
            if where is not None:
                self.walkers.place(data, sim.mocap, where[k])
            mujoco.mj_step(model, data)
            if data.ncon or self._touching:
                self._note(float(data.time))
        if self.terrain:
            self.heights.append((float(data.time), self._rise()))
        x, y, yaw = sim.pose()
        # The hinge's angle winds past +-pi; a heading is an angle in (-pi, pi].
        return float(data.time), x, y, math.atan2(math.sin(yaw), math.cos(yaw))

    def _rise(self) -> float:
        return float(self._sim.data.xpos[self._sim.body][2]) - self._centre

    def _note(self, t: float) -> None:
        """Keep the contacts of the robot's body that began at ``t`` (the floor left out)."""
        import mujoco

        sim, data = self._sim, self._sim.data
        pairs = data.contact.geom[: data.ncon]
        mine = (pairs[:, 0] == sim.geom) | (pairs[:, 1] == sim.geom)
        others = np.where(pairs[mine, 0] == sim.geom, pairs[mine, 1], pairs[mine, 0])
        now = frozenset(mujoco.mj_id2name(sim.model, mujoco.mjtObj.mjOBJ_GEOM, int(g)) or f"geom_{int(g)}"
                        for g in others if int(g) not in sim.floor)
        for name in sorted(now - self._touching):
            if name not in self._leaves:
                self.contacts.append((t, name))
            elif t - self._leaf_last.get(name, -math.inf) > DOOR_DEBOUNCE:
                self.door_contacts.append((t, name))  # one push, however often the leaf bounces off the body
        for name in now & self._leaves:
            self._leaf_last[name] = t
        self._touching = now

    def close(self) -> None:
        self._sim = None


def _open_leaf_end(door: dict, opened: float) -> np.ndarray:
    """(2,) the free end of a leaf at its open limit ``opened``: the closed leaf runs from the hinge across the
    doorway (to twice the passage's centre, seen from the hinge), turned about the hinge's axis."""
    hinge = np.asarray(door["hinge"][:2], dtype=float)
    across = 2.0 * (np.asarray(door["passage"]["center"], dtype=float) - hinge)
    turn = opened * (1.0 if door["axis"][2] >= 0 else -1.0)
    c, s = math.cos(turn), math.sin(turn)
    return hinge + np.array([c * across[0] - s * across[1], s * across[0] + c * across[1]])


def _to_segment(p: np.ndarray, a: np.ndarray, b: np.ndarray) -> float:
    ab = b - a
    u = float(np.clip((p - a) @ ab / max(float(ab @ ab), 1e-12), 0.0, 1.0))
    return float(np.hypot(*(p - a - u * ab)))


def _wall_gap(scene):
    """The reacting people's distance to the world's footprints (below a person's height) and the floor's edge,
    as the environment computes it (worldgen.envs.reacting.walkers_of)."""
    from worldgen.errors import ParameterError
    from worldgen.feasibility.geometry import Obstacles2D
    from worldgen.people.places import PERSON_HEIGHT
    from worldgen.people.react import wall_gap_of
    from worldgen.scene.footprint import scene_footprints

    if scene is None:
        raise ParameterError("people who react to the robot need the world's scene to step aside in; "
                             "it could not be rebuilt for this world")
    return wall_gap_of(Obstacles2D.from_footprints(scene_footprints(scene, PERSON_HEIGHT)), scene.bounds)
