"""FCL collision objects for a scene, built once, and robot-footprint distance queries.

Every collider of the scene (``scene.colliders()``: not the floor, not markers)
becomes an FCL object of its own kind (box, cylinder, sphere, or a BVH mesh)
at its world pose. The robot is a vertical FCL cylinder standing on the floor.

python-fcl costs a few microseconds per pair, so queries for many robot
positions use a broad phase: a lower bound of each (position, collider)
distance from the collider's axis-aligned box, and FCL only for the pairs
whose bound could still beat the smallest distance found so far.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Optional

import fcl
import numpy as np

from worldgen.scene import Robot, Scene

__all__ = ["Colliders", "Nearest"]


@dataclass(frozen=True)
class Nearest:
    """The smallest FCL distance (m, negative = penetration depth) over a set of robot positions.

    ``index`` is the position it occurred at, ``name`` the collider; ``distance``
    is inf and ``name`` None when there is nothing to hit.
    """

    distance: float
    index: int
    name: Optional[str]
    queries: int


def _geometry(node):
    shape = node.shape
    if shape.kind == "box":
        return fcl.Box(*shape.size)
    if shape.kind == "cylinder":
        return fcl.Cylinder(shape.radius, shape.length)
    if shape.kind == "sphere":
        return fcl.Sphere(shape.radius)
    if shape.kind == "mesh":
        model = fcl.BVHModel()
        faces = np.asarray(shape.faces, dtype=np.int64)
        model.beginModel(len(shape.vertices), len(faces))
        model.addSubModel(np.ascontiguousarray(shape.scaled_vertices(), dtype=float), faces)
        model.endModel()
        return model
    raise TypeError(f"node {node.name!r}: no FCL geometry for shape kind {shape.kind!r}")


class Colliders:
    """The scene's colliders as FCL objects, with their world boxes for the broad phase."""

    def __init__(self, scene: Scene):
        nodes = scene.colliders()
        self.names = tuple(n.name for n in nodes)
        self.objects = []
        for node in nodes:
            m = scene.world_matrix(node.name)
            self.objects.append(fcl.CollisionObject(_geometry(node), fcl.Transform(m[:3, :3], m[:3, 3])))
        boxes = np.array([scene.aabb(n.name) for n in nodes], dtype=float).reshape(-1, 2, 3)
        self.lo = boxes[:, 0, :]
        self.hi = boxes[:, 1, :]
        self._unsigned = fcl.DistanceRequest(enable_signed_distance=False)
        self._signed = fcl.DistanceRequest(enable_signed_distance=True)
        self._contact = fcl.CollisionRequest(num_max_contacts=1, enable_contact=True)

    def __len__(self) -> int:
        return len(self.names)

    def body(self, robot: Robot) -> fcl.CollisionObject:
        """The robot's FCL cylinder, to be placed with :meth:`place`."""
        return fcl.CollisionObject(fcl.Cylinder(robot.radius, robot.height), fcl.Transform())

    @staticmethod
    def place(body: fcl.CollisionObject, robot: Robot, x: float, y: float) -> None:
        body.setTranslation(np.array([x, y, robot.height / 2]))

    def distance(self, body: fcl.CollisionObject, robot: Robot, c: int) -> float:
        """FCL's signed distance (m, negative = penetration depth) from the placed body to collider ``c``.

        Asked unsigned first (GJK alone) and signed only for pairs in contact. A pair
        that touches only across a horizontal plane (a robot exactly as tall as the
        opening under a lintel) is distance 0 and never reaches the signed query:
        libccd's EPA throws on such face-to-face contacts, and a C++ exception from
        python-fcl aborts the whole process.
        """
        d = fcl.distance(body, self.objects[c], self._unsigned, fcl.DistanceResult())
        if d > 0:
            return float(d)
        if self.lo[c, 2] >= robot.height or self.hi[c, 2] <= 0.0:
            return 0.0
        return float(fcl.distance(body, self.objects[c], self._signed, fcl.DistanceResult()))

    def depth(self, body: fcl.CollisionObject, c: int) -> float:
        """FCL's contact depth (m) of the placed body in collider ``c``; only for pairs :meth:`distance` puts below 0.

        The signed distance reads about 0 for a cylinder wholly inside a box; the
        contact's penetration depth does not.
        """
        result = fcl.CollisionResult()
        fcl.collide(body, self.objects[c], self._contact, result)
        return max((k.penetration_depth for k in result.contacts), default=0.0)

    def lower_bounds(self, robot: Robot, xy: np.ndarray) -> np.ndarray:
        """(n, m) lower bound of the distance from the robot at each of the (n, 2) points to each collider."""
        x = xy[:, 0, None]
        y = xy[:, 1, None]
        gx = np.maximum(np.maximum(self.lo[None, :, 0] - x, x - self.hi[None, :, 0]), 0.0)
        gy = np.maximum(np.maximum(self.lo[None, :, 1] - y, y - self.hi[None, :, 1]), 0.0)
        gz = np.maximum(np.maximum(self.lo[:, 2] - robot.height, -self.hi[:, 2]), 0.0)
        return np.maximum(np.sqrt(gx * gx + gy * gy) - robot.radius, gz[None, :])

    def nearest(self, robot: Robot, xy: np.ndarray, expect: float = 0.0) -> Nearest:
        """Smallest FCL distance from the robot cylinder at any of the (n, 2) points to any collider.

        Exact: pairs are measured in order of their lower bound until the bound
        reaches the best distance found. ``expect`` is a guess of the answer
        (e.g. the clearance the path was planned for); pairs whose bound is
        below it are gathered first, which keeps the sort small.
        """
        xy = np.asarray(xy, dtype=float).reshape(-1, 2)
        if len(self) == 0 or len(xy) == 0:
            return Nearest(float("inf"), 0, None, 0)
        bounds = self.lower_bounds(robot, xy)
        best, where, who, queries = float("inf"), 0, None, 0
        body = self.body(robot)
        threshold = expect + max(robot.radius / 2, 1e-3)
        while True:
            pi, ci = np.nonzero(bounds < threshold)
            order = np.argsort(bounds[pi, ci], kind="stable")
            for k in order:
                lb = bounds[pi[k], ci[k]]
                if lb >= best:
                    break
                p, c = int(pi[k]), int(ci[k])
                self.place(body, robot, xy[p, 0], xy[p, 1])
                d = self.distance(body, robot, c)
                queries += 1
                if d < best:
                    best, where, who = float(d), p, self.names[c]
                bounds[p, c] = np.inf  # measured: never again
            if best < threshold or np.all(np.isinf(bounds)):
                return Nearest(best, where, who, queries)
            # Nothing close enough: widen to every pair (rare: wide-open worlds).
            threshold = np.inf
