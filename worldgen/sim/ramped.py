"""Following a schedule on a robot whose speed and turn rate ramp: Gazebo's, whose DiffDrive changes its wheels'
speed at most at their acceleration (worldgen.export.robot), where MuJoCo's servos take a twist at once.

The environment's :class:`~worldgen.envs.policies.TimedFollower` heads for where the schedule is a command
(0.05 s) ahead and stands to turn when that point lies more than 0.3 rad off its heading. A robot that takes
its twist at once keeps within 1 cm of a schedule so (MuJoCo). A ramped one does not: at the schedule's slow
speeds that point is millimetres away, a centimetre off the path puts it far off the heading, and the robot
stands, turns, falls behind and swings past (on barn seed 22 in Harmonic: up to 0.25 m behind, 17 to 20 rad of
turning where MuJoCo's robot turned 9; a unicycle with the DiffDrive's ramps, 0.48 m over bench_drive_dynamic's
first 25 schedules). :func:`ramped_follower` instead asks the schedule's own speed (feed-forward) plus a
correction for the distance behind it, and heads for where the schedule is :data:`LEAD` later, which a
centimetre aside barely turns; where that point is near (the schedule waits or turns on the spot) it faces
the schedule's next movement. Every rate is asked no faster than the robot can stop from (:func:`braked`).
"""

from __future__ import annotations

import math
from typing import Callable, Optional

import numpy as np

from worldgen.envs.policies import TimedFollower

__all__ = ["LEAD", "NEAR", "GAIN_ALONG", "GAIN_TURN", "TURN_LIMIT", "BRAKING", "braked", "ramped_follower"]

#: s: the robot heads for where its schedule is this much later.
LEAD = 0.3
#: m: nearer than this to that point, the robot faces the schedule's next movement instead (heading for a
#: point millimetres away would only jitter).
NEAR = 0.03
#: 1/s: m/s of speed added for each m the robot is behind its schedule along its heading (taken off ahead).
GAIN_ALONG = 3.0
#: 1/s: rad/s of turn asked for each rad off the aim.
GAIN_TURN = 5.0
#: rad: further off its aim than this the robot stands and turns.
TURN_LIMIT = 1.0
#: The share of a robot's turn acceleration :func:`braked` plans to stop a turn with (the rest covers a command's
#: late start: the rate is set once a command).
BRAKING = 0.8


def braked(w: float, err: float, turn_accel: Optional[float]) -> float:
    """A rate ``w`` (a turn rate, or a speed) toward something ``err`` away (rad, or m), no faster than a robot
    whose rate changes at most :data:`BRAKING` x ``turn_accel`` (rad/s^2, or m/s^2) can stop from there
    (``w`` itself with no limit).

    Gazebo's DiffDrive ramps the twist it is told at its wheels' acceleration (worldgen.export.robot), so a
    follower that asks 8 rad/s until it faces its target swings on past it (a 0.2 m robot turns at most
    19.2 rad/s^2 faster or slower: from 8 rad/s it needs 1.7 rad to stop); catching up at 0.75 m/s with a
    schedule that stops, a robot once ran 7 cm past (barn seed 2 among movers, into an obstacle the schedule
    passes 5 cm from)."""
    if turn_accel is None:
        return w
    return math.copysign(min(abs(w), math.sqrt(2.0 * BRAKING * turn_accel * abs(err))), w)


def ramped_follower(rows: np.ndarray, v_max: float, w_max: float, period: float, turn_accel: Optional[float],
                    accel: Optional[float]) -> Callable[[float, float, float, float], tuple[float, float]]:
    """``(t, x, y, yaw) -> (v, w)`` following the ``t, x, y`` schedule ``rows`` (t the simulator's time) with
    commands ``period`` s apart, within ``v_max`` (m/s) and ``w_max`` (rad/s), on a robot whose turn rate and
    speed change at most ``turn_accel`` (rad/s^2) and ``accel`` (m/s^2; None: not limited). The speed is
    also asked no faster than lets the robot stop where the schedule next stands still (a wait, the goal)."""
    timed = TimedFollower(rows, v_max=v_max, w_max=w_max, period=period)
    step = np.hypot(*np.diff(rows[:, 1:], axis=0).T)
    stops = np.append(np.flatnonzero(step < 1e-6), len(rows) - 1)  # rows the schedule stands still from

    def act(t: float, x: float, y: float, yaw: float) -> tuple[float, float]:
        now, end = timed.at(t), timed.at(t + period)
        # the schedule's speed at the command's end: what the ramp should reach by then
        ahead = float(np.hypot(*(timed.at(t + 2.0 * period) - end))) / period
        behind = (now[0] - x) * math.cos(yaw) + (now[1] - y) * math.sin(yaw)
        dx, dy = timed.at(t + LEAD) - (x, y)
        aim = math.atan2(dy, dx) if math.hypot(dx, dy) > NEAR else timed.next_heading(t)
        err = 0.0 if aim is None else (aim - yaw + math.pi) % (2.0 * math.pi) - math.pi
        v = 0.0 if abs(err) > TURN_LIMIT else min(v_max, max(0.0, ahead * math.cos(err) + GAIN_ALONG * behind))
        stop = rows[stops[np.searchsorted(rows[stops, 0], t)] if t <= rows[-1, 0] else -1, 1:]
        v = braked(v, float(np.hypot(*(stop - (x, y)))), accel)
        return v, braked(float(np.clip(GAIN_TURN * err, -w_max, w_max)), err, turn_accel)

    return act
