"""Hand-built scenes for the MJCF/URDF exporter tests: every shape kind, every kind of attachment.

The cluttered generator makes only static root boxes and cylinders; these
scenes cover what it does not: spheres, meshes, tilted shapes, dynamic bodies,
a marker, and a door leaf on a revolute joint whose frame is offset and turned,
starting ajar, with a rigidly attached handle.
"""

from __future__ import annotations

import math

import numpy as np

from worldgen.scene import Box, Cylinder, Joint, Material, Mesh, Node, Physics, Pose, Scene, Sphere

__all__ = ["showcase_scene", "rock_mesh", "DOOR_INITIAL", "HINGE"]

DOOR_INITIAL = 0.4
#: Hinge position in the door frame's (post's) frame.
HINGE = (0.0, 0.1, -0.05)
LEAF_HALF_WIDTH = 0.45


def rock_mesh(uri: str = "meshes/rock.stl") -> Mesh:
    """A closed, outward-facing, lopsided octahedron (its centroid is off its frame's origin)."""
    v = np.array([[0.3, 0, 0], [-0.2, 0, 0], [0, 0.25, 0], [0, -0.15, 0], [0, 0, 0.35], [0, 0, -0.1]], dtype=float) + [0.05, 0.02, 0.0]
    f = np.array([[0, 2, 4], [2, 1, 4], [1, 3, 4], [3, 0, 4], [2, 0, 5], [1, 2, 5], [3, 1, 5], [0, 3, 5]])
    return Mesh(uri, v, f)


def showcase_scene() -> Scene:
    wood = Material("wood", (0.6, 0.4, 0.2, 1.0), 0.6)
    grey = Material("grey", (0.5, 0.5, 0.5, 1.0), 0.9)
    rock = rock_mesh()
    # The leaf at its initial angle: hinge, then the turn, then half a leaf along the turned x axis.
    c, s = math.cos(DOOR_INITIAL), math.sin(DOOR_INITIAL)
    leaf_pose = Pose(HINGE[0] + LEAF_HALF_WIDTH * c, HINGE[1] + LEAF_HALF_WIDTH * s, HINGE[2], 0.0, 0.0, DOOR_INITIAL)
    nodes = (
        Node("floor", "floor", Box((8.0, 8.0, 0.1)), Pose(0, 0, -0.05), material=grey),
        Node("wall_a", "wall", Box((6.0, 0.1, 1.0)), Pose(0, 3.5, 0.5), material=grey),
        Node("tilted_box", "obstacle", Box((0.4, 0.6, 0.8)), Pose(-2.0, 1.0, 0.6, 0.3, -0.2, 1.1), material=wood),
        Node("tilted_cylinder", "obstacle", Cylinder(0.2, 1.2), Pose(-1.0, -2.0, 0.7, 1.2, 0.1, -0.4)),
        Node("ball", "obstacle", Sphere(0.3), Pose(2.0, -2.0, 0.3)),
        Node("rock", "obstacle", rock, Pose(-2.5, -1.0, 0.2, 0.1, 0.2, 0.7)),
        Node("big_rock", "obstacle", Mesh(rock.uri, rock.vertices, rock.faces, (2.0, 1.5, 1.0)), Pose(2.5, 2.0, 0.2, 0, 0, -0.5)),
        Node("crate", "obstacle", Box((0.5, 0.4, 0.3)), Pose(0.5, -1.0, 0.16, 0, 0, 0.25), static=False, mass=4.0, material=wood),
        Node("pebble", "obstacle", Sphere(0.1), Pose(1.0, 1.0, 0.12), static=False, mass=0.5),
        Node("loose_rock", "obstacle", rock, Pose(-0.5, 1.5, 0.12, 0, 0, 0.3), static=False, mass=2.0),
        Node("goal_marker", "marker", Cylinder(0.25, 0.01), Pose(1.5, 0.0, 0.005), material=Material("goal", (0.1, 0.9, 0.1, 0.5))),
        Node("door_post", "door_frame", Box((0.1, 0.1, 2.0)), Pose(-1.0, 0.5, 1.0, 0, 0, 0.2), material=grey),
        Node("door_leaf", "door", Box((2 * LEAF_HALF_WIDTH, 0.04, 1.8)), leaf_pose, parent="door_post",
             static=False, mass=10.0, material=wood),
        Node("door_handle", "door", Sphere(0.04), Pose(0.35, 0.06, 0.0), parent="door_leaf", mass=0.2),
    )
    # The joint frame sits at the hinge (half a leaf back along the leaf's x) and is rolled by
    # pi/2, so the vertical hinge axis reads (0, 1, 0) in the joint frame: exporters must turn it.
    hinge = Joint("door_hinge", "revolute", "door_post", "door_leaf",
                  pose=Pose(-LEAF_HALF_WIDTH, 0.0, 0.0, math.pi / 2, 0.0, 0.0), axis=(0.0, 1.0, 0.0),
                  limits=(-1.5, 1.5), initial=DOOR_INITIAL, damping=2.0)
    return Scene(nodes, (hinge,), ((-3.0, -3.0), (3.0, 3.0)), Physics(0.002, 1.0))
