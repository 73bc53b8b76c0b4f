"""How far the lazy planner's nodes need to look: lower bounds on a path through a node by each obstacle
next, and the band of obstacles a node asks tangents to at once (:mod:`~worldgen.feasibility.planner`).

A node at ``p``, reached at cost ``g``, asks for tangents to an obstacle only once the search's key
reaches that obstacle's bound: no path through the node that goes on by the obstacle can be shorter.
"""

from __future__ import annotations

import numpy as np

from worldgen.feasibility.cspace import ConfigSpace

__all__ = ["MIN_BATCH", "lower_bounds", "next_band"]

#: At least this many obstacles per request, so that one request covers the obstacles just beyond it.
MIN_BATCH = 8


def lower_bounds(cs: ConfigSpace, goal: np.ndarray, points: np.ndarray, g: np.ndarray,
                 circles: np.ndarray) -> np.ndarray:
    """(k, N) per node (at ``points`` (k, 2), cost ``g`` (k,), on ``circles`` (k,), -1 for the start): a lower
    bound on the length of any path through it whose next obstacle is each one (inf for its own).

    The path goes on through a point x of the obstacle's bounding disc (centre c,
    radius r), so it is at least g + |p - x| + |x - goal|, which is at least both
    |p - c| + |c - goal| - 2 r and, for x at distance d >= (distance from c to the
    line p-goal) - r from that line, 2 sqrt((|p - goal| / 2)^2 + d^2).
    """
    p = points[:, None, :]
    g = g[:, None]
    c = cs.hull_c[None, :, :]
    d = c - p
    to_c = np.sqrt(d[..., 0] ** 2 + d[..., 1] ** 2)
    c_goal = np.hypot(cs.hull_c[:, 0] - goal[0], cs.hull_c[:, 1] - goal[1])[None, :]
    via = to_c + c_goal - 2 * cs.hull_r[None, :]
    u = goal[None, None, :] - p
    span = np.sqrt(u[..., 0] ** 2 + u[..., 1] ** 2)
    off = np.abs(d[..., 0] * u[..., 1] - d[..., 1] * u[..., 0]) / np.maximum(span, 1e-300)
    off = np.maximum(off - cs.hull_r[None, :], 0.0)
    via = np.maximum(via, np.where(span > 0, 2 * np.sqrt(span * span / 4 + off * off), 0.0))
    lb = g + np.maximum(via, span)
    for k, circle in enumerate(circles.tolist()):
        if circle >= 0:
            lb[k, cs.owner[circle]] = np.inf
    return lb


def next_band(lb: np.ndarray, done: float, hi: float) -> tuple[np.ndarray, float]:
    """The obstacles whose bound ``lb`` (N,) lies in (``done``, ``hi``], at least :data:`MIN_BATCH` of them
    when there are; and the bound up to which obstacles are then taken."""
    todo = lb > done
    chosen = np.flatnonzero(todo & (lb <= hi))
    if len(chosen) < MIN_BATCH:
        rest = np.flatnonzero(todo & np.isfinite(lb))
        if len(rest) <= MIN_BATCH:
            chosen = rest
        else:
            chosen = rest[np.argpartition(lb[rest], MIN_BATCH - 1)[:MIN_BATCH]]
    upto = max(hi, float(lb[chosen].max())) if len(chosen) else hi
    return chosen, upto
