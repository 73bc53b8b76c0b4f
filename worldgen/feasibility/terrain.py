"""The terrain along a proven path: its incline profile, the largest step it crosses, and the check that
the footprint never covers ground its robot cannot drive (docs/terrain.md).

The planner kept the path's footprint off every non-drivable polygon (worldgen.scene.drivable); this check
proves it again on its own, with exact distances from the written path to those polygons, and reads the
figures world.json records for each task.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Optional, Sequence

import numpy as np
import shapely

from worldgen.feasibility.report import Check, TaskPath
from worldgen.floats import round_float
from worldgen.scene import Robot, Scene
from worldgen.scene.drivable import ramp_side_height, step_edges, terrain_footprints
from worldgen.scene.terrain import Terrain

__all__ = ["PathTerrain", "path_terrain", "terrain_check", "PROFILE_STEP"]

#: Distance (m) between the samples of a path's incline profile, the path's corners added.
PROFILE_STEP = 0.1


@dataclass(frozen=True)
class PathTerrain:
    """``profile`` (k, 3): distance along the path (m), the ground's height (m) and its incline (rad)
    under the robot's centre; ``largest_incline`` rad over the profile; ``largest_step`` m, the highest
    step edge within the footprint anywhere along the path; ``margin`` m, the smallest distance from the
    footprint's edge to ground it may not drive (inf when there is none)."""

    profile: np.ndarray
    largest_incline: float
    largest_step: float
    margin: float

    def entry(self) -> dict:
        return {"incline_profile": [[round_float(v) for v in row] for row in self.profile.tolist()],
                "largest_incline": round_float(self.largest_incline), "largest_step": round_float(self.largest_step)}


def samples(line: np.ndarray, step: float = PROFILE_STEP) -> tuple[np.ndarray, np.ndarray]:
    """(s, xy): points every ``step`` m along the polyline (k, 2) and at each corner, with their distance."""
    out_s, out_xy = [np.zeros(1)], [line[:1]]
    total = 0.0
    for a, b in zip(line[:-1], line[1:]):
        length = float(np.hypot(*(b - a)))
        n = max(1, int(math.ceil(length / step)))
        t = np.arange(1, n + 1) / n
        out_s.append(total + t * length)
        out_xy.append(a + t[:, None] * (b - a))
        total += length
    return np.concatenate(out_s), np.concatenate(out_xy)


def path_terrain(terrain: Terrain, robot: Robot, line: np.ndarray, forbidden: Sequence) -> PathTerrain:
    """The terrain figures of the path ``line`` (k, 2) for ``robot``; ``forbidden`` its non-drivable polygons."""
    s, xy = samples(np.asarray(line, dtype=float))
    inclines = np.arctan(terrain.gradients(xy))
    profile = np.column_stack([s, terrain.heights(xy), inclines])
    path = shapely.LineString(line) if len(line) > 1 else shapely.Point(line[0])
    margin = min((float(path.distance(f.polygon)) - robot.radius for f in forbidden), default=math.inf)
    return PathTerrain(profile, float(inclines.max(initial=0.0)), _largest_step(terrain, path, robot.radius), margin)


def _largest_step(terrain: Terrain, path, radius: float) -> float:
    """The highest step edge within ``radius`` of the path: exact, a ramp side's height being concave
    along it (its largest on an interval is at an end or at a corner of the landing)."""
    swept = path.buffer(radius, quad_segs=32)
    best = 0.0
    for _, edge, ramp, height in step_edges(terrain):
        near = edge.intersection(swept)
        if near.is_empty:
            continue
        if ramp is None:
            best = max(best, height)
            continue
        c, s_ = math.cos(ramp.yaw), math.sin(ramp.yaw)
        pts = np.array([p for g in getattr(near, "geoms", [near]) for p in g.coords])
        u = c * (pts[:, 0] - ramp.cx) + s_ * (pts[:, 1] - ramp.cy)
        lo, hi = float(u.min()), float(u.max())
        candidates = [lo, hi] + [k for k in (-ramp.landing / 2, ramp.landing / 2) if lo <= k <= hi]
        best = max(best, float(ramp_side_height(ramp, np.array(candidates)).max()))
    return best


def terrain_check(scene: Scene, tasks, robot: Robot, paths: Sequence[Optional[TaskPath]]) -> \
        tuple[Check, list[Optional[PathTerrain]]]:
    """terrain_drivable: every path keeps its footprint on drivable ground, its inclines and steps within
    the limits; value: the smallest margin (m) from the footprint's edge to non-drivable ground."""
    assert scene.terrain is not None, "only a scene with terrain has a terrain check"
    forbidden = terrain_footprints(scene, robot)
    figures = [None if p is None else path_terrain(scene.terrain, robot, p.waypoints, forbidden) for p in paths]
    step_limit = min(robot.max_step_up, robot.max_step_down)
    bad, worst = [], math.inf
    for task, fig in zip(tasks, figures):
        if fig is None:
            continue
        worst = min(worst, fig.margin)
        if fig.margin < 0:
            bad.append(f"{task.id}: the footprint comes {-fig.margin:.4f} m onto ground it cannot drive")
        elif fig.largest_step > step_limit + 1e-12:
            bad.append(f"{task.id}: the path crosses a {fig.largest_step:.4f} m step (limit {step_limit:g} m)")
    value = None if not math.isfinite(worst) else worst
    if bad:
        return Check("terrain_drivable", False, value, "; ".join(bad)), figures
    found = [f for f in figures if f is not None]
    if not found:
        return Check("terrain_drivable", False, None, "no path to read the terrain along"), figures
    incline = max(f.largest_incline for f in found)
    step = max(f.largest_step for f in found)
    return Check("terrain_drivable", True, value, f"largest incline {math.degrees(incline):.2f} deg, largest step {step:.4f} m "
                 f"along the paths"), figures
