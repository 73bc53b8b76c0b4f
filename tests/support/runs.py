"""Runs to record as bags: a small world and trajectories through it whose figures are known by construction."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np

__all__ = ["small_world", "along", "toward", "idle_then", "spawn_of", "write_bag"]


def small_world(out: Path, seed: int = 0) -> Path:
    """A small cluttered world folder (8 x 8 m, 6 obstacles) written under ``out``."""
    import worldgen

    world = worldgen.generate("cluttered", seed=seed, size=[8, 8], n_obstacles=6)
    return Path(world.write(out))


def _meta(folder: Path) -> dict:
    return json.loads((Path(folder) / "world.json").read_text())


def spawn_of(folder: Path) -> tuple[float, float, float]:
    s = _meta(folder)["tasks"][0]["spawn"]
    return float(s[0]), float(s[1]), float(s[5])


def _polyline(points: np.ndarray, speed: float, dt: float, t0: float) -> np.ndarray:
    """(n, 4) t, x, y, yaw moving along ``points`` at ``speed``, sampled every ``dt`` from ``t0``, last point included."""
    s = np.concatenate([[0.0], np.cumsum(np.hypot(*np.diff(points, axis=0).T))])
    ts = np.arange(0.0, s[-1] / speed, dt)
    ts = np.append(ts, s[-1] / speed)
    x, y = np.interp(ts * speed, s, points[:, 0]), np.interp(ts * speed, s, points[:, 1])
    seg = np.searchsorted(s, ts * speed, side="right").clip(1, len(points) - 1) - 1
    d = np.diff(points, axis=0)
    yaw = np.unwrap(np.arctan2(d[:, 1], d[:, 0]))[seg]
    return np.column_stack([ts + t0, x, y, yaw])


def along(folder: Path, speed: float = 0.5, dt: float = 0.05, t0: float = 0.0) -> np.ndarray:
    """The task's reference path driven at ``speed``: reaches the goal, no contact."""
    wp = np.asarray(_meta(folder)["tasks"][0]["path"]["waypoints"], dtype=float)[:, :2]
    return _polyline(wp, speed, dt, t0)


def toward(folder: Path, target, speed: float = 0.5, dt: float = 0.05) -> np.ndarray:
    """From the spawn straight to ``target`` (x, y)."""
    sx, sy, _ = spawn_of(folder)
    return _polyline(np.array([[sx, sy], list(target)], dtype=float), speed, dt, 0.0)


def idle_then(traj: np.ndarray, seconds: float, dt: float = 0.05) -> np.ndarray:
    """The robot stands at the first pose for ``seconds`` (the sim clock running), then ``traj`` follows."""
    still = np.arange(0.0, seconds, dt)
    head = np.column_stack([still, np.repeat(traj[:1, 1:], len(still), axis=0)])
    moved = traj.copy()
    moved[:, 0] += seconds
    return np.vstack([head, moved])


def write_bag(path: Path, folder: Path, traj: np.ndarray, **kw) -> Path:
    """The run written with :func:`worldgen.ros.write_run`, spawned at the world's spawn, naming the world."""
    from worldgen.ros import write_run

    meta = _meta(folder)
    kw.setdefault("world_id", meta["world_id"])
    kw.setdefault("task", meta["tasks"][0]["id"])
    return write_run(path, traj, spawn=spawn_of(folder), **kw)
