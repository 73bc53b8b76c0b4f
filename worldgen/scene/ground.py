"""The terrain as pieces an engine's collision geometry carries: convex solids and height fields.

Every piece's top is the model's ground (worldgen.scene.terrain) where it lies:

- a ramp is one convex solid, its trapezoid profile extruded across its width;
- a kerb is a box standing on the floor;
- a pothole is a box sunk to its depth, and the floor slab around it is cut into triangular prisms
  (a constrained Delaunay triangulation of the floor's rectangle less every pothole), since a slab has
  no holes;
- a rough patch is a height field with the patch's grid as its nodes, cut into the same triangles as
  the model's, and cut out of the floor like a pothole where it dips below it.

Every solid is a convex prism, given as two rings of corners: MuJoCo makes a mesh of the corners alone
into their convex hull; the formats that read triangles get the prism's caps and sides.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Optional, Union

import numpy as np
import shapely

from worldgen.files import TERRAIN_MESH_NAME
from worldgen.scene import Box, Material, Mesh, Node, Scene
from worldgen.scene.terrain import Ramp, Rough, Step

__all__ = ["Solid", "Field", "Piece", "ground_pieces", "FLOOR_NAME", "yaw_quat", "ground_scene", "TERRAIN_NODE"]

#: The node that carries the terrain's one mesh in the formats that refer to mesh files.
TERRAIN_NODE = "terrain"

#: The scene's floor node, the one slab potholes are cut out of.
FLOOR_NAME = "floor"
#: How far below the floor's top a solid standing on it reaches (m): it overlaps the slab instead of
#: touching it, so no ray or contact finds a seam.
_SINK = 0.001


@dataclass(frozen=True, eq=False)
class Solid:
    """A convex prism: ``points`` (2k, 3) world corners, two rings of k in order round the same convex
    polygon, corner i of the first joined to corner i of the second."""

    name: str
    points: np.ndarray


@dataclass(frozen=True, eq=False)
class Field:
    """A height field: ``grid`` (ny, nx) heights (m) over a ``length`` x ``width`` rectangle centred at
    (cx, cy) turned by ``yaw``, ``grid[j][i]`` at local x = -length/2 + i cell, y = -width/2 + j cell."""

    name: str
    cx: float
    cy: float
    yaw: float
    length: float
    width: float
    grid: np.ndarray
    base: float


Piece = Union[Solid, Field]


def _box(e, u0: float, u1: float, v0: float, v1: float, z0: float, z1: float) -> np.ndarray:
    corners = np.array([[u0, v0], [u1, v0], [u1, v1], [u0, v1]])
    xy = e.to_world(corners)
    return np.vstack([np.column_stack([xy, np.full(4, z)]) for z in (z0, z1)])


def ground_pieces(scene: Scene, floor_thickness: Optional[float] = None) -> tuple[bool, list[Piece]]:
    """(whether the floor slab is replaced by the pieces, the pieces) of ``scene``'s terrain."""
    terrain = scene.terrain
    if terrain is None:
        return False, []
    floor = next((n for n in scene.nodes if n.name == FLOOR_NAME and isinstance(n.shape, Box)), None)
    thickness = floor_thickness or (floor.shape.size[2] if floor is not None and isinstance(floor.shape, Box) else 0.1)
    pieces: list[Piece] = []
    holes = []
    for k, e in enumerate(terrain.elements):
        name = f"terrain_{k}"
        hl, hw = e.length / 2, e.width / 2
        if isinstance(e, Ramp):
            # The inclines go on below the floor's top to the solid's sunk bottom: no lip at the foot.
            foot = hl + _SINK * e.run / e.rise
            top = [(-hl + e.run, e.rise), (hl - e.run, e.rise)] if e.landing > 0 else [(0.0, e.rise)]
            ring = [(-foot, -_SINK)] + top + [(foot, -_SINK)]
            local = np.array([(u, v, z) for v in (-hw, hw) for u, z in ring])
            pieces.append(Solid(name, np.column_stack([e.to_world(local[:, :2]), local[:, 2]])))
        elif isinstance(e, Step) and e.height > 0:
            pieces.append(Solid(name, _box(e, -hl, hl, -hw, hw, -_SINK, e.height)))
        elif isinstance(e, Step):
            pieces.append(Solid(name, _box(e, -hl, hl, -hw, hw, e.height - thickness, e.height)))
            holes.append(e.outline())
        elif isinstance(e, Rough):
            pieces.append(Field(name, e.cx, e.cy, e.yaw, e.length, e.width, e.array, thickness))
            if e.array.min() < 0:  # dips below the floor's top: the slab gives way to it
                holes.append(e.outline())
    if not holes or floor is None:
        return False, pieces
    return True, _cut_floor(scene, floor, holes, thickness) + pieces


def _cut_floor(scene: Scene, floor, holes, thickness: float) -> list[Piece]:
    """The floor slab less the potholes, as triangular prisms."""
    m = scene.world_matrix(floor.name)
    sx, sy, _ = floor.shape.size
    slab = shapely.Polygon((m[:2, :2] @ np.array([[-sx / 2, -sy / 2], [sx / 2, -sy / 2], [sx / 2, sy / 2],
                                                   [-sx / 2, sy / 2]]).T).T + m[:2, 3])
    top = float(m[2, 3] + thickness / 2)
    left = slab.difference(shapely.union_all(holes))
    triangles = shapely.constrained_delaunay_triangles(left)
    out: list[Piece] = []
    for k, tri in enumerate(getattr(triangles, "geoms", [triangles])):
        xy = np.array(tri.exterior.coords)[:3]
        if abs(shapely.area(tri)) < 1e-12:
            continue
        out.append(Solid(f"{FLOOR_NAME}_{k}", np.vstack([np.column_stack([xy, np.full(3, z)])
                                                          for z in (top - thickness, top)])))
    return out


def yaw_quat(yaw: float) -> tuple[float, float, float, float]:
    """(w, x, y, z) of a turn by ``yaw`` about z."""
    return (math.cos(yaw / 2), 0.0, 0.0, math.sin(yaw / 2))


def _solid_triangles(points: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(vertices, faces) of a prism given as two rings of corners (the first half of ``points`` and the
    second, each in order round a convex polygon, corner i of one joined to corner i of the other), faces
    turned outward."""
    k = len(points) // 2
    i = np.arange(k)
    j = (i + 1) % k
    faces = np.vstack([np.column_stack([np.zeros(k - 2, int), i[1:-1], i[2:]]),  # the two caps, as fans
                       np.column_stack([np.full(k - 2, k), k + i[2:], k + i[1:-1]]),
                       np.column_stack([i, j, k + j]), np.column_stack([i, k + j, k + i])])
    centre = points.mean(axis=0)
    a, b, c = points[faces[:, 0]], points[faces[:, 1]], points[faces[:, 2]]
    inward = np.einsum("ij,ij->i", np.cross(b - a, c - a), a - centre) < 0
    faces[inward] = faces[inward][:, ::-1]
    return points, faces


def _field_triangles(f: Field) -> tuple[np.ndarray, np.ndarray]:
    """(vertices, faces) of a height field's top, split as the model splits each cell, over a flat bottom
    ``base`` below its lowest node, walled round."""
    ny, nx = f.grid.shape
    cell = f.length / (nx - 1)
    u, v = np.meshgrid(-f.length / 2 + cell * np.arange(nx), -f.width / 2 + cell * np.arange(ny))
    xy = _Frame(f).to_world(np.column_stack([u.ravel(), v.ravel()]))
    bottom = float(f.grid.min()) - f.base
    top = np.column_stack([xy, f.grid.ravel()])
    low = np.column_stack([xy, np.full(len(xy), bottom)])
    vertices = np.vstack([top, low])
    n = nx * ny
    idx = np.arange(n).reshape(ny, nx)
    a, b, c, d = idx[:-1, :-1].ravel(), idx[:-1, 1:].ravel(), idx[1:, :-1].ravel(), idx[1:, 1:].ravel()
    faces = [np.column_stack([a, b, d]), np.column_stack([a, d, c]),  # the diagonal (i, j)-(i+1, j+1)
             np.column_stack([a + n, d + n, b + n]), np.column_stack([a + n, c + n, d + n])]
    ring = np.concatenate([idx[0, :], idx[1:, -1], idx[-1, -2::-1], idx[-2:0:-1, 0]])
    nxt = np.roll(ring, -1)
    faces += [np.column_stack([ring, ring + n, nxt]), np.column_stack([nxt, ring + n, nxt + n])]
    return vertices, np.vstack(faces)


class _Frame:
    def __init__(self, f: Field):
        self.cx, self.cy, self.yaw = f.cx, f.cy, f.yaw

    def to_world(self, uv: np.ndarray) -> np.ndarray:
        c, s = math.cos(self.yaw), math.sin(self.yaw)
        return np.column_stack([self.cx + c * uv[:, 0] - s * uv[:, 1], self.cy + s * uv[:, 0] + c * uv[:, 1]])


def ground_scene(scene: Scene) -> Scene:
    """``scene`` as the formats with mesh colliders write it: every terrain piece in one mesh
    (:data:`~worldgen.files.TERRAIN_MESH_NAME`) on a static node :data:`TERRAIN_NODE` beside the floor,
    or, where potholes cut the floor slab (which is then in the mesh), on the floor node itself, so every
    entity of world.json is still a body of the file; ``scene`` itself on flat ground."""
    replaced, pieces = ground_pieces(scene)
    if not pieces:
        return scene
    vertices, faces, offset = [], [], 0
    for piece in pieces:
        v, f = _field_triangles(piece) if isinstance(piece, Field) else _solid_triangles(piece.points)
        vertices.append(v)
        faces.append(f + offset)
        offset += len(v)
    floor = next((n for n in scene.nodes if n.name == FLOOR_NAME), None)
    material = floor.material if floor is not None else Material()
    mesh = Mesh(TERRAIN_MESH_NAME, np.vstack(vertices), np.vstack(faces))
    if replaced:  # the cut slab is in the mesh: it stands in the floor's place, under the floor's name
        return scene.with_nodes([Node(FLOOR_NAME, "floor", mesh, material=material) if n.name == FLOOR_NAME else n
                                 for n in scene.nodes])
    return scene.with_nodes(list(scene.nodes) + [Node(TERRAIN_NODE, "floor", mesh, material=material)])
