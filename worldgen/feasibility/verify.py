"""Prove a path with FCL: the footprint cylinder, sampled densely along it, keeps its clearance."""

from __future__ import annotations

import numpy as np

from worldgen.feasibility.collision import Colliders, Nearest
from worldgen.scene import Robot

__all__ = ["sample_path", "sample_spacing", "verify_path"]


def sample_spacing(robot: Robot) -> float:
    """Distance between consecutive samples: a quarter of the robot radius (METADATA.md's bound)."""
    return robot.radius / 4.0


def sample_path(waypoints: np.ndarray, spacing: float) -> np.ndarray:
    """(n, 2) points along the polyline, every waypoint included, no gap wider than ``spacing``."""
    w = np.asarray(waypoints, dtype=float).reshape(-1, 2)
    if len(w) < 2:
        return w.copy()
    seg = np.diff(w, axis=0)
    n = np.maximum(np.ceil(np.hypot(*seg.T) / spacing).astype(np.int64), 1)
    owner = np.repeat(np.arange(len(seg)), n)
    t = (np.arange(n.sum()) - np.repeat(np.cumsum(n) - n, n)) / np.repeat(n, n)
    pts = w[:-1][owner] + t[:, None] * seg[owner]
    return np.vstack([pts, w[-1:]])


def verify_path(colliders: Colliders, robot: Robot, waypoints: np.ndarray) -> tuple[Nearest, np.ndarray]:
    """The smallest FCL clearance of the footprint along the path, and the samples it used."""
    samples = sample_path(waypoints, sample_spacing(robot))
    return colliders.nearest(robot, samples, expect=robot.clearance), samples
