"""The certificate among people: a timed path along the proven static path that no person comes near.

Method (docs/people.md): the robot keeps to its task's proven static path (its polyline, which
keeps ``robot.clearance`` from every obstacle) and only chooses *when* to be where along it. Arc
length is cut into cells ``ds = max_speed x DT / CELLS_PER_STEP`` (the last one shorter, ending at
the goal), time into steps of :data:`DT`; a cell is blocked at a step when the robot's centre
there is closer than ``robot.inflation + person radius + margin`` to any person's centre, with
``margin = MARGIN + w DT / 2`` and ``w`` the robot's top speed plus the fastest any person walks:
two positions that far apart at both ends of a step cannot come closer than ``inflation + radius
+ MARGIN`` in between, the robot moving along its path at constant speed. The robot may wait,
go ahead or back by up to ``CELLS_PER_STEP`` cells a step (so never faster than ``max_speed``);
a forward sweep over the steps keeps the set of cells it can be in (a dilation, then the
step's free cells), and the first step the goal's cell is reachable is the arrival time. The
path is read back from the stored sets.

The arrival time is optimal only among such profiles along this one static path at this
resolution; another route round the people, or a finer grid, could arrive earlier. It is an
upper bound on the earliest arrival, and the timed path a checkable witness (world.json's
``tasks[].timed_path``), not the optimum.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace
from typing import Optional, Sequence

import numpy as np

from worldgen.feasibility.report import Check, FeasibilityReport
from worldgen.scene.motion import positions_at

__all__ = ["DT", "CELLS_PER_STEP", "MARGIN", "TimedPath", "timed_path", "person_speed", "certify"]

#: Time step (s) of the sweep, and the largest one between two rows of a timed path.
DT = 0.05
#: Cells the robot may cover in one step at full speed.
CELLS_PER_STEP = 2
#: Distance (m) kept beyond contact at every instant, over and above the sampling bound.
MARGIN = 0.01
#: Time (s) the sweep goes on after the last person stops, beyond the time the path takes.
AFTER = 5.0


@dataclass(frozen=True, eq=False)
class TimedPath:
    """``rows`` (k, 3) of t, x, y (t from 0, strictly increasing; straight between rows at constant
    speed); ``arrival`` the last row's time (s)."""

    rows: np.ndarray
    arrival: float


def person_speed(tracks: Sequence[np.ndarray]) -> float:
    """The fastest any person walks between two rows of its (k, 3) ``t, x, y`` track, m/s."""
    best = 0.0
    for traj in tracks:
        d = np.diff(traj, axis=0)
        if len(d):
            best = max(best, float(np.max(np.hypot(d[:, 1], d[:, 2]) / d[:, 0])))
    return best


def timed_path(waypoints: np.ndarray, tracks: Sequence[np.ndarray], radii: Sequence[float], inflation: float,
               max_speed: float) -> Optional[TimedPath]:
    """The earliest timed path along ``waypoints`` (k, 2) at up to ``max_speed`` that keeps the robot's
    disc (``inflation``) and every person's (its (m, 3) track, not looping, and radius) apart, or None."""
    w = np.asarray(waypoints, dtype=float).reshape(-1, 2)
    seg = np.hypot(*np.diff(w, axis=0).T)
    cum = np.concatenate([[0.0], np.cumsum(seg)])
    length = float(cum[-1])
    ds = max_speed * DT / CELLS_PER_STEP
    n_cells = max(1, math.ceil(length / ds - 1e-9))
    s = np.minimum(np.arange(n_cells + 1) * ds, length)
    xy = _at(w, cum, s)
    end = max((float(t[-1, 0]) for t in tracks), default=0.0)
    steps = math.ceil((end + length / max_speed + AFTER) / DT)
    times = np.arange(steps + 1) * DT
    reach = np.asarray(radii, dtype=float) + inflation + MARGIN + (max_speed + person_speed(tracks)) * DT / 2
    free = _free_cells(w, cum, s, xy, tracks, reach, times)
    sets = np.zeros((steps + 1, n_cells + 1), dtype=bool)
    sets[0, 0] = free[0, 0]
    k_goal = None
    for k in range(1, steps + 1):
        prev = sets[k - 1]
        if not prev.any():
            return None
        c = np.concatenate([[0], np.cumsum(prev)])
        i = np.arange(n_cells + 1)
        near = c[np.minimum(i + CELLS_PER_STEP + 1, n_cells + 1)] - c[np.maximum(i - CELLS_PER_STEP, 0)]
        sets[k] = (near > 0) & free[k]
        if sets[k, n_cells]:
            k_goal = k
            break
    if k_goal is None:
        return None
    cells = [n_cells]
    for k in range(k_goal, 0, -1):
        i = cells[-1]
        lo, hi = max(0, i - CELLS_PER_STEP), min(n_cells, i + CELLS_PER_STEP)
        options = np.flatnonzero(sets[k - 1, lo:hi + 1]) + lo
        cells.append(int(options[np.argmin(np.abs(options - i))]))  # wait where it can, else move least
    profile = s[np.array(cells[::-1])]
    return TimedPath(_rows(w, cum, times[: k_goal + 1], profile), k_goal * DT)


def certify(report: FeasibilityReport, scene, tasks, robot, max_speed: float) -> FeasibilityReport:
    """``report`` with the check ``timed_path`` and each task's certificate among the scene's people.

    A task without a static path has no certificate either; the check fails then, and where the
    people leave the robot no way through along its path (its value: the latest arrival, s).
    """
    people = [m for m in scene.movers if m.person]
    tracks = [np.asarray(m.trajectory, dtype=float) for m in people]
    radii = [m.radius for m in people]
    found, missing = [], []
    for task, path in zip(tasks, report.paths):
        timed = None if path is None else timed_path(path.waypoints, tracks, radii, robot.inflation, max_speed)
        found.append(timed)
        if timed is None:
            why = "no static path" if path is None else f"the people leave no way through at <= {max_speed:g} m/s"
            missing.append(f"{task.id}: {why}")
    if missing:
        check = Check("timed_path", False, None, "no timed path among the people for " + "; ".join(missing))
    else:
        latest = max(t.arrival for t in found)
        check = Check("timed_path", True, latest,
                      f"{len(found)} timed path(s) among {len(people)} people, latest arrival {latest:.2f} s")
    return replace(report, checks=report.checks + (check,), timed_paths=tuple(found))


def _at(w: np.ndarray, cum: np.ndarray, s: np.ndarray) -> np.ndarray:
    """(m, 2) the points at arc lengths ``s`` along the polyline."""
    return np.column_stack([np.interp(s, cum, w[:, 0]), np.interp(s, cum, w[:, 1])])


def _free_cells(w, cum, s, xy, tracks, reach, times) -> np.ndarray:
    """(steps + 1, cells) bool: no person within its ``reach`` of the cell's point at the step's time.

    Only (step, person) pairs within reach of the polyline are looked at; each blocks the cells
    whose arc length falls inside the circle's chords on the path's segments (exact, then marked
    through a difference array)."""
    n_t, n_s = len(times), len(s)
    marks = np.zeros((n_t, n_s + 1), dtype=np.int32)
    if not len(tracks):
        return np.ones((n_t, n_s), dtype=bool)
    pos = positions_at(list(tracks), [False] * len(tracks), times)  # (n_t, people, 2)
    a, b = w[:-1], w[1:]
    d = b - a
    dd = np.maximum(np.einsum("ij,ij->i", d, d), 1e-300)
    for j in range(pos.shape[1]):
        p = pos[:, j, :]
        r2 = reach[j] ** 2
        # Circle-segment chords: |a + u d - p|^2 = r^2, u in [0, 1], for every step and segment.
        ap = a[None, :, :] - p[:, None, :]
        bq = np.einsum("tsk,sk->ts", ap, d)
        cq = np.einsum("tsk,tsk->ts", ap, ap) - r2
        disc = bq * bq - dd[None] * cq
        t_idx, seg_idx = np.nonzero(disc > 0)
        if not len(t_idx):
            continue
        root = np.sqrt(disc[t_idx, seg_idx])
        u0 = np.maximum((-bq[t_idx, seg_idx] - root) / dd[seg_idx], 0.0)
        u1 = np.minimum((-bq[t_idx, seg_idx] + root) / dd[seg_idx], 1.0)
        keep = u0 <= u1
        t_idx, seg_idx, u0, u1 = t_idx[keep], seg_idx[keep], u0[keep], u1[keep]
        seg_len = np.sqrt(dd[seg_idx])
        s0 = cum[seg_idx] + u0 * seg_len
        s1 = cum[seg_idx] + u1 * seg_len
        # Cells with s0 <= s <= s1 (closed: a cell on the circle counts as blocked).
        first = np.searchsorted(s, s0 - 1e-12, side="left")
        last = np.searchsorted(s, s1 + 1e-12, side="right")
        hit = last > first
        np.add.at(marks, (t_idx[hit], first[hit]), 1)
        np.add.at(marks, (t_idx[hit], last[hit]), -1)
    return np.cumsum(marks, axis=1)[:, :n_s] == 0


def _rows(w: np.ndarray, cum: np.ndarray, times: np.ndarray, profile: np.ndarray) -> np.ndarray:
    """(k, 3) t, x, y rows: the profile's samples, the polyline's corners crossed between two of them
    (at the time the robot passes them), and nothing a straight constant-speed leg already says."""
    t_out, s_out = [times[0]], [profile[0]]
    for k in range(1, len(times)):
        s0, s1 = profile[k - 1], profile[k]
        corners = cum[(cum > min(s0, s1)) & (cum < max(s0, s1))]
        if s1 < s0:
            corners = corners[::-1]
        for c in corners:
            t_out.append(times[k - 1] + (c - s0) / (s1 - s0) * (times[k] - times[k - 1]))
            s_out.append(c)
        t_out.append(times[k])
        s_out.append(s1)
    t_arr, s_arr = np.array(t_out), np.array(s_out)
    pts = _at(w, cum, s_arr)
    rows = np.column_stack([t_arr, pts])
    # Drop a row where the velocity before and after it is the same and it is no corner.
    vel = np.diff(pts, axis=0) / np.diff(t_arr)[:, None]
    same = np.all(np.abs(vel[1:] - vel[:-1]) < 1e-9, axis=1)
    is_corner = np.isin(s_arr[1:-1], cum)
    keep = np.r_[True, ~same | is_corner, True]
    return rows[keep]
