"""Prove a path with FCL: the volume the footprint sweeps along it keeps its clearance, continuously.

A vertical cylinder of radius r moved along a straight segment sweeps exactly
a box (the segment's length by 2 r, as tall as the robot, turned along the
segment) and the cylinder at each end. So a polyline's swept volume is one FCL
box per segment plus one cylinder per waypoint, and the smallest FCL distance
from those pieces to the colliders is the path's clearance everywhere along it,
not at samples: a handful of queries per segment instead of hundreds of placements.
"""

from __future__ import annotations

import math

import fcl
import numpy as np

from worldgen.feasibility.collision import Colliders, Nearest
from worldgen.scene import Robot

__all__ = ["verify_path", "swept_pieces"]


def swept_pieces(robot: Robot, waypoints: np.ndarray) -> tuple[list, np.ndarray, np.ndarray]:
    """The FCL pieces of the volume swept along ``waypoints`` (k, 2), and each piece's 2-D extent.

    Returns (objects, a (p, 2), b (p, 2)): piece i covers the points within
    ``robot.radius`` of segment a[i]b[i] (a point for a waypoint's cylinder), from
    the floor to ``robot.height``.
    """
    w = np.asarray(waypoints, dtype=float).reshape(-1, 2)
    r, h = robot.radius, robot.height
    objects, a, b = [], [], []
    for x, y in w:
        objects.append(fcl.CollisionObject(fcl.Cylinder(r, h), fcl.Transform(np.array([x, y, h / 2]))))
        a.append((x, y))
        b.append((x, y))
    for p, q in zip(w[:-1], w[1:]):
        d = q - p
        length = math.hypot(d[0], d[1])
        if length <= 1e-12:
            continue
        c, s = d / length
        rot = np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])
        mid = (p + q) / 2
        box = fcl.Box(length, 2 * r, h)
        objects.append(fcl.CollisionObject(box, fcl.Transform(rot, np.array([mid[0], mid[1], h / 2]))))
        a.append(tuple(p))
        b.append(tuple(q))
    return objects, np.array(a, dtype=float).reshape(-1, 2), np.array(b, dtype=float).reshape(-1, 2)


def verify_path(colliders: Colliders, robot: Robot, waypoints: np.ndarray) -> Nearest:
    """The smallest FCL distance from the swept volume of the footprint along the polyline to any collider.

    ``Nearest.index`` is the piece it occurred at and ``Nearest.where`` a point (x, y) on the path there.
    """
    objects, a, b = swept_pieces(robot, waypoints)
    return colliders.nearest_pieces(robot, objects, a, b, expect=robot.clearance)
