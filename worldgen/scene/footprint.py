"""2-D footprints of a scene's colliders, as a robot on the floor meets them.

The robot is a vertical cylinder standing on the floor, so what matters of an
obstacle is its shadow on the floor, for the part of it below the robot's top.
Upright cylinders and spheres keep an exact disc (a polygon would cut corners
and under-report distances); everything else becomes a convex polygon that
contains the shape's projection (exact for boxes that are only yawed).
"""

from __future__ import annotations

import weakref
from dataclasses import dataclass
from typing import Optional

import numpy as np
import shapely

from worldgen.scene.graph import Scene
from worldgen.scene.shapes import Box, Cylinder, Mesh, Sphere

__all__ = ["Footprint", "FootprintIndex", "scene_footprints", "robot_footprints", "SAFETY"]

#: Extra margin (m) the feasibility planner keeps on top of the robot's inflation radius: far above
#: the 6-decimal rounding of waypoints and FCL's solver tolerance, far below any length that matters
#: (it lengthens a path by well under 0.1 %). A passage is refused only when it is narrower than
#: 2 x (inflation + SAFETY); generators that build passages to a width (corridor) read it here.
SAFETY = 1e-4

_VERTICAL = 1e-9


@dataclass(frozen=True, eq=False)
class Footprint:
    """The floor shadow of one node: a disc (centre, radius) or a convex polygon."""

    name: str
    role: str
    polygon: Optional[shapely.Polygon] = None
    centre: Optional[tuple[float, float]] = None
    radius: float = 0.0

    @property
    def is_disc(self) -> bool:
        return self.polygon is None

    def bounds(self) -> tuple[float, float, float, float]:
        """(minx, miny, maxx, maxy)."""
        if self.polygon is None:
            assert self.centre is not None, "a disc footprint has a centre"
            cx, cy = self.centre
            return (cx - self.radius, cy - self.radius, cx + self.radius, cy + self.radius)
        return tuple(self.polygon.bounds)


_CACHE: "weakref.WeakKeyDictionary[Scene, dict[float, list[Footprint]]]" = weakref.WeakKeyDictionary()


def scene_footprints(scene: Scene, height: float) -> list[Footprint]:
    """Footprints of every collider that reaches into the slab 0 < z < ``height``.

    Scenes are immutable, so the result is remembered per scene and height: the
    generator and the feasibility check ask for the same footprints.
    """
    per_scene = _CACHE.setdefault(scene, {})
    if height not in per_scene:
        per_scene[height] = _footprints(scene, height)
    return list(per_scene[height])


def robot_footprints(scene: Scene, robot) -> list[Footprint]:
    """The footprints that matter to ``robot``: everything below its top plus its clearance.

    The one height every layer uses (generator screening, feasibility, metrics),
    so all of them share one cached computation per scene.
    """
    return scene_footprints(scene, robot.height + robot.clearance)


def _footprints(scene: Scene, height: float) -> list[Footprint]:
    out: list[Optional[Footprint]] = []
    boxes: list[tuple[int, object, np.ndarray]] = []  # upright boxes, made together below
    for node in scene.colliders():
        m = scene.world_matrix(node.name)
        shape = node.shape
        if shape is None:  # colliders() gives only nodes with a shape
            continue
        upright = abs(abs(m[2, 2]) - 1.0) < _VERTICAL
        if isinstance(shape, Box) and upright:
            boxes.append((len(out), node, m))
            out.append(None)
            continue
        if isinstance(shape, Sphere) or (isinstance(shape, Cylinder) and upright):
            zc = m[2, 3]
            half = shape.radius if isinstance(shape, Sphere) else shape.length / 2
            if zc + half <= 1e-9 or zc - half >= height:
                continue
            radius = shape.radius
            if isinstance(shape, Sphere):
                # The widest slice inside the slab: the equator, unless it lies outside it.
                dz = 0.0 if 0.0 <= zc <= height else min(abs(zc), abs(zc - height))
                radius = float(np.sqrt(max(shape.radius**2 - dz**2, 0.0)))
            out.append(Footprint(node.name, node.role, centre=(float(m[0, 3]), float(m[1, 3])), radius=radius))
            continue
        if isinstance(shape, Mesh):
            pts = shape.scaled_vertices() @ m[:3, :3].T + m[:3, 3]
        elif isinstance(shape, Cylinder):
            # A tilted cylinder: the hull of its two end circles, sampled finely and pushed out
            # so the polygon contains the true shadow.
            ang = np.linspace(0, 2 * np.pi, 64, endpoint=False)
            r_out = shape.radius / np.cos(np.pi / 64)
            ring = np.stack([r_out * np.cos(ang), r_out * np.sin(ang)], axis=1)
            local = np.concatenate([np.c_[ring, np.full(64, z)] for z in (-shape.length / 2, shape.length / 2)])
            pts = local @ m[:3, :3].T + m[:3, 3]
        else:
            pts = shape.local_corners() @ m[:3, :3].T + m[:3, 3]
        if pts[:, 2].max() <= 1e-9 or pts[:, 2].min() >= height:
            continue
        hull = shapely.MultiPoint(pts[:, :2]).convex_hull
        if hull.geom_type != "Polygon":  # a degenerate (flat) shadow still blocks
            hull = hull.buffer(1e-6)
        out.append(Footprint(node.name, node.role, polygon=hull))
    if boxes:
        _upright_boxes(boxes, height, out)
    return [f for f in out if f is not None]


def _upright_boxes(boxes, height: float, out: list) -> None:
    """The rectangles of upright boxes, all in one pass: their corners turned together, the polygons
    made by one shapely call (one polygon at a time was most of the footprints' cost)."""
    corners = np.stack([node.shape.local_corners() for _, node, _ in boxes])  # (k, 8, 3)
    rot = np.stack([m[:3, :3] for _, _, m in boxes])
    pos = np.stack([m[:3, 3] for _, _, m in boxes])
    pts = np.matmul(corners, rot.transpose(0, 2, 1)) + pos[:, None, :]
    # local_corners() lists (-,-,-), (-,-,+), (-,+,-), (-,+,+), (+,-,-), ...: the bottom face, in
    # order around the rectangle, is corners 0, 2, 6, 4.
    polygons = shapely.polygons(pts[:, [0, 2, 6, 4], :2])
    z = pts[:, :, 2]
    reaches = (z.max(axis=1) > 1e-9) & (z.min(axis=1) < height)
    for (slot, node, _), polygon, keep in zip(boxes, polygons, reaches):
        if keep:
            out[slot] = Footprint(node.name, node.role, polygon=polygon)


class FootprintIndex:
    """Which of many points have a footprint within a radius, in one pass.

    Discs are kept as arrays, polygons in a shapely STRtree, so a query costs
    one vectorised pass however many obstacles there are.
    """

    def __init__(self, footprints: list[Footprint]):
        self.footprints = list(footprints)
        discs = [f for f in self.footprints if f.is_disc]
        self._disc_xy = np.array([f.centre for f in discs], dtype=float).reshape(-1, 2)
        self._disc_r = np.array([f.radius for f in discs], dtype=float)
        self._polygons = [f.polygon for f in self.footprints if not f.is_disc]
        self._tree = shapely.STRtree(self._polygons) if self._polygons else None

    def blocked(self, xy: np.ndarray, radius: float) -> np.ndarray:
        """(n,) bool: True where a footprint lies within ``radius`` of the point (or covers it)."""
        xy = np.asarray(xy, dtype=float).reshape(-1, 2)
        hit = np.zeros(len(xy), dtype=bool)
        if len(self._disc_r):
            d = np.hypot(xy[:, None, 0] - self._disc_xy[None, :, 0], xy[:, None, 1] - self._disc_xy[None, :, 1])
            hit |= (d - self._disc_r[None, :] <= radius).any(axis=1)
        if self._tree is not None and len(xy):
            ipt, _ = self._tree.query(shapely.points(xy), predicate="dwithin", distance=radius)
            hit[ipt] = True
        return hit
