"""Exact ranges of a noise-free lidar: analytic ray casting against the collision geometry.

Every node with a shape and collision (the floor slab too, role ``marker`` never)
is intersected in 3-D, in its own frame, so any orientation is exact: boxes by
the slab method, cylinders by their side quadric and cap planes, spheres by their
quadric, meshes triangle by triangle (Moller-Trumbore, the triangles themselves,
not a hull, as MuJoCo's ``mj_ray`` and Gazebo's CPU ray sensor do). A horizontal
ray above the floor never meets the floor slab, so no special case is needed.

Conventions (also in world.json ``sensors.lidar``):
- the sensor sits at ``pose``; ray i points along the sensor's x axis turned by
  ``angle_min + i * (angle_max - angle_min) / (samples - 1)`` about its z axis
  (the Gazebo / ROS LaserScan spacing). ``angle_min`` is ``lidar_angle_min`` when set
  (0 puts ``ranges[0]`` straight ahead, as many 360-degree scanners do), else the
  field of view is centred ahead. A full circle (``lidar_fov`` = 2 pi) gets
  ``angle_max = angle_min + 2 pi (samples - 1) / samples`` so no ray is cast twice;
- a ray starts at ``range_min`` (as Gazebo casts from its minimum range): the range
  is the distance from the sensor to the first surface at or beyond ``range_min``;
- ``range_max`` where no surface lies within ``[range_min, range_max]`` (never +inf:
  JSON has no infinity, and ROS drivers commonly report the limit).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Mapping

import numpy as np

from worldgen.scene import Pose, Scene
from worldgen.scene.ground import ground_scene

__all__ = ["LidarSpec", "spec_from_params", "angles", "directions", "cast", "scan", "describe", "FULL_CIRCLE"]

FULL_CIRCLE = 2.0 * math.pi
#: Directions with a smaller component than this are treated as parallel to a face.
_PARALLEL = 1e-300
#: A field of view this close to 2 pi is a full circle: world.json keeps 6 decimals of it.
_CIRCLE_TOL = 1e-5


@dataclass(frozen=True)
class LidarSpec:
    """Where the lidar is and how it scans; angles in rad, ranges in m."""

    pose: Pose
    angle_min: float
    angle_max: float
    samples: int
    range_min: float
    range_max: float


def spec_from_params(params: Mapping, spawn: Pose) -> LidarSpec:
    """The default lidar: at ``spawn`` (x, y, yaw), ``lidar_height`` above the floor.

    ``lidar_angle_min`` (optional) is ROS LaserScan's ``angle_min``: ray 0 points
    there and the rays follow counter-clockwise over ``lidar_fov``; unset, the
    field of view is centred ahead (a full circle then starts at -pi).
    """
    fov = float(params["lidar_fov"])
    n = int(params["lidar_samples"])
    start = params.get("lidar_angle_min")
    if n == 1:
        lo = hi = 0.0 if start is None else float(start)
    else:
        circle = fov >= FULL_CIRCLE - _CIRCLE_TOL
        span = FULL_CIRCLE * (n - 1) / n if circle else fov
        lo = float(start) if start is not None else (-math.pi if circle else -fov / 2.0)
        hi = lo + span
    pose = Pose(spawn.x, spawn.y, float(params["lidar_height"]), 0.0, 0.0, spawn.yaw)
    return LidarSpec(pose, lo, hi, n, float(params["lidar_range_min"]), float(params["lidar_range_max"]))


def angles(spec: LidarSpec) -> np.ndarray:
    """(samples,) ray angles about the sensor's z axis, rad."""
    if spec.samples == 1:
        return np.array([spec.angle_min])
    return np.linspace(spec.angle_min, spec.angle_max, spec.samples)


def directions(spec: LidarSpec) -> np.ndarray:
    """(samples, 3) unit ray directions in the world frame."""
    a = angles(spec)
    local = np.stack([np.cos(a), np.sin(a), np.zeros_like(a)], axis=1)
    return local @ spec.pose.rotation.T


def scan(scene: Scene, spec: LidarSpec) -> np.ndarray:
    """(samples,) ranges in m, ``range_max`` where nothing is hit."""
    hits = cast(scene, spec.pose.position, directions(spec), spec.range_min)
    return np.where(hits <= spec.range_max, hits, spec.range_max)


def describe(scene: Scene, spec: LidarSpec) -> dict:
    """world.json's ``sensors.lidar`` block. On terrain the rays meet the ground too (its pieces as the
    exported mesh carries them, worldgen.scene.ground): a slope rising into the scan plane reads as a wall,
    and ``terrain_returns`` lists the rays whose return is the ground's, not an obstacle's."""
    ground = ground_scene(scene)
    ranges = scan(ground, spec)
    out = {
        "pose": spec.pose.as_list(),
        "angle_min": spec.angle_min,
        "angle_max": spec.angle_max,
        "samples": spec.samples,
        "range_min": spec.range_min,
        "range_max": spec.range_max,
        "ranges": ranges.tolist(),
    }
    if ground is not scene:  # only on terrain, so that flat worlds keep their bytes
        out["terrain_returns"] = np.flatnonzero(ranges < scan(scene, spec) - 1e-9).tolist()
    return out


def cast(scene: Scene, origin: np.ndarray, dirs: np.ndarray, start: float = 0.0) -> np.ndarray:
    """(n,) distance along each unit direction from ``origin`` to the first collision surface
    at or beyond ``start``; +inf where there is none. ``dirs`` is (n, 3)."""
    origin = np.asarray(origin, dtype=float).reshape(3)
    dirs = np.asarray(dirs, dtype=float).reshape(-1, 3)
    best = np.full(len(dirs), np.inf)
    groups: dict[str, list] = {"box": [], "cylinder": [], "sphere": [], "mesh": []}
    for node in scene.nodes:
        if node.shape is not None and node.collision:
            groups[node.shape.kind].append((node.shape, scene.world_matrix(node.name)))
    if groups["box"]:
        half = np.array([s.size for s, _ in groups["box"]]) / 2.0
        o, d = _local_rays(groups["box"], origin, dirs)
        best = np.minimum(best, _first(_box_hits(o, d, half), start))
    if groups["cylinder"]:
        radius = np.array([s.radius for s, _ in groups["cylinder"]])
        half = np.array([s.length for s, _ in groups["cylinder"]]) / 2.0
        o, d = _local_rays(groups["cylinder"], origin, dirs)
        best = np.minimum(best, _first(_cylinder_hits(o, d, radius, half), start))
    if groups["sphere"]:
        centre = np.array([m[:3, 3] for _, m in groups["sphere"]])
        radius = np.array([s.radius for s, _ in groups["sphere"]])
        best = np.minimum(best, _first(_sphere_hits(origin, dirs, centre, radius), start))
    for shape, m in groups["mesh"]:
        tri = (shape.scaled_vertices() @ m[:3, :3].T + m[:3, 3])[shape.faces]
        best = np.minimum(best, _first(_triangle_hits(origin, dirs, tri), start))
    return best


# -- per shape kind: candidate distances (objects, rays, k), nan where a candidate is no hit ----

def _local_rays(items, origin, dirs):
    """Ray origin (m, 1, 3) and directions (m, n, 3) in each object's frame."""
    rot = np.array([m[:3, :3] for _, m in items])
    pos = np.array([m[:3, 3] for _, m in items])
    # Row vectors: v_local = R^T v is v_row @ R; one batched matmul for every object.
    o = np.matmul((origin - pos)[:, None, :], rot)
    d = np.matmul(dirs[None, :, :], rot)
    return o, d


def _first(candidates: np.ndarray, start: float) -> np.ndarray:
    """(n,) smallest candidate >= start over objects and candidates; inf where none."""
    c = np.where(candidates >= start, candidates, np.inf)  # nan compares False: dropped
    c = c.reshape(c.shape[0], c.shape[1], -1)
    # Elementwise over the few candidates, then down the objects: numpy's reductions over a short
    # last axis cost far more than these (1.3 of 2.3 ms a scan at 50 obstacles).
    best = c[:, :, 0]
    for k in range(1, c.shape[2]):
        best = np.minimum(best, c[:, :, k])
    return best.min(axis=0)


def _box_hits(o, d, half):
    """Entry and exit distances of the slab method, (m, n, 2)."""
    safe = np.where(np.abs(d) < _PARALLEL, _PARALLEL, d)
    with np.errstate(over="ignore"):
        t1 = (-half[:, None, :] - o) / safe
        t2 = (half[:, None, :] - o) / safe
    lo, hi = np.minimum(t1, t2), np.maximum(t1, t2)
    near = np.maximum(np.maximum(lo[..., 0], lo[..., 1]), lo[..., 2])
    far = np.minimum(np.minimum(hi[..., 0], hi[..., 1]), hi[..., 2])
    ok = near <= far
    return np.stack([np.where(ok, near, np.nan), np.where(ok, far, np.nan)], axis=2)


def _cylinder_hits(o, d, radius, half):
    """Side and cap crossings of cylinders along local z, (m, n, 4)."""
    r = radius[:, None]
    h = half[:, None]
    ox, oy, oz = o[..., 0], o[..., 1], o[..., 2]
    dx, dy, dz = d[..., 0], d[..., 1], d[..., 2]
    a = dx * dx + dy * dy
    b = ox * dx + oy * dy
    c = ox * ox + oy * oy - r * r
    disc = b * b - a * c
    with np.errstate(invalid="ignore", divide="ignore"):
        root = np.sqrt(disc)
        side = [(-b - root) / a, (-b + root) / a]
    out = []
    for t in side:
        z = oz + t * dz
        out.append(np.where((a > 0) & (disc >= 0) & (np.abs(z) <= h), t, np.nan))
    for cap in (-1.0, 1.0):
        with np.errstate(invalid="ignore", divide="ignore"):
            t = (cap * h - oz) / dz
        x, y = ox + t * dx, oy + t * dy
        out.append(np.where((dz != 0) & (x * x + y * y <= r * r), t, np.nan))
    return np.stack(out, axis=2)


def _sphere_hits(origin, dirs, centre, radius):
    """Both crossings of each sphere, (m, n, 2); directions are unit vectors."""
    oc = origin - centre  # (m, 3)
    b = oc @ dirs.T  # (m, n)
    c = (oc * oc).sum(axis=1)[:, None] - radius[:, None] ** 2
    disc = b * b - c
    with np.errstate(invalid="ignore"):
        root = np.sqrt(disc)
    ok = disc >= 0
    return np.stack([np.where(ok, -b - root, np.nan), np.where(ok, -b + root, np.nan)], axis=2)


def _triangle_hits(origin, dirs, tri):
    """Moller-Trumbore crossing of every triangle (f, 3, 3) by every ray, as (1, n, f)."""
    e1 = tri[:, 1] - tri[:, 0]
    e2 = tri[:, 2] - tri[:, 0]
    p = np.cross(dirs[:, None, :], e2[None, :, :])  # (n, f, 3)
    det = np.einsum("nfk,fk->nf", p, e1)
    s = origin - tri[:, 0]  # (f, 3)
    with np.errstate(divide="ignore", invalid="ignore"):
        inv = 1.0 / det
        u = np.einsum("nfk,fk->nf", p, s) * inv
        q = np.cross(s, e1)  # (f, 3)
        v = (dirs @ q.T) * inv
        t = (e2 * q).sum(axis=1)[None, :] * inv
        ok = (np.abs(det) > 1e-15) & (u >= 0) & (v >= 0) & (u + v <= 1)
    return np.where(ok, t, np.nan)[None]
