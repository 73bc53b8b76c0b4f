"""A policy with a planted weakness, for the campaign tests: it drives well everywhere but in one corner of
the world space, where a person comes near ahead of it.

``FreezesNearPeople`` follows the task's timed path where the task has one (worlds with people: the
path certified clear of every person's tube, docs/people.md) and its reference path elsewhere, both with
the shipped followers (:mod:`worldgen.envs.policies`), which reach the goal without contact. Its flaw: the
first time a person's disc comes within :data:`FREEZE_DISTANCE` m of the robot's centre inside
:data:`FREEZE_CONE` rad of its heading, it stops and never moves again (the freezing robot), so the run
times out or the person walks into it. Outside the corner (no person ever near ahead: no people, or
people elsewhere) it passes; inside (a person crossing its way) it fails.

People are where world.json's tracks have them at the episode's time: a privileged view, as the
followers' own pose is; the campaign's worlds with impassive people move exactly so.

Use it as the system ``{"policy": "support.planted:FreezesNearPeople.for_env", "env": {"angular_velocity": 4.0}}``
(``tests/`` on sys.path, as pytest puts it there for this folder): the timed path turns its corners on the
spot, and at the environment's default turn rate (1 rad/s) the follower lags behind it into obstacles.
"""

from __future__ import annotations

import math

import numpy as np

from worldgen.envs.policies import PathFollower, TimedFollower
from worldgen.scene.motion import positions_at

__all__ = ["FreezesNearPeople", "Breaks", "Stands", "TwoArguments", "FREEZE_DISTANCE", "FREEZE_CONE"]

#: m from the robot's centre to a person's disc edge at which it freezes.
FREEZE_DISTANCE = 1.5
#: rad either side of the heading that counts as ahead.
FREEZE_CONE = math.pi / 3


class FreezesNearPeople:
    """A follower that freezes for good once a person is near ahead (see the module's docstring)."""

    def __init__(self, follower, people: list[dict]):
        self.follower = follower
        self.timed = isinstance(follower, TimedFollower)
        self.tracks = [np.asarray(p["trajectory"], dtype=float) for p in people]
        self.radii = np.array([float(p["radius"]) for p in people])
        self.frozen_at = None

    @classmethod
    def for_env(cls, env) -> "FreezesNearPeople":
        u = env.unwrapped
        people = [m for m in u.world.movers if not m.get("loop", False)]
        timed = u.task.get("timed_path")
        follower = TimedFollower.for_env(env) if timed else PathFollower.for_env(env)
        return cls(follower, people)

    def _near_ahead(self, x: float, y: float, yaw: float, t: float) -> bool:
        if not self.tracks:
            return False
        where = positions_at(self.tracks, [False] * len(self.tracks), np.array([t]))[0]
        d = np.hypot(where[:, 0] - x, where[:, 1] - y) - self.radii
        bearing = np.arctan2(where[:, 1] - y, where[:, 0] - x) - yaw
        off = np.abs((bearing + math.pi) % (2 * math.pi) - math.pi)
        return bool(np.any((d < FREEZE_DISTANCE) & (off < FREEZE_CONE)))

    def action(self, x: float, y: float, yaw: float, t: float) -> np.ndarray:
        if self.frozen_at is None and self._near_ahead(x, y, yaw, t):
            self.frozen_at = t
        if self.frozen_at is not None:
            return np.zeros(2, dtype=np.float32)
        return self.follower.action(x, y, yaw, t) if self.timed else self.follower.action(x, y, yaw)


class Breaks:
    """A policy whose ``action`` raises after ``steps`` calls: a policy's own bug, no robot failure."""

    def __init__(self, steps: int = 5):
        self.steps = steps

    @classmethod
    def for_env(cls, env) -> "Breaks":
        return cls()

    def action(self, observation) -> np.ndarray:
        self.steps -= 1
        if self.steps < 0:
            raise RuntimeError("the network's weights are NaN")
        return np.zeros(2, dtype=np.float32)


class Stands:
    """Made without the environment (its factory, the class, takes no argument); it never moves."""

    def action(self, observation) -> np.ndarray:
        return np.zeros(2, dtype=np.float32)


class TwoArguments:
    """An ``action`` of no shape the campaign knows: (x, y)."""

    def __init__(self, env):
        self.env = env

    def action(self, x, y) -> np.ndarray:
        return np.zeros(2, dtype=np.float32)
