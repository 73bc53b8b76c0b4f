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

from worldgen.errors import SceneError
from worldgen.scene import Robot, Scene

__all__ = ["Colliders", "Nearest"]


@dataclass(frozen=True)
class Nearest:
    """The smallest FCL distance (m, negative = penetration depth) over a set of robot positions or pieces.

    ``index`` is the position (piece) it occurred at and ``where`` a point (x, y)
    there, ``name`` the collider; ``distance`` is inf and ``name`` None when
    there is nothing to hit.
    """

    distance: float
    index: int
    name: Optional[str]
    queries: int
    where: Optional[tuple[float, float]] = None


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
    raise SceneError(f"node {node.name!r}: no FCL geometry for shape kind {shape.kind!r}")


class Colliders:
    """The scene's colliders as FCL objects, with their world boxes for the broad phase."""

    def __init__(self, scene: Scene):
        nodes = scene.colliders()
        self.scene = scene
        self.nodes = nodes
        self.names = tuple(n.name for n in nodes)
        # FCL objects are made when a query first reaches a collider: the broad phase below
        # keeps most of them from ever being asked (0.7 ms a world at 50 obstacles made eagerly).
        self._objects: list[Optional[fcl.CollisionObject]] = [None] * len(nodes)
        boxes = scene.aabbs([n.name for n in nodes])
        self.lo = boxes[:, 0, :]
        self.hi = boxes[:, 1, :]
        self._unsigned = fcl.DistanceRequest(enable_signed_distance=False)
        self._signed = fcl.DistanceRequest(enable_signed_distance=True)
        self._contact = fcl.CollisionRequest(num_max_contacts=1, enable_contact=True)

    def __len__(self) -> int:
        return len(self.names)

    def object(self, c: int) -> fcl.CollisionObject:
        """Collider ``c`` as an FCL object placed in the world."""
        obj = self._objects[c]
        if obj is None:
            node = self.nodes[c]
            m = self.scene.world_matrix(node.name)
            obj = self._objects[c] = fcl.CollisionObject(_geometry(node), fcl.Transform(m[:3, :3], m[:3, 3]))
        return obj

    def body(self, robot: Robot) -> fcl.CollisionObject:
        """The robot's FCL cylinder, to be placed with :meth:`place`."""
        return fcl.CollisionObject(fcl.Cylinder(robot.radius, robot.height), fcl.Transform())

    @staticmethod
    def place(body: fcl.CollisionObject, robot: Robot, x: float, y: float) -> None:
        body.setTranslation(np.array([x, y, robot.height / 2]))

    def distance(self, body: fcl.CollisionObject, robot: Robot, c: int) -> float:
        """FCL's signed distance (m, negative = penetration depth) from the placed body (standing on the
        floor, ``robot.height`` tall) to collider ``c``.

        Asked unsigned first (GJK alone) and signed only for pairs in contact. A pair
        that touches only across a horizontal plane (a robot exactly as tall as the
        opening under a lintel) is distance 0 and never reaches the signed query:
        libccd's EPA throws on such face-to-face contacts, and a C++ exception from
        python-fcl aborts the whole process.
        """
        d = fcl.distance(body, self.object(c), self._unsigned, fcl.DistanceResult())
        if d > 0:
            return float(d)
        if self.lo[c, 2] >= robot.height or self.hi[c, 2] <= 0.0:
            return 0.0
        return float(fcl.distance(body, self.object(c), self._signed, fcl.DistanceResult()))

    def depth(self, body: fcl.CollisionObject, c: int) -> float:
        """FCL's contact depth (m) of the placed body in collider ``c``; only for pairs :meth:`distance` puts below 0.

        The signed distance reads about 0 for a cylinder wholly inside a box; the
        contact's penetration depth does not.
        """
        result = fcl.CollisionResult()
        fcl.collide(body, self.object(c), self._contact, result)
        return max((k.penetration_depth for k in result.contacts), default=0.0)

    def lower_bounds(self, robot: Robot, xy: np.ndarray) -> np.ndarray:
        """(n, m) lower bound of the distance from the robot at each of the (n, 2) points to each collider."""
        xy = np.asarray(xy, dtype=float).reshape(-1, 2)
        d = _point_box(xy[:, None, :], self.lo[None, :, :2], self.hi[None, :, :2])
        gz = np.maximum(np.maximum(self.lo[:, 2] - robot.height, -self.hi[:, 2]), 0.0)
        return np.maximum(d - robot.radius, gz[None, :])

    def segment_lower_bounds(self, robot: Robot, a: np.ndarray, b: np.ndarray, refine: float = np.inf) -> np.ndarray:
        """(n, m) lower bound of the distance from the volume the robot sweeps along each segment
        a[i]b[i] ((n, 2) each; a point where a == b) to each collider: the 2-D distance from the
        segment to the collider's box less the radius, or the vertical gap, whichever is larger.

        Pairs whose boxes alone already put them ``refine`` or more apart keep that coarser bound.
        """
        a = np.asarray(a, dtype=float).reshape(-1, 2)
        b = np.asarray(b, dtype=float).reshape(-1, 2)
        lo, hi = self.lo[None, :, :2], self.hi[None, :, :2]
        gz = np.maximum(np.maximum(self.lo[:, 2] - robot.height, -self.hi[:, 2]), 0.0)[None, :]
        seg_lo, seg_hi = np.minimum(a, b)[:, None, :], np.maximum(a, b)[:, None, :]
        gap = np.maximum(np.maximum(lo - seg_hi, seg_lo - hi), 0.0)
        bound = np.maximum(np.sqrt(gap[..., 0] ** 2 + gap[..., 1] ** 2) - robot.radius, gz)
        p, c = np.nonzero(bound < refine)
        if len(p):
            # Exact for these: a box corner may be nearer than either end, or the segment may cross the box.
            ap, bp, lc, hc = a[p], b[p], self.lo[c, :2], self.hi[c, :2]
            d = np.minimum(_point_box(ap, lc, hc), _point_box(bp, lc, hc))
            for cx in (0, 1):
                for cy in (0, 1):
                    corner = np.stack([np.where(cx, hc[:, 0], lc[:, 0]), np.where(cy, hc[:, 1], lc[:, 1])], axis=1)
                    d = np.minimum(d, _point_segment(corner, ap, bp))
            d = np.where(_crosses_box(ap, bp, lc, hc), 0.0, d)
            bound[p, c] = np.maximum(d - robot.radius, gz[0, c])
        return bound

    def nearest(self, robot: Robot, xy: np.ndarray, expect: float = 0.0) -> Nearest:
        """Smallest FCL distance from the robot cylinder at any of the (n, 2) points to any collider."""
        xy = np.asarray(xy, dtype=float).reshape(-1, 2)
        body = self.body(robot)

        def measure(p: int, c: int) -> float:
            self.place(body, robot, xy[p, 0], xy[p, 1])
            return self.distance(body, robot, c)

        if len(self) == 0 or len(xy) == 0:
            return Nearest(float("inf"), 0, None, 0, None)
        return self._nearest(self.lower_bounds(robot, xy), measure, robot, expect, xy)

    def nearest_pieces(self, robot: Robot, pieces: list, a: np.ndarray, b: np.ndarray,
                       expect: float = 0.0) -> Nearest:
        """Smallest FCL distance from any of the placed robot ``pieces`` to any collider; piece i
        lies within the robot radius of segment a[i]b[i] (see :meth:`segment_lower_bounds`)."""
        if len(self) == 0 or len(pieces) == 0:
            return Nearest(float("inf"), 0, None, 0, None)

        def measure(p: int, c: int) -> float:
            return self.distance(pieces[p], robot, c)

        bounds = self.segment_lower_bounds(robot, a, b, refine=expect + max(robot.radius / 2, 1e-3))
        return self._nearest(bounds, measure, robot, expect, (a + b) / 2)

    def _nearest(self, bounds: np.ndarray, measure, robot: Robot, expect: float, where: np.ndarray) -> Nearest:
        """The smallest of ``measure(p, c)`` over every (piece, collider) pair, exactly.

        Pairs are measured in order of their lower bound ``bounds[p, c]`` until the
        bound reaches the best distance found. ``expect`` is a guess of the answer
        (e.g. the clearance the path was planned for); pairs whose bound is below
        it are gathered first, which keeps the sort small.
        """
        best, at, who, queries = float("inf"), 0, None, 0
        threshold = expect + max(robot.radius / 2, 1e-3)
        while True:
            pi, ci = np.nonzero(bounds < threshold)
            order = np.argsort(bounds[pi, ci], kind="stable")
            for k in order:
                if bounds[pi[k], ci[k]] >= best:
                    break
                p, c = int(pi[k]), int(ci[k])
                d = measure(p, c)
                queries += 1
                if d < best:
                    best, at, who = float(d), p, self.names[c]
                bounds[p, c] = np.inf  # measured: never again
            if best < threshold or np.all(np.isinf(bounds)):
                return Nearest(best, at, who, queries, (float(where[at][0]), float(where[at][1])))
            # Nothing close enough: widen to every pair (rare: wide-open worlds).
            threshold = np.inf


def _point_box(p: np.ndarray, lo: np.ndarray, hi: np.ndarray) -> np.ndarray:
    """Distance from points to axis-aligned rectangles (0 inside); arrays broadcast, last axis (x, y)."""
    g = np.maximum(np.maximum(lo - p, p - hi), 0.0)
    return np.sqrt(g[..., 0] ** 2 + g[..., 1] ** 2)


def _point_segment(p: np.ndarray, a: np.ndarray, b: np.ndarray) -> np.ndarray:
    ab = b - a
    den = np.maximum(ab[..., 0] ** 2 + ab[..., 1] ** 2, 1e-300)
    t = np.clip(((p - a) * ab).sum(axis=-1) / den, 0.0, 1.0)
    d = p - a - t[..., None] * ab
    return np.sqrt(d[..., 0] ** 2 + d[..., 1] ** 2)


def _crosses_box(a: np.ndarray, b: np.ndarray, lo: np.ndarray, hi: np.ndarray) -> np.ndarray:
    """True where segment ab meets the rectangle [lo, hi] (Liang-Barsky clipping); arrays broadcast."""
    d = b - a
    t0 = np.zeros(np.broadcast_shapes(a.shape, lo.shape)[:-1])
    t1 = np.ones_like(t0)
    ok = np.ones_like(t0, dtype=bool)
    for k in (0, 1):
        dk = np.broadcast_to(d[..., k], t0.shape)
        ak = np.broadcast_to(a[..., k], t0.shape)
        lok = np.broadcast_to(lo[..., k], t0.shape)
        hik = np.broadcast_to(hi[..., k], t0.shape)
        still = dk == 0
        ok &= ~still | ((ak >= lok) & (ak <= hik))
        safe = np.where(still, 1.0, dk)
        ta, tb = (lok - ak) / safe, (hik - ak) / safe
        enter = np.where(still, -np.inf, np.minimum(ta, tb))
        leave = np.where(still, np.inf, np.maximum(ta, tb))
        t0 = np.maximum(t0, enter)
        t1 = np.minimum(t1, leave)
    return ok & (t0 <= t1)
