"""Which cells of a path people block, step by step: the grid the timed certificate's sweep
(:mod:`worldgen.people.timed`) searches, a cell blocked at a step when a person (or the tube round its
recorded walk) is within reach of the cell's point on the path."""

from __future__ import annotations

import math

import numpy as np

from worldgen.scene.motion import positions_at

__all__ = ["steps_within", "free_cells", "free_at"]


def steps_within(tau: float, dt: float) -> int:
    """Steps either side of a step whose recorded positions its tube of ``tau`` s must keep clear of: every
    time within ``tau`` of an instant between this step and the next half-way is within dt / 2 of one of
    them (0 for the recorded line itself, whose instant is within dt / 2 of the step)."""
    return 0 if tau <= 0 else math.ceil(tau / dt + 0.5 - 1e-9)


def free_cells(w, cum, s, tracks, reach, times, dt: float, window=None, loops=None, extra=None) -> np.ndarray:
    """(steps + 1, cells) bool: no person's recorded position within ``window`` steps of the step (its
    tube's, :func:`steps_within`), for steps ``dt`` s apart within its ``reach`` of the cell's point.

    ``loops`` (one per track, default none) says which tracks repeat (a scripted mover's loop).
    People with the same window are taken together: the cells they block at the steps from ``window``
    before the first to ``window`` after the last, then each step blocked where any of its window is.
    ``extra`` (one per segment of the path, m): more reach on that segment (a corner passed moving).
    """
    window = np.zeros(len(tracks), dtype=np.int64) if window is None else window
    loops = np.zeros(len(tracks), dtype=bool) if loops is None else np.asarray(loops, dtype=bool).reshape(len(tracks))
    free = np.ones((len(times), len(s)), dtype=bool)
    for m in np.unique(window):
        who = np.flatnonzero(window == m)
        m = int(m)
        ext = np.concatenate([times[0] - dt * np.arange(m, 0, -1), times, times[-1] + dt * np.arange(1, m + 1)])
        blocked = ~free_at(w, cum, s, [tracks[j] for j in who], reach[who], ext, loops[who], extra)
        if m:
            c = np.concatenate([np.zeros((1, len(s)), dtype=np.int32), np.cumsum(blocked, axis=0, dtype=np.int32)])
            blocked = (c[2 * m + 1:] - c[:-2 * m - 1]) > 0
        free &= ~blocked
    return free


def free_at(w, cum, s, tracks, reach, times, loops=None, extra=None) -> np.ndarray:
    """(steps + 1, cells) bool: no person within its ``reach`` of the cell's point at the step's time
    (``loops``: which tracks repeat, default none).

    Only (step, person) pairs within reach of the polyline are looked at; each blocks the cells
    whose arc length falls inside the circle's chords on the path's segments (exact, then marked
    through a difference array)."""
    n_t, n_s = len(times), len(s)
    marks = np.zeros((n_t, n_s + 1), dtype=np.int32)
    if not len(tracks):
        return np.ones((n_t, n_s), dtype=bool)
    loops = [False] * len(tracks) if loops is None else [bool(x) for x in loops]
    pos = positions_at(list(tracks), loops, times)  # (n_t, agents, 2)
    a, b = w[:-1], w[1:]
    d = b - a
    dd = np.maximum(np.einsum("ij,ij->i", d, d), 1e-300)
    more = np.zeros(len(d)) if extra is None else np.asarray(extra, dtype=float)
    for j in range(pos.shape[1]):
        p = pos[:, j, :]
        r2 = ((reach[j] + more) ** 2)[None, :]
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
