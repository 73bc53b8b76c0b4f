"""Scenes: the graph (nodes, shapes, poses, joints, movers) as plain data, no I/O, no file formats.

Exported here: the data types. The facts read off a scene live beside them and are imported
from their modules: ``footprint`` (floor shadows), ``doors`` (leaves and their states),
``motion`` (where movers are at a time)."""

from worldgen.scene.graph import NAME_PATTERN, ROLES, Joint, Material, Node, Physics, Robot, Scene, Task
from worldgen.scene.mover import Mover
from worldgen.scene.pose import Pose, matrix_to_pose, rpy_matrix
from worldgen.scene.shapes import Box, Cylinder, Mesh, Shape, Sphere, unit_inertia

__all__ = [
    "NAME_PATTERN", "ROLES", "Joint", "Material", "Node", "Physics", "Robot", "Scene", "Task",
    "Pose", "matrix_to_pose", "rpy_matrix",
    "Box", "Cylinder", "Mesh", "Shape", "Sphere", "unit_inertia",
    "Mover",
]
