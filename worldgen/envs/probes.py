"""Reference probes: two deterministic policies that are the named yardsticks of a world's difficulty.

The path follower (:class:`~worldgen.envs.policies.PathFollower`) succeeds almost
everywhere and the random policy almost nowhere, so neither tells an easy world
from a hard one. The probes fail in some worlds and not in others, and the
difficulty score (:mod:`worldgen.groundtruth.difficulty`) is validated against
their failures (benchmarks/bench_difficulty.py), as BARN names its planners:

- :class:`ReactiveProbe` (``"reactive"``): lidar only, no map and no memory. From
  the observation alone (the scan, the goal's distance and bearing) it picks,
  among :data:`HEADINGS` headings, the one closest to the goal's bearing along
  which a corridor as wide as the robot plus :data:`MARGIN` is free for
  ``min(goal distance, horizon)`` (1.5 m; failing that, half and a quarter of
  it), within a right angle of the bearing; where none is, the freest heading. It turns
  toward it and drives at a speed the free distance ahead allows. It is myopic
  on purpose: dead ends, pockets and long detours trap it.
- :class:`CornerCutter` (``"tracker"``): the path follower with a lookahead of
  0.8 m instead of 0.15 m: it reads the true pose and the exact reference path
  but cuts every corner by up to the lookahead, so it grazes obstacles where the
  path bends tightly near them.

Both are pure functions of what they read (the reactive probe of the
observation; the tracker of the pose and its progress along the path), so the
same episode gives the same actions. :func:`run_episode` drives one episode.
"""

from __future__ import annotations

import math
from typing import Callable

import numpy as np

from worldgen.envs.policies import PathFollower

__all__ = ["ReactiveProbe", "CornerCutter", "PROBES", "make_probe", "run_episode", "HEADINGS", "MARGIN",
           "TRACKER_LOOKAHEAD"]

#: Candidate headings of the reactive probe (evenly spaced over the full circle, 0 = straight ahead).
HEADINGS = 72
#: Gap (m) the reactive probe keeps free on each side of its footprint along a candidate heading.
MARGIN = 0.06
#: Lookahead (m) of the corner-cutting tracker (the path follower's is 0.15).
TRACKER_LOOKAHEAD = 0.8


class ReactiveProbe:
    """Goal seeking with local obstacle avoidance from the lidar (see the module's docstring).

    ``beam_angles`` are the scan's angles (rad, counter-clockwise from the heading; a sector's is the mean
    of its beams'), ``radius`` the robot's (m), ``range_max`` the lidar's; speeds within ``v_max``, ``w_max``.
    """

    def __init__(self, beam_angles, radius: float, range_max: float, v_max: float, w_max: float,
                 horizon: float = 1.5, gain: float = 2.5, turn_in_place: float = 0.5, brake: float = 0.6):
        a = np.asarray(beam_angles, dtype=float)
        self.cos, self.sin = np.cos(a), np.sin(a)
        self.radius, self.range_max = float(radius), float(range_max)
        self.v_max, self.w_max = float(v_max), float(w_max)
        self.horizon, self.gain, self.turn_in_place, self.brake = float(horizon), float(gain), float(turn_in_place), float(brake)
        self.headings = (np.arange(HEADINGS) - HEADINGS // 2) * (2.0 * math.pi / HEADINGS)  # includes 0

    @classmethod
    def for_env(cls, env, **kwargs) -> "ReactiveProbe":
        """A probe for ``env``'s lidar, robot and action limits (call after ``reset``: it reads the robot's radius)."""
        env = env.unwrapped
        angles = np.asarray(env.lidar.angles, dtype=float)
        if env.lidar.sectors:
            angles = angles.reshape(env.lidar.sectors, -1).mean(axis=1)
        return cls(angles, env.world.robot.radius, env.config.lidar_range_max, float(env.action_space.high[0]),
                   float(env.action_space.high[1]), **kwargs)

    def free(self, scan: np.ndarray) -> np.ndarray:
        """(HEADINGS,) free distance (m) a disc of radius + MARGIN can travel along each candidate heading."""
        r = np.asarray(scan, dtype=float)
        hit = r < self.range_max - 1e-6  # a beam at range_max saw nothing
        px, py = r[hit] * self.cos[hit], r[hit] * self.sin[hit]
        ch, sh = np.cos(self.headings)[:, None], np.sin(self.headings)[:, None]
        along = px * ch + py * sh
        lateral = -px * sh + py * ch
        width = self.radius + MARGIN
        # Only points ahead block a heading: moving away from a point beside or behind never reaches it.
        inside = (np.abs(lateral) < width) & (along > 0.0)
        # The disc moving along the heading first touches a point at along - sqrt(width^2 - lateral^2).
        reach = along - np.sqrt(np.maximum(width * width - lateral * lateral, 0.0))
        return np.where(inside, reach, self.range_max).min(axis=1, initial=self.range_max)

    def action(self, obs) -> np.ndarray:
        """(v, w) as float32 from one observation of the environment."""
        obs = np.asarray(obs, dtype=float)
        scan, distance, bearing = obs[:-4], float(obs[-4]), float(obs[-3])
        free = self.free(scan)
        off = np.abs((self.headings - bearing + math.pi) % (2.0 * math.pi) - math.pi)
        # The heading nearest the goal's bearing, within a right angle of it, that is free for min(goal distance,
        # horizon); failing that, for half and a quarter of the horizon (a corridor's bend); else the freest
        # heading, nearer the bearing on a tie (it turns back only when nothing goal-ward is free).
        k = int(np.lexsort((off, -free))[0])
        for reach in (self.horizon, self.horizon / 2.0, self.horizon / 4.0):
            ok = (free >= min(distance, reach)) & (off <= math.pi / 2.0)
            if ok.any():
                k = int(np.argmin(np.where(ok, off, np.inf)))
                break
        err = float(self.headings[k])
        w = float(np.clip(self.gain * err, -self.w_max, self.w_max))
        if abs(err) > self.turn_in_place:
            return np.array([0.0, w], dtype=np.float32)
        ahead = float(free[HEADINGS // 2])  # heading 0
        v = self.v_max * math.cos(err) * min(1.0, max(ahead, 0.0) / self.brake)
        return np.array([max(min(v, distance), 0.0), w], dtype=np.float32)


class CornerCutter(PathFollower):
    """The path follower with a :data:`TRACKER_LOOKAHEAD` m lookahead: it cuts corners (see the module)."""

    def __init__(self, waypoints, v_max: float, w_max: float, lookahead: float = TRACKER_LOOKAHEAD, **kwargs):
        super().__init__(waypoints, v_max, w_max, lookahead=lookahead, **kwargs)


#: The probes' names (:func:`make_probe`).
PROBES = ("reactive", "tracker")


def make_probe(name: str, env) -> Callable:
    """``act(env, obs) -> action`` of the probe ``name`` for ``env``'s current episode (after its reset)."""
    from worldgen.errors import ParameterError

    if name == "reactive":
        reactive = ReactiveProbe.for_env(env)
        return lambda _env, obs: reactive.action(obs)
    if name == "tracker":
        tracker = CornerCutter.for_env(env)
        return lambda e, _obs: tracker.action(*e.unwrapped.robot_pose)
    raise ParameterError(f"parameter 'probe' must be one of {', '.join(PROBES)}, got {name!r}")


def run_episode(env, probe: str, **reset) -> dict:
    """Reset ``env`` (``reset`` goes to ``env.reset``), drive it with ``probe`` to the episode's end; the end's info
    (with the reset's keys)."""
    obs, first = env.reset(**reset)
    act = make_probe(probe, env)
    while True:
        obs, _, terminated, truncated, info = env.step(act(env, obs))
        if terminated or truncated:
            return {**first, **info}
