"""The certificate among people: a timed path along the proven static path that no person comes near.

Method (docs/people.md): the robot keeps to its task's proven static path (its polyline, which
keeps ``robot.clearance`` from every obstacle) and only chooses *when* to be where along it. Each
leg of the polyline is cut into equal cells no longer than ``ds = 0.999 max_speed x DT /
CELLS_PER_STEP`` (so every corner is a cell), time into steps of :data:`DT`; a cell is blocked at a
step when the robot's centre there is closer than ``robot.inflation + person radius + margin`` to
any person's centre, with ``margin = MARGIN + w DT / 2`` and ``w`` the robot's top speed plus the
fastest any person walks: two positions that far apart at both ends of a step cannot come closer
than ``inflation + radius + MARGIN`` in between, each moving straight at constant speed. In a step
the robot may wait, or go ahead or back by up to ``CELLS_PER_STEP`` cells of one leg (a corner is
passed at a step's end), so it never leaves the path nor goes faster than ``max_speed`` (the 0.1 %
spare pays for the 6-decimal rounding of the rows). A forward sweep over the steps keeps the set of
cells it can be in (a dilation, then the step's free cells); the first step the goal's cell is
reachable is the arrival time, and the path is read back from the stored sets.

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
from worldgen.people.behaviours import Tube, tube_of
from worldgen.scene.motion import positions_at

__all__ = ["DT", "CELLS_PER_STEP", "MARGIN", "SPARE", "TimedPath", "timed_path", "person_speed", "certify", "tube_steps"]

#: Time step (s) of the sweep, and the largest one between two rows of a timed path.
DT = 0.05
#: Cells the robot may cover in one step at full speed.
CELLS_PER_STEP = 2
#: Distance (m) kept beyond contact at every instant, over and above the sampling bound.
MARGIN = 0.01
#: Share of the top speed the cells leave spare, for the rounding of the written rows.
SPARE = 1e-3
#: Time (s) the sweep goes on after the last person stops, beyond the time the path takes.
AFTER = 5.0
#: Steps whose free cells are worked out at once (6.4 s): the sweep rarely needs all of them.
FREE_CHUNK = 128


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
               max_speed: float, tubes: Optional[Sequence[Tube]] = None) -> Optional[TimedPath]:
    """The earliest timed path along ``waypoints`` (k, 2) at up to ``max_speed`` that keeps the robot's
    disc (``inflation``) and every person's (its (m, 3) track, not looping, and radius) apart, or None.

    ``tubes`` (one per person, default the recorded line): the robot keeps clear of the whole tube, every
    recorded position from ``t - tau`` to ``t + tau`` widened by ``d`` (:func:`_free_cells`)."""
    w = np.asarray(waypoints, dtype=float).reshape(-1, 2)
    s, corner = _cells(w, max_speed * DT / CELLS_PER_STEP * (1 - SPARE))
    cum = np.concatenate([[0.0], np.cumsum(np.hypot(*np.diff(w, axis=0).T))])
    length = float(cum[-1])
    n_cells = len(s) - 1
    i = np.arange(n_cells + 1)
    # Each cell's window: up to CELLS_PER_STEP cells either way, not past a corner (a corner cell reaches
    # into both of its legs). The relation is symmetric, so it serves both the sweep and the read-back.
    before = corner[np.maximum(np.searchsorted(corner, i, side="left") - 1, 0)]
    after = corner[np.minimum(np.searchsorted(corner, i, side="right"), len(corner) - 1)]
    on_corner = np.isin(i, corner)
    lo = np.maximum(i - CELLS_PER_STEP, np.where(on_corner, before, corner[np.searchsorted(corner, i, side="right") - 1]))
    hi = np.minimum(i + CELLS_PER_STEP, np.where(on_corner, after, corner[np.searchsorted(corner, i, side="left")]))
    lo[0], hi[-1] = 0, n_cells
    end = max((float(t[-1, 0]) for t in tracks), default=0.0)
    steps = math.ceil((end + length / max_speed + AFTER) / DT)
    times = np.arange(steps + 1) * DT
    reach = np.asarray(radii, dtype=float) + inflation + MARGIN + (max_speed + person_speed(tracks)) * DT / 2
    tubes = list(tubes) if tubes is not None else [Tube(0.0, 0.0)] * len(tracks)
    reach = reach + np.array([tube.d for tube in tubes], dtype=float).reshape(len(tracks))
    window = np.array([tube_steps(tube.tau) for tube in tubes], dtype=np.int64).reshape(len(tracks))
    # Which cells are free at which step, worked out a chunk of steps at a time as the sweep gets there:
    # the sweep usually stops long before the last person stops (each row depends on its step alone).
    free = np.zeros((steps + 1, n_cells + 1), dtype=bool)
    known = 0
    sets = np.zeros((steps + 1, n_cells + 1), dtype=bool)
    k_goal = None
    for k in range(0, steps + 1):
        if k == known:
            known = min(k + FREE_CHUNK, steps + 1)
            free[k:known] = _free_cells(w, cum, s, tracks, reach, times[k:known], window)
        if k == 0:
            sets[0, 0] = free[0, 0]
            continue
        prev = sets[k - 1]
        if not prev.any():
            return None
        c = np.concatenate([[0], np.cumsum(prev)])
        sets[k] = (c[hi + 1] - c[lo] > 0) & free[k]
        if sets[k, n_cells]:
            k_goal = k
            break
    if k_goal is None:
        return None
    cells = [n_cells]
    for k in range(k_goal, 0, -1):
        j = cells[-1]
        options = np.flatnonzero(sets[k - 1, lo[j]:hi[j] + 1]) + lo[j]
        cells.append(int(options[np.argmin(np.abs(options - j))]))  # wait where it can, else move least
    profile = s[np.array(cells[::-1])]
    return TimedPath(_rows(w, cum, times[: k_goal + 1], profile), k_goal * DT)


def _cells(w: np.ndarray, ds: float) -> tuple[np.ndarray, np.ndarray]:
    """(arc length of every cell (m,), the cell index of every corner, spawn and goal included): each leg
    cut into equal cells no longer than ``ds``."""
    seg = np.hypot(*np.diff(w, axis=0).T)
    cum = np.concatenate([[0.0], np.cumsum(seg)])
    parts = [np.zeros(1)]
    corner = [0]
    for q, length in enumerate(seg):
        n = max(1, math.ceil(length / ds - 1e-9))
        parts.append(cum[q] + np.arange(1, n + 1) * (length / n))
        parts[-1][-1] = cum[q + 1]
        corner.append(corner[-1] + n)
    return np.concatenate(parts), np.array(corner)


def certify(report: FeasibilityReport, scene, tasks, robot, max_speed: float,
            behaviours: Optional[Sequence[str]] = None) -> FeasibilityReport:
    """``report`` with the check ``timed_path`` and each task's certificate among the scene's people.

    A task without a static path has no certificate either; the check fails then, and where the
    people leave the robot no way through along its path (its value: the latest arrival, s).
    """
    people = [m for m in scene.movers if m.person]
    tracks = [np.asarray(m.trajectory, dtype=float) for m in people]
    radii = [m.radius for m in people]
    tubes = [tube_of(b) for b in behaviours] if behaviours is not None else None
    found, missing = [], []
    for task, path in zip(tasks, report.paths):
        timed = None if path is None else timed_path(path.waypoints, tracks, radii, robot.inflation, max_speed, tubes)
        found.append(timed)
        if timed is None:
            why = "no static path" if path is None else f"the people leave no way through at <= {max_speed:g} m/s"
            missing.append(f"{task.id}: {why}")
    if missing:
        check = Check("timed_path", False, None, "no timed path among the people for " + "; ".join(missing))
    else:
        latest = max(t.arrival for t in found if t is not None)  # none missing: all found
        check = Check("timed_path", True, latest,
                      f"{len(found)} timed path(s) among {len(people)} people, latest arrival {latest:.2f} s")
    return replace(report, checks=report.checks + (check,), timed_paths=tuple(found))


def _at(w: np.ndarray, cum: np.ndarray, s: np.ndarray) -> np.ndarray:
    """(m, 2) the points at arc lengths ``s`` along the polyline."""
    return np.column_stack([np.interp(s, cum, w[:, 0]), np.interp(s, cum, w[:, 1])])


def tube_steps(tau: float) -> int:
    """Steps either side of a step whose recorded positions its tube of ``tau`` s must keep clear of: every
    time within ``tau`` of an instant between this step and the next half-way is within DT / 2 of one of
    them (0 for the recorded line itself, whose instant is within DT / 2 of the step)."""
    return 0 if tau <= 0 else math.ceil(tau / DT + 0.5 - 1e-9)


def _free_cells(w, cum, s, tracks, reach, times, window=None) -> np.ndarray:
    """(steps + 1, cells) bool: no person's recorded position within ``window`` steps of the step (its
    tube's, :func:`tube_steps`) within its ``reach`` of the cell's point.

    People with the same window are taken together: the cells they block at the steps from ``window``
    before the first to ``window`` after the last, then each step blocked where any of its window is.
    """
    window = np.zeros(len(tracks), dtype=np.int64) if window is None else window
    free = np.ones((len(times), len(s)), dtype=bool)
    for m in np.unique(window):
        who = np.flatnonzero(window == m)
        m = int(m)
        ext = np.concatenate([times[0] - DT * np.arange(m, 0, -1), times, times[-1] + DT * np.arange(1, m + 1)])
        blocked = ~_free_at(w, cum, s, [tracks[j] for j in who], reach[who], ext)
        if m:
            c = np.concatenate([np.zeros((1, len(s)), dtype=np.int32), np.cumsum(blocked, axis=0, dtype=np.int32)])
            blocked = (c[2 * m + 1:] - c[:-2 * m - 1]) > 0
        free &= ~blocked
    return free


def _free_at(w, cum, s, tracks, reach, times) -> np.ndarray:
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
    """(k, 3) t, x, y rows of the profile's samples (every corner is one: corners are passed at a
    step's end), less those a straight constant-speed leg between their neighbours already says."""
    pts = _at(w, cum, profile)
    rows = np.column_stack([times, pts])
    vel = np.diff(pts, axis=0) / np.diff(times)[:, None]
    same = np.all(np.abs(vel[1:] - vel[:-1]) < 1e-9, axis=1)
    keep = np.r_[True, ~same, True]
    return rows[keep]
