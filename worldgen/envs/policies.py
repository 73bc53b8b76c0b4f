"""Scripted baselines for the navigation environment: a reference-path follower, a reactive heuristic
and a random policy.

:class:`PathFollower` is pure pursuit on the task's reference path (world.json
``tasks[].path.waypoints``, the exact shortest path for the footprint): it steers
toward the point ``lookahead`` metres further along the path than the robot's
projection on it, turning on the spot while that point lies more than
``turn_in_place`` radians off the heading. It reads the robot's true pose (an
oracle baseline, not a learned policy) and scores SPL close to 1: an upper bound
a learned policy can be compared with. :class:`RandomPolicy` samples the action
space from its own seeded generator: the floor. :class:`GapHeuristic` reads only
the observation (as a learned policy does): it heads for the free lidar sector
nearest the goal's bearing, turning on the spot while that sector lies well off
the heading; the bar a learned policy has to clear.
"""

from __future__ import annotations

import math
from typing import Sequence

import numpy as np

from worldgen.seeding import policy_rng

__all__ = ["GapHeuristic", "PathFollower", "RandomPolicy", "TimedFollower", "drive_timed"]


class PathFollower:
    """Pure pursuit along ``waypoints`` ((k, 2) m) within ``v_max`` m/s and ``w_max`` rad/s."""

    def __init__(self, waypoints: Sequence[Sequence[float]], v_max: float, w_max: float, lookahead: float = 0.15,
                 gain: float = 3.0, turn_in_place: float = 0.35):
        self.path = np.asarray(waypoints, dtype=float).reshape(-1, 2)
        if len(self.path) == 1:
            self.path = np.vstack([self.path, self.path])
        self.v_max, self.w_max = float(v_max), float(w_max)
        self.lookahead, self.gain, self.turn_in_place = float(lookahead), float(gain), float(turn_in_place)
        self.segment = 0

    @classmethod
    def for_env(cls, env, **kwargs) -> "PathFollower":
        """A follower of the current episode's reference path, within the env's action limits."""
        env = env.unwrapped
        return cls(env.task["path"]["waypoints"], float(env.action_space.high[0]), float(env.action_space.high[1]),
                   **kwargs)

    def _target(self, xy: np.ndarray) -> np.ndarray:
        path = self.path
        while True:  # the segment the robot is on: move on once past a segment's end
            a, b = path[self.segment], path[self.segment + 1]
            seg = b - a
            s = float(np.clip(np.dot(xy - a, seg) / max(float(np.dot(seg, seg)), 1e-12), 0.0, 1.0))
            if s < 1.0 or self.segment == len(path) - 2:
                break
            self.segment += 1
        along = s * math.hypot(*seg) + self.lookahead
        for k in range(self.segment, len(path) - 1):
            length = math.hypot(*(path[k + 1] - path[k]))
            if along <= length:
                return path[k] + (path[k + 1] - path[k]) * (along / max(length, 1e-12))
            along -= length
        return path[-1]

    def action(self, x: float, y: float, yaw: float) -> np.ndarray:
        """(v, w) as float32 for the robot at (x, y) heading ``yaw``."""
        xy = np.array([x, y])
        target = self._target(xy)
        dx, dy = target - xy
        err = (math.atan2(dy, dx) - yaw + math.pi) % (2.0 * math.pi) - math.pi
        w = float(np.clip(self.gain * err, -self.w_max, self.w_max))
        if abs(err) > self.turn_in_place:
            v = 0.0
        else:
            # Never faster than the turn rate allows on this curvature (pure pursuit: w = v * 2 sin(err) / d).
            d = max(math.hypot(dx, dy), 1e-9)
            curvature = abs(2.0 * math.sin(err) / d)
            v = min(self.v_max, self.w_max / curvature if curvature > 1e-9 else self.v_max) * math.cos(err)
            v = min(v, self.v_max * d / self.lookahead)  # ease in on the goal
        return np.array([max(v, 0.0), w], dtype=np.float32)


class TimedFollower:
    """Drives a task's timed path (world.json ``tasks[].timed_path``: ``t, x, y`` rows): each step it heads
    for where the timed path is at the step's end and asks the speed that gets there in ``period`` s
    (turning first where that point lies more than ``turn_in_place`` rad off the heading), within ``v_max``
    and ``w_max``; where that point is within ``near`` m (the timed path standing at the spawn or a corner,
    or just overshot) it turns to face the path's next leg instead. The timed path turns on the spot no
    faster than ``robot.max_turn_rate`` and changes speed no faster than ``robot.max_acceleration``, so a
    follower with the environment's default limits keeps up with it, within the certificate's
    ``robot.tracking_margin`` (docs/people.md: measured), and so keeps the certificate's distance from
    every person's tube, however the people react."""

    def __init__(self, rows, v_max: float, w_max: float, period: float, turn_in_place: float = 0.3,
                 near: float = 0.01):
        self.rows = np.asarray(rows, dtype=float).reshape(-1, 3)
        self.v_max, self.w_max, self.period = float(v_max), float(w_max), float(period)
        self.turn_in_place, self.near = float(turn_in_place), float(near)
        step = np.diff(self.rows[:, 1:], axis=0)
        self._moves = np.flatnonzero(np.hypot(step[:, 0], step[:, 1]) > 1e-9)  # the rows a movement starts at
        self._yaws = np.arctan2(step[:, 1], step[:, 0])

    @classmethod
    def for_env(cls, env, **kwargs) -> "TimedFollower":
        """A follower of the current episode's timed path, within the env's action limits."""
        env = env.unwrapped
        return cls(env.task["timed_path"], float(env.action_space.high[0]), float(env.action_space.high[1]),
                   env.config.control_period, **kwargs)

    def at(self, t: float) -> np.ndarray:
        """(2,) where the timed path has the robot at time ``t`` (at the goal after its last row)."""
        r = self.rows
        return np.array([np.interp(t, r[:, 0], r[:, 1]), np.interp(t, r[:, 0], r[:, 2])])

    def next_heading(self, t: float) -> float | None:
        """The direction (rad) of the timed path's next movement after time ``t``, None once it has arrived."""
        k = int(np.searchsorted(self.rows[:, 0], t, side="right")) - 1
        later = self._moves[self._moves >= k]
        return float(self._yaws[later[0]]) if len(later) else None

    def action(self, x: float, y: float, yaw: float, t: float) -> np.ndarray:
        """(v, w) as float32 for the robot at (x, y) heading ``yaw`` at time ``t``."""
        dx, dy = self.at(t + self.period) - np.array([x, y])
        dist = math.hypot(dx, dy)
        if dist < self.near:  # close enough (never turn round for a few mm overshot): face where it goes next
            ahead = self.next_heading(t + self.period)
            if ahead is None:
                return np.zeros(2, dtype=np.float32)
            err = (ahead - yaw + math.pi) % (2.0 * math.pi) - math.pi
            return np.array([0.0, float(np.clip(err / self.period, -self.w_max, self.w_max))], dtype=np.float32)
        err = (math.atan2(dy, dx) - yaw + math.pi) % (2.0 * math.pi) - math.pi
        w = float(np.clip(err / self.period, -self.w_max, self.w_max))
        v = 0.0 if abs(err) > self.turn_in_place else min(self.v_max, dist / self.period * math.cos(err))
        return np.array([max(v, 0.0), w], dtype=np.float32)


class RandomPolicy:
    """Uniform actions in ``action_space`` from its own generator seeded with ``seed``."""

    def __init__(self, action_space, seed: int = 0):
        self.low = np.asarray(action_space.low, dtype=np.float64)
        self.high = np.asarray(action_space.high, dtype=np.float64)
        self.rng = policy_rng(seed)

    def action(self, *_ignored) -> np.ndarray:
        return self.rng.uniform(self.low, self.high).astype(np.float32)


class GapHeuristic:
    """Turn toward the goal and drive into the free sector nearest its bearing (observation only).

    A sector is free when it and both its neighbours reach beyond ``free`` m (the robot is wider
    than a ray), or the goal is nearer than its range; the
    sectors' bearings are those of their beams (``angles``, rad, the env's ``lidar.angles``).
    """

    def __init__(self, angles, sectors: int, v_max: float, w_max: float, free: float = 0.8, gain: float = 2.0,
                 turn_in_place: float = 0.6, slow: float = 0.25, cone: float = math.pi / 3):
        a = np.asarray(angles, dtype=float).reshape(sectors, -1)
        self.bearing = np.arctan2(np.sin(a).mean(axis=1), np.cos(a).mean(axis=1))
        self.v_max, self.w_max = float(v_max), float(w_max)
        self.free, self.gain, self.turn_in_place, self.slow = float(free), float(gain), float(turn_in_place), float(slow)
        self.cone = float(cone)

    @classmethod
    def for_env(cls, env, **kwargs) -> "GapHeuristic":
        env = env.unwrapped
        lidar = env.lidar
        return cls(lidar.angles, lidar.size, float(env.action_space.high[0]), float(env.action_space.high[1]), **kwargs)

    def action(self, obs) -> np.ndarray:
        """(v, w) as float32 for the observation ``obs`` (scan, goal distance, goal angle, last v, last w)."""
        obs = np.asarray(obs, dtype=float)
        n = len(self.bearing)
        scan, distance, goal = obs[:n], obs[n], obs[n + 1]
        off = np.abs((self.bearing - goal + math.pi) % (2.0 * math.pi) - math.pi)
        wide = np.minimum(scan, np.minimum(np.roll(scan, 1), np.roll(scan, -1)))  # the robot is wider than a ray
        ok = (wide > self.free) | (scan > distance)
        target = self.bearing[int(np.argmin(np.where(ok, off, np.inf)))] if ok.any() else goal
        # Anything within `cone` of the heading closer than `free` (a box beside the robot's path too) slows
        # the robot and pushes its heading away, the harder the closer.
        fwd = np.abs(self.bearing) < self.cone
        push = np.clip((self.free - scan[fwd]) / self.free, 0.0, 1.0)
        w = float(np.clip(self.gain * target - self.gain * float(np.sum(push * np.sign(self.bearing[fwd]))),
                          -self.w_max, self.w_max))
        front = float(scan[fwd].min(initial=np.inf))
        room = min(1.0, max(0.0, (front - self.slow) / max(self.free - self.slow, 1e-9)))
        v = 0.0 if abs(target) > self.turn_in_place else self.v_max * math.cos(target) * room
        return np.array([max(v, 0.0), w], dtype=np.float32)


def drive_timed(env, **reset) -> dict:
    """Reset ``env`` (``reset`` goes to ``env.reset``) and drive the episode's timed path with a
    :class:`TimedFollower` to the episode's end; the end's info."""
    env.reset(**reset)
    follower = TimedFollower.for_env(env)
    u = env.unwrapped
    while True:
        x, y, yaw = u.robot_pose
        _, _, terminated, truncated, info = env.step(follower.action(x, y, yaw, u.episode.rows[-1][0]))
        if terminated or truncated:
            return info
