"""A unicycle at stated limits driving a timed path, written apart from the code that makes the path.

The robot is a point with a heading; each small step ``h`` it asks for the speed and turn rate that
keep it on the schedule, and gets them clipped to ``|w| <= turn_rate``, ``0 <= v <= max_speed`` and
``|v - v_before| <= acceleration h``: what a differential-drive base can do. Its steering is simple on
purpose: it faces where the schedule goes next (turning on the spot while that lies off its heading and
the schedule stands; turning on the move where the schedule passes a small corner without stopping), and
its speed is the schedule's, plus a pull toward the scheduled point.
"""

from __future__ import annotations

import math

import numpy as np

from worldgen.people.corners import CUT_ANGLE

__all__ = ["drive"]


def _at(rows: np.ndarray, t: float) -> np.ndarray:
    return np.array([np.interp(t, rows[:, 0], rows[:, 1]), np.interp(t, rows[:, 0], rows[:, 2])])


def _next_heading(rows: np.ndarray, t: float, fallback: float) -> float:
    """The direction of the schedule's next movement after ``t`` (``fallback`` where none is left)."""
    k = int(np.searchsorted(rows[:, 0], t, side="right")) - 1
    for j in range(max(k, 0), len(rows) - 1):
        d = rows[j + 1, 1:] - rows[j, 1:]
        if math.hypot(*d) > 1e-9:
            return math.atan2(d[1], d[0])
    return fallback


def drive(rows, yaw0: float, max_speed: float, turn_rate: float, acceleration: float, h: float = 0.001,
          gain: float = 4.0) -> np.ndarray:
    """(n, 4) t, x, y, yaw of the unicycle from the schedule's first row facing ``yaw0`` to its last row."""
    rows = np.asarray(rows, dtype=float).reshape(-1, 3)
    x, y = rows[0, 1:]
    yaw, v = float(yaw0), 0.0
    out = []
    t = 0.0
    end = float(rows[-1, 0])
    while t <= end + 1e-12:
        out.append((t, x, y, yaw))
        want = _next_heading(rows, t, yaw)
        err = (want - yaw + math.pi) % (2 * math.pi) - math.pi
        w = max(-turn_rate, min(turn_rate, err / h))
        # The schedule's speed now, and a pull along the heading toward where it has the robot.
        here = _at(rows, t)
        ahead = _at(rows, t + h)
        v_ref = math.hypot(*(ahead - here)) / h
        lag = float(np.dot(here - np.array([x, y]), [math.cos(yaw), math.sin(yaw)]))
        # Off its heading it stands to turn, unless the schedule itself moves on through a small corner: then
        # it turns on the move (docs/people.md, corners passed moving).
        on_the_move = v_ref > 1e-9 and abs(err) <= CUT_ANGLE + 1e-3
        target = 0.0 if abs(err) > 1e-3 and not on_the_move else v_ref + gain * lag
        target = max(0.0, min(max_speed, target))
        v = max(v - acceleration * h, min(v + acceleration * h, target))
        x, y = x + v * h * math.cos(yaw), y + v * h * math.sin(yaw)
        yaw += w * h
        t += h
    return np.array(out)
