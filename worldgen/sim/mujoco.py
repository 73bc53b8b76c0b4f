"""The robot in MuJoCo, as the drive loop steps it: the environment's differential-drive body
(:mod:`worldgen.envs.robot`) added to a world folder's MJCF, with real contacts against walls, obstacles,
door leaves and movers; the movers (mocap bodies) follow world.json's ``dynamic_obstacles`` scripts.

Deterministic: the same world and commands give the same poses, bit for bit, in any process.
"""

from __future__ import annotations

import math
from pathlib import Path
from typing import Union

import numpy as np
from lxml import etree

from worldgen.envs.movers import MoverScript
from worldgen.envs.robot import RobotModel, add_robot, compile_world
from worldgen.export.xml import safe_parser
from worldgen.groundtruth.folder import robot_of

__all__ = ["MujocoBackend", "V_RANGE", "W_MAX"]

#: The servos' limits: forward speed (m/s) and turn rate (rad/s), beyond anything the controller asks.
V_RANGE = (-1.0, 1.0)
W_MAX = 4.0


class MujocoBackend:
    """:meth:`start` puts the robot at the spawn; :meth:`step` holds (v, w) for N physics steps.

    ``mjcf`` is the world's MJCF, its bytes (a world need not be on disk: a World, a pack archive's) or its path."""

    def __init__(self, mjcf: Union[bytes, Path], meta: dict):
        root = etree.fromstring(mjcf if isinstance(mjcf, bytes) else Path(mjcf).read_bytes(), safe_parser())
        robot = robot_of(meta)
        add_robot(root, robot.radius, robot.height, V_RANGE, W_MAX)
        self._root = root
        self._floor = sorted(e["name"] for e in meta["entities"] if e["role"] == "floor")
        self._movers = [m["name"] for m in meta.get("dynamic_obstacles", [])]
        self._script = MoverScript(meta.get("dynamic_obstacles", []))
        self._sim: RobotModel | None = None
        self.dt = 0.0

    def start(self, spawn: tuple[float, float, float, float]) -> tuple[float, float, float, float]:
        import mujoco

        x, y, _, yaw = spawn
        self._sim = sim = compile_world(self._root, (x, y, yaw), self._floor, self._movers)
        self.dt = float(sim.model.opt.timestep)
        if len(self._script):
            self._script.place(sim.data, sim.mocap, self._script.positions(np.zeros(1))[0])
        mujoco.mj_forward(sim.model, sim.data)
        return (float(sim.data.time), *sim.pose())

    def step(self, v: float, w: float, n: int) -> tuple[float, float, float, float]:
        import mujoco

        sim = self._sim
        assert sim is not None
        sim.data.ctrl[sim.ctrl] = (v, 0.0, w)
        # Movers (mocap bodies) follow world.json's scripts, placed before every physics step.
        where = self._script.positions(sim.data.time + self.dt * np.arange(int(n))) if len(self._script) else None
        for k in range(int(n)):
            if where is not None:
                self._script.place(sim.data, sim.mocap, where[k])
            mujoco.mj_step(sim.model, sim.data)
        x, y, yaw = sim.pose()
        # The hinge's angle winds past +-pi; a heading is an angle in (-pi, pi].
        return float(sim.data.time), x, y, math.atan2(math.sin(yaw), math.cos(yaw))

    def close(self) -> None:
        self._sim = None
