"""Difficulty metrics after BARN's, computed exactly along the reference paths.

These are not BARN's numbers (those are :mod:`worldgen.groundtruth.barn`'s):
docs/metrics.md gives the definitions with formulas and says, metric by metric,
how and by how much they differ from BARN's (Perille et al. 2020). The obstacles are the floor shadows of
everything a robot can hit (:func:`worldgen.scene.footprint.robot_footprints`, walls
included) and the edge of the floor area (``scene.bounds``) counts as a wall.
Each task's path is sampled at :data:`SAMPLES` points evenly spaced by arc
length, ends included; from each sample :data:`DIRECTIONS` rays are cast in
2-D, exactly, against discs and polygon edges.
"""

from __future__ import annotations

import math
from typing import Optional, Sequence

import numpy as np
import shapely

from worldgen.scene.footprint import Footprint, robot_footprints

__all__ = ["difficulty", "path_samples", "ray_lengths", "SAMPLES", "DIRECTIONS", "DISPERSION_REACH", "NAMES"]

#: Samples per task path (arc-length spaced, both ends included).
SAMPLES = 50
#: Rays per sample, evenly spaced from angle 0: BARN's dispersion uses 16 too.
DIRECTIONS = 16
#: Dispersion looks this many inflation radii (robot.radius + clearance) around a sample.
DISPERSION_REACH = 4.0
NAMES = ("closest_obstacle_distance_mean", "average_visibility", "dispersion", "characteristic_dimension", "tortuosity")


def path_samples(waypoints: np.ndarray, count: int = SAMPLES) -> np.ndarray:
    """(count, 2) points evenly spaced by arc length along the polyline (k, 2), ends included."""
    w = np.asarray(waypoints, dtype=float).reshape(-1, 2)
    cum = np.r_[0.0, np.cumsum(np.hypot(*np.diff(w, axis=0).T))]
    if cum[-1] <= 0:
        return np.repeat(w[:1], count, axis=0)
    s = np.linspace(0.0, cum[-1], count)
    return np.column_stack([np.interp(s, cum, w[:, 0]), np.interp(s, cum, w[:, 1])])


def difficulty(scene, robot, tasks: Sequence, paths: Sequence) -> dict[str, Optional[float]]:
    """worldgen's five exact figures after BARN's (None each when no task has a path)."""
    found = [(t, p) for t, p in zip(tasks, paths) if p is not None]
    if not found:
        return {name: None for name in NAMES}
    prints = robot_footprints(scene, robot)
    pts = np.vstack([path_samples(p.waypoints) for _, p in found])
    theta = np.arange(DIRECTIONS) * (2 * math.pi / DIRECTIONS)
    dirs = np.column_stack([np.cos(theta), np.sin(theta)])
    lengths = ray_lengths(prints, scene.bounds, pts, dirs)  # (samples, directions)
    blocked = lengths < DISPERSION_REACH * robot.inflation
    half = DIRECTIONS // 2
    tortuosity = []
    for task, path in found:
        chord = math.hypot(task.goal.x - task.spawn.x, task.goal.y - task.spawn.y)
        tortuosity.append(path.length / chord if chord > 0 else 1.0)
    return {
        "closest_obstacle_distance_mean": float(np.mean(_clearance(prints, scene.bounds, pts))),
        "average_visibility": float(lengths.mean()),
        "dispersion": float(np.mean((blocked != np.roll(blocked, -1, axis=1)).sum(axis=1))),
        "characteristic_dimension": float(np.mean((lengths[:, :half] + lengths[:, half:]).min(axis=1))),
        "tortuosity": float(np.mean(tortuosity)),
    }


def _clearance(prints: list[Footprint], bounds, pts: np.ndarray) -> np.ndarray:
    """(n,) distance from each point to the nearest footprint or edge of the bounds."""
    (x0, y0), (x1, y1) = bounds
    best = np.minimum(np.minimum(pts[:, 0] - x0, x1 - pts[:, 0]), np.minimum(pts[:, 1] - y0, y1 - pts[:, 1]))
    discs = [fp for fp in prints if fp.is_disc]
    if discs:
        c = np.array([fp.centre for fp in discs])
        r = np.array([fp.radius for fp in discs])
        d = np.sqrt(((pts[:, None, :] - c[None]) ** 2).sum(axis=2)) - r
        best = np.minimum(best, d.min(axis=1))
    polygons = np.array([fp.polygon for fp in prints if not fp.is_disc], dtype=object)
    if len(polygons):
        d = shapely.distance(polygons[:, None], shapely.points(pts)[None, :])  # one call for all pairs
        best = np.minimum(best, d.min(axis=0))
    return np.maximum(best, 0.0)


def ray_lengths(prints: list[Footprint], bounds, origins: np.ndarray, dirs: np.ndarray) -> np.ndarray:
    """(n, k) distance from each origin (n, 2) along each unit direction (k, 2) to the first
    footprint boundary, or to the edge of the bounds where that comes first (0 from inside one)."""
    o = np.asarray(origins, dtype=float)
    d = np.asarray(dirs, dtype=float)
    (x0, y0), (x1, y1) = bounds
    with np.errstate(divide="ignore", invalid="ignore"):
        tx = np.where(d[:, 0] > 0, (x1 - o[:, 0, None]) / d[:, 0], np.where(d[:, 0] < 0, (x0 - o[:, 0, None]) / d[:, 0], np.inf))
        ty = np.where(d[:, 1] > 0, (y1 - o[:, 1, None]) / d[:, 1], np.where(d[:, 1] < 0, (y0 - o[:, 1, None]) / d[:, 1], np.inf))
    best = np.maximum(np.minimum(tx, ty), 0.0)
    discs = [fp for fp in prints if fp.is_disc]
    if discs:
        c = np.array([fp.centre for fp in discs])  # (m, 2)
        r = np.array([fp.radius for fp in discs])
        # |o + t d - c|^2 = r^2 with |d| = 1: t^2 + 2 b t + cc = 0, b = (o - c).d split into o.d - c.d.
        b = (o @ d.T)[:, :, None] - (d @ c.T)[None, :, :]  # (n, k, m)
        cc = (((o[:, None, :] - c[None]) ** 2).sum(axis=2) - r * r)[:, None, :]  # (n, 1, m)
        disc = b * b - cc
        with np.errstate(invalid="ignore"):
            t = -b - np.sqrt(disc)
        t = np.where((disc >= 0) & (t >= 0), t, np.where(cc <= 0, 0.0, np.inf))
        best = np.minimum(best, t.min(axis=2))
    loops = [np.asarray(fp.polygon.exterior.coords) for fp in prints if fp.polygon is not None]
    if loops:
        a = np.vstack([q[:-1] for q in loops])  # (m, 2) edge starts
        e = np.vstack([np.diff(q, axis=0) for q in loops])  # (m, 2) edge vectors
        # o + t d = a + u e; with x(p, q) = p_x q_y - p_y q_x:
        # t = x(a - o, e) / x(d, e), u = x(a - o, d) / x(d, e); each cross product split by linearity.
        den = d[:, 0, None] * e[:, 1] - d[:, 1, None] * e[:, 0]  # (k, m)
        ae = a[:, 0] * e[:, 1] - a[:, 1] * e[:, 0]  # (m,)
        oe = o[:, 0, None] * e[:, 1] - o[:, 1, None] * e[:, 0]  # (n, m)
        ad = a[:, 0] * d[:, 1, None] - a[:, 1] * d[:, 0, None]  # (k, m)
        od = o[:, 0, None] * d[:, 1] - o[:, 1, None] * d[:, 0]  # (n, k)
        with np.errstate(divide="ignore", invalid="ignore"):
            inv = 1.0 / den
            t = (ae - oe)[:, None, :] * inv
            u = (ad[None] - od[:, :, None]) * inv
        t = np.where((u >= 0) & (u <= 1) & (t >= 0), t, np.inf)  # den = 0 gives inf or nan: dropped
        best = np.minimum(best, t.min(axis=2))
    return best
