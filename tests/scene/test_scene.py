"""Scene graph: poses, shapes, derived transforms and bounding boxes, canonical hash."""

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from worldgen.scene import Box, Cylinder, Joint, Material, Mesh, Node, Pose, Scene, Sphere, matrix_to_pose, rpy_matrix

angles = st.floats(-math.pi, math.pi, allow_nan=False)
coords = st.floats(-50, 50, allow_nan=False)


def test_rpy_is_fixed_axis_rz_ry_rx():
    r, p, y = 0.3, -0.4, 1.1
    rx = np.array([[1, 0, 0], [0, math.cos(r), -math.sin(r)], [0, math.sin(r), math.cos(r)]])
    ry = np.array([[math.cos(p), 0, math.sin(p)], [0, 1, 0], [-math.sin(p), 0, math.cos(p)]])
    rz = np.array([[math.cos(y), -math.sin(y), 0], [math.sin(y), math.cos(y), 0], [0, 0, 1]])
    assert np.allclose(rpy_matrix(r, p, y), rz @ ry @ rx)


@given(coords, coords, coords, angles, st.floats(-1.5, 1.5), angles)
def test_pose_matrix_round_trip(x, y, z, roll, pitch, yaw):
    pose = Pose(x, y, z, roll, pitch, yaw)
    back = matrix_to_pose(pose.matrix())
    assert np.allclose(back.matrix(), pose.matrix(), atol=1e-9)


def test_world_transform_composes_parent_chain():
    scene = Scene([
        Node("base", "obstacle", Box((1, 1, 1)), Pose(1, 0, 0, 0, 0, math.pi / 2)),
        Node("arm", "obstacle", Box((1, 1, 1)), Pose(2, 0, 0), parent="base"),
    ])
    # 2 m along the parent's x, which points along world +y after the quarter turn.
    assert np.allclose(scene.world_matrix("arm")[:3, 3], [1, 2, 0])
    assert scene.world_pose("arm").yaw == pytest.approx(math.pi / 2)


@settings(max_examples=60)
@given(angles, angles, angles, st.sampled_from(["box", "cylinder", "sphere"]))
def test_aabb_contains_every_surface_point(roll, pitch, yaw, kind):
    shape = {"box": Box((1.0, 0.4, 2.0)), "cylinder": Cylinder(0.3, 1.2), "sphere": Sphere(0.5)}[kind]
    scene = Scene([Node("a", "obstacle", shape, Pose(1, -2, 3, roll, pitch, yaw))])
    lo, hi = scene.aabb("a")
    m = scene.world_matrix("a")
    rng = np.random.default_rng(0)
    # Points on the surface, drawn in the shape's frame, must lie inside the world box;
    # and the box must be tight: some point comes within 2 cm of each face.
    if kind == "box":
        pts = np.concatenate([rng.uniform(-0.5, 0.5, (4000, 3)) * shape.size, shape.local_corners()])
    elif kind == "cylinder":
        a = rng.uniform(0, 2 * math.pi, 4000)
        pts = np.c_[shape.radius * np.cos(a), shape.radius * np.sin(a), np.where(rng.random(4000) < 0.5, 0.6, -0.6)]
    else:
        v = rng.normal(size=(4000, 3))
        pts = 0.5 * v / np.linalg.norm(v, axis=1, keepdims=True)
    world = pts @ m[:3, :3].T + m[:3, 3]
    assert np.all(world >= lo - 1e-9) and np.all(world <= hi + 1e-9)
    assert np.all(world.min(axis=0) - lo < 0.02) and np.all(hi - world.max(axis=0) < 0.02)


def test_names_unique_and_checked():
    with pytest.raises(ValueError, match="used twice"):
        Scene([Node("a", "wall", Box((1, 1, 1))), Node("a", "wall", Box((1, 1, 1)))])
    with pytest.raises(ValueError, match="must match"):
        Node("../etc", "wall", Box((1, 1, 1)))
    with pytest.raises(ValueError, match="role"):
        Node("a", "tree", Box((1, 1, 1)))
    with pytest.raises(ValueError, match="unknown parent"):
        Scene([Node("a", "wall", Box((1, 1, 1)), parent="b")])


def test_shape_sizes_must_be_positive():
    for bad in (lambda: Box((1, 0, 1)), lambda: Cylinder(-1, 1), lambda: Sphere(float("nan"))):
        with pytest.raises(ValueError):
            bad()


def test_joint_initial_must_be_within_limits():
    with pytest.raises(ValueError, match="outside limits"):
        Joint("hinge", "revolute", "frame", "leaf", limits=(0.0, 1.0), initial=2.0)


def test_marker_never_collides():
    assert Node("m", "marker", Sphere(0.1)).collision is False


def test_content_hash_changes_with_any_geometry_and_not_with_noise():
    base = [Node("a", "obstacle", Box((1, 1, 1)), Pose(1, 2, 0.5)), Node("b", "obstacle", Cylinder(0.2, 1), Pose(0, 0, 0.5))]
    h = Scene(base).content_hash()
    assert h.startswith("sha256:") and len(h) == 71
    assert Scene(list(base)).content_hash() == h
    moved = [base[0], Node("b", "obstacle", Cylinder(0.2, 1), Pose(0, 0.001, 0.5))]
    assert Scene(moved).content_hash() != h
    recoloured = [base[0], Node("b", "obstacle", Cylinder(0.2, 1), Pose(0, 0, 0.5), material=Material("x", (1, 0, 0, 1)))]
    assert Scene(recoloured).content_hash() != h
    # below the written precision (1e-6 m), a difference is not a different world
    jitter = [base[0], Node("b", "obstacle", Cylinder(0.2, 1), Pose(1e-9, 0, 0.5))]
    assert Scene(jitter).content_hash() == h


def test_mesh_is_read_only_and_stays_inside_world_folder():
    verts = [[0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1]]
    faces = [[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]]
    mesh = Mesh("meshes/tet.stl", verts, faces)
    with pytest.raises(ValueError):
        mesh.vertices[0, 0] = 5
    with pytest.raises(ValueError, match="inside the world folder"):
        Mesh("../tet.stl", verts, faces)
    assert mesh.volume() == pytest.approx(1 / 6)
