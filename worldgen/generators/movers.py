"""Movers: person-sized dynamic obstacles that walk scripted, looping paths on free floor.

Any generator gets them through the common parameters ``n_movers``,
``mover_radius``, ``mover_height``, ``mover_speed`` and ``mover_waypoints``:
the pipeline (:func:`worldgen.pipeline.attempt`) calls :func:`place_movers` on each
draft with its own RNG stream (:func:`worldgen.seeding.mover_rng`), so adding or changing movers
never moves an obstacle or a task.

A mover's path is a closed polygon of ``mover_waypoints`` points walked at
``mover_speed``: every leg, including the one back to the start, keeps the
mover's disc off the floor shadow of every static collider below its height
(exact segment distances, not samples) and inside the bounds. A mover starts
at least ``robot.inflation + mover_radius`` from every spawn and goal, and
``2 x mover_radius`` from every other mover's start. The tasks' reference paths
stay those of the static world; the pipeline then certifies each task among the movers (and people) with
the timed path of :mod:`worldgen.people.timed`, refusing a draw whose movers leave no way through.

Where a mover is at a time ``t`` is :mod:`worldgen.scene.motion`'s.
"""

from __future__ import annotations

import math
from typing import Any, Mapping, Optional, Sequence

import numpy as np
import shapely

from worldgen.floats import round_float
from worldgen.scene import Mover, Robot, Scene, Task
from worldgen.scene.footprint import FootprintIndex, scene_footprints

__all__ = ["PATH_TRIES", "place_movers"]
#: Fresh whole paths tried per mover before the draft counts as overcrowded.
PATH_TRIES = 40
#: Candidate points drawn at once (screened together, then tried in order).
_BATCH = 64
#: Extra distance (m) kept from obstacles, so 6-decimal rounding never tips a leg into contact.
_SLACK = 1e-3


class _Floor:
    """Exact 'is this disc / this swept disc clear?' questions against a scene's static footprints."""

    def __init__(self, scene: Scene, height: float):
        prints = scene_footprints(scene, height)
        self.index = FootprintIndex(prints)
        self.geoms = np.array([shapely.Point(fp.centre) if fp.is_disc else fp.polygon for fp in prints], dtype=object)
        self.extra = np.array([fp.radius for fp in prints], dtype=float)  # discs: their radius
        self.tree = shapely.STRtree(self.geoms) if len(self.geoms) else None
        self.reach = float(self.extra.max()) if len(self.extra) else 0.0

    def points_clear(self, xy: np.ndarray, radius: float) -> np.ndarray:
        return ~self.index.blocked(xy, radius)

    def leg_clear(self, a, b, radius: float) -> bool:
        if self.tree is None:
            return True
        line = shapely.LineString([a, b])
        hits = self.tree.query(line, predicate="dwithin", distance=radius + self.reach)
        if not len(hits):
            return True
        gaps = shapely.distance(line, self.geoms[hits]) - self.extra[hits]
        return bool(np.all(gaps > radius))


def place_movers(scene: Scene, tasks: Sequence[Task], robot: Robot, params: Mapping[str, Any],
                 rng: np.random.Generator) -> tuple[tuple[Mover, ...], Optional[str]]:
    """``params['n_movers']`` movers for ``scene``: (movers, None), or ((), reason) when they do not fit."""
    count = params["n_movers"]
    if count == 0:
        return (), None
    r, h = params["mover_radius"], params["mover_height"]
    speed, n_points = params["mover_speed"], params["mover_waypoints"]
    floor = _Floor(scene, h)
    clear_r = r + _SLACK
    (x0, y0), (x1, y1) = scene.bounds
    if x1 - x0 <= 2 * clear_r or y1 - y0 <= 2 * clear_r:
        return (), f"the floor is too small for movers of radius {r:g} m"
    task_points = np.array([[p.x, p.y] for t in tasks for p in (t.spawn, t.goal)], dtype=float).reshape(-1, 2)
    keep_from_tasks = robot.inflation + clear_r
    starts: list[np.ndarray] = []
    movers = []
    for i in range(count):
        path = None
        for _ in range(PATH_TRIES):
            path = _draw_path(rng, floor, scene.bounds, clear_r, n_points, task_points, keep_from_tasks, starts)
            if path is not None:
                break
        if path is None:
            return (), (f"could not lay {count} mover paths of {n_points} waypoints for radius {r:g} m "
                        f"on free floor (placed {i})")
        starts.append(path[0])
        movers.append(Mover(f"mover_{i}", r, h, _timed(path, speed), True, params["friction"]))
    return tuple(movers), None


def _candidates(rng, floor: _Floor, bounds, radius: float) -> np.ndarray:
    (x0, y0), (x1, y1) = bounds
    xy = np.column_stack([rng.uniform(x0 + radius, x1 - radius, _BATCH), rng.uniform(y0 + radius, y1 - radius, _BATCH)])
    xy = np.round(xy, 6)
    return xy[floor.points_clear(xy, radius)]


def _draw_path(rng, floor, bounds, radius, n_points, task_points, keep_from_tasks, starts):
    """A closed free path as an (n_points, 2) array, or None when this try failed."""
    pts = _candidates(rng, floor, bounds, radius)
    start = None
    for p in pts:
        far_from_tasks = not len(task_points) or np.hypot(*(task_points - p).T).min() >= keep_from_tasks
        far_from_movers = all(math.hypot(*(p - q)) >= 2 * radius for q in starts)
        if far_from_tasks and far_from_movers:
            start = p
            break
    if start is None:
        return None
    path = [start]
    min_leg = max(radius, 0.1)  # legs of some length, so the times strictly increase
    while len(path) < n_points:
        last_one = len(path) == n_points - 1
        for p in _candidates(rng, floor, bounds, radius):
            if math.hypot(*(p - path[-1])) < min_leg or not floor.leg_clear(path[-1], p, radius):
                continue
            if last_one and (math.hypot(*(p - start)) < min_leg or not floor.leg_clear(p, start, radius)):
                continue
            path.append(p)
            break
        else:
            return None
    return np.array(path)


def _timed(path: np.ndarray, speed: float) -> tuple[tuple[float, float, float], ...]:
    """(t, x, y) rows walking ``path`` and back to its start at ``speed``; times rounded, increasing."""
    closed = np.vstack([path, path[:1]])
    rows, t = [], 0.0
    for k, (x, y) in enumerate(closed):
        if k:
            t += math.hypot(x - closed[k - 1][0], y - closed[k - 1][1]) / speed
        rows.append((round_float(t), round_float(x), round_float(y)))
    return tuple(rows)
