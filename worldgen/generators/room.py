"""The floor and the walls of a rectangular room centred on the origin, shared by generators."""

from __future__ import annotations

from worldgen.scene import Box, Material, Node, Pose

__all__ = ["FLOOR_THICKNESS", "floor_node", "wall_nodes", "room_bounds"]

#: The floor is a slab whose top face is z = 0.
FLOOR_THICKNESS = 0.1

FLOOR_RGBA = (0.82, 0.82, 0.80, 1.0)
WALL_RGBA = (0.55, 0.57, 0.62, 1.0)


def room_bounds(size) -> tuple[tuple[float, float], tuple[float, float]]:
    """((minx, miny), (maxx, maxy)) of a room of inner extents ``size`` centred on the origin."""
    sx, sy = size
    return ((-sx / 2.0, -sy / 2.0), (sx / 2.0, sy / 2.0))


def floor_node(size, margin: float, friction: float) -> Node:
    """A floor slab covering the room plus ``margin`` on every side."""
    sx, sy = size
    return Node(
        "floor", "floor", Box((sx + 2 * margin, sy + 2 * margin, FLOOR_THICKNESS)),
        Pose(0.0, 0.0, -FLOOR_THICKNESS / 2.0), material=Material("floor", FLOOR_RGBA, friction),
    )


def wall_nodes(size, height: float, thickness: float, friction: float) -> list[Node]:
    """Four walls whose inner faces lie on the room's bounds; east/west walls close the corners."""
    sx, sy = size
    t, h = thickness, height
    mat = Material("wall", WALL_RGBA, friction)
    z = h / 2.0
    return [
        Node("wall_north", "wall", Box((sx, t, h)), Pose(0.0, sy / 2 + t / 2, z), material=mat),
        Node("wall_south", "wall", Box((sx, t, h)), Pose(0.0, -sy / 2 - t / 2, z), material=mat),
        Node("wall_east", "wall", Box((t, sy + 2 * t, h)), Pose(sx / 2 + t / 2, 0.0, z), material=mat),
        Node("wall_west", "wall", Box((t, sy + 2 * t, h)), Pose(-sx / 2 - t / 2, 0.0, z), material=mat),
    ]
