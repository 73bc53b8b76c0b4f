"""MJCF exporter: every world MuJoCo compiles and steps without a warning, and says what the scene says."""

from __future__ import annotations

import math

import mujoco
import numpy as np
import pytest
from support import draft
from support.reftools_mujoco import load_and_step
from support.scenes import DOOR_INITIAL, showcase_scene

from worldgen.export import mjcf
from worldgen.export.xml import parse_bytes
from worldgen.scene import Box, Joint, Node, Physics, Pose, Scene

#: (seed, params): the default room, a crowded big room, boxes only, no walls, tall thin cylinders.
CLUTTERED_CASES = [(seed, {}) for seed in range(50)] + [
    (0, {"size": [20.0, 20.0], "n_obstacles": 200}),
    (3, {"size": [20.0, 20.0], "n_obstacles": 50, "obstacle_shapes": "box"}),
    (4, {"walls": False, "n_obstacles": 30}),
    (5, {"obstacle_shapes": "cylinder", "cylinder_radius": [0.05, 0.1], "obstacle_height": [2.0, 3.0]}),
    (6, {"n_obstacles": 0}),
]


def mjcf_text(scene: Scene, name: str = "world") -> str:
    return mjcf.to_mjcf(scene, name=name).decode()


@pytest.mark.parametrize("seed,params", CLUTTERED_CASES, ids=lambda v: str(v) if isinstance(v, int) else None)
def test_cluttered_worlds_load_and_step(seed, params):
    scene, _ = draft("cluttered", seed, **params)
    model, data = load_and_step(mjcf_text(scene))
    names = {model.geom(i).name for i in range(model.ngeom)}
    assert names == {n.name for n in scene.nodes if n.shape is not None}
    # Static root nodes are bare world geoms: nothing may have moved.
    assert model.nbody == 1 and model.nq == 0


def test_showcase_loads_steps_and_keeps_the_door_where_the_scene_has_it():
    scene = showcase_scene()
    model, data = load_and_step(mjcf_text(scene))
    hinge = model.joint("door_hinge")
    assert hinge.type[0] == mujoco.mjtJoint.mjJNT_HINGE
    # Radians, not degrees: the range and the initial angle come back unconverted.
    np.testing.assert_allclose(model.jnt_range[hinge.id], (-1.5, 1.5))
    assert model.jnt_limited[hinge.id] == 1
    assert model.qpos0[model.jnt_qposadr[hinge.id]] == pytest.approx(DOOR_INITIAL)
    assert model.dof_damping[model.jnt_dofadr[hinge.id]] == pytest.approx(2.0)
    # A vertical hinge and no push: after 500 steps the leaf is still at its initial angle.
    assert data.qpos[model.jnt_qposadr[hinge.id]] == pytest.approx(DOOR_INITIAL, abs=1e-3)
    # Dynamic bodies sit on the floor and settle there instead of falling through it.
    for name, height in (("crate", 0.15), ("pebble", 0.1)):
        assert data.body(name).xpos[2] == pytest.approx(height, abs=0.01)


def test_showcase_every_kind_of_body():
    scene = showcase_scene()
    model = mujoco.MjModel.from_xml_string(mjcf_text(scene))
    for node in scene.nodes:
        if node.static and node.parent is None and node.name != "door_post":
            assert model.geom(node.name).bodyid[0] == 0, node.name  # a bare world geom
            continue
        body = model.body(node.name)
        assert body.mass[0] == pytest.approx(node.mass)
        np.testing.assert_allclose(body.inertia, node.inertia, atol=1e-6)  # 6 decimals written
    free = {model.joint(i).name for i in range(model.njnt) if model.jnt_type[i] == mujoco.mjtJoint.mjJNT_FREE}
    assert free == {"crate", "pebble", "loose_rock"}
    assert model.body("door_leaf").parentid[0] == model.body("door_post").id
    assert model.body("door_handle").parentid[0] == model.body("door_leaf").id
    assert model.body("door_handle").jntnum[0] == 0  # rigidly attached
    marker = model.geom("goal_marker")
    assert marker.contype[0] == 0 and marker.conaffinity[0] == 0
    for node in scene.nodes:
        geom = model.geom(node.name)
        np.testing.assert_allclose(geom.rgba, node.material.rgba, atol=1e-6)
        assert geom.friction[0] == pytest.approx(node.material.friction)


def test_options_come_from_the_scene_physics():
    scene, _ = draft("cluttered", 1)
    scene = Scene(scene.nodes, (), scene.bounds, Physics(0.005, 0.0, (0.0, 0.5, -3.7)))
    model = mujoco.MjModel.from_xml_string(mjcf_text(scene, name="my_world"))
    assert model.opt.timestep == pytest.approx(0.005)
    np.testing.assert_allclose(model.opt.gravity, (0.0, 0.5, -3.7))
    root = parse_bytes(mjcf_text(scene).encode()).getroot()
    assert root.find("compiler").get("angle") == "radian"


def test_model_name_and_same_bytes_twice():
    scene = showcase_scene()
    a, b = mjcf.to_mjcf(scene, name="w1"), mjcf.to_mjcf(showcase_scene(), name="w1")
    assert a == b
    assert b'<mujoco model="w1">' in a
    assert b"-0 " not in a and b'"-0"' not in a


def test_floor_is_a_colliding_box():
    scene, _ = draft("cluttered", 2)
    model = mujoco.MjModel.from_xml_string(mjcf_text(scene))
    floor = model.geom("floor")
    assert floor.type[0] == mujoco.mjtGeom.mjGEOM_BOX and floor.contype[0] == 1
    # The floor's top face is z = 0.
    assert floor.pos[2] + floor.size[2] == pytest.approx(0.0, abs=1e-9)


@pytest.mark.parametrize("bad,message", [
    (lambda s: Scene(s.nodes + (Node("world", "obstacle", Box((1, 1, 1))),), s.joints, s.bounds), "reserved"),
    (lambda s: Scene(s.nodes, s.joints + (Joint("door_hinge", "fixed", "world", "crate"),), s.bounds), "used twice"),
    (lambda s: Scene(s.nodes, (Joint("bad", "revolute", "world", "door_leaf", limits=(-1, 1)),), s.bounds),
     "node's parent is 'door_post'"),
    (lambda s: Scene(s.nodes, s.joints + (Joint("crate", "fixed", "world", "ball"),), s.bounds), "free joint"),
])
def test_inconsistent_scenes_are_refused_with_a_clear_message(bad, message):
    with pytest.raises(ValueError, match=message):
        mjcf.to_mjcf(bad(showcase_scene()))


def test_revolute_root_on_the_world_and_a_pure_frame():
    """A root node hinged to the world, and a shape-less frame node carrying a child."""
    nodes = (
        Node("floor", "floor", Box((4, 4, 0.1)), Pose(0, 0, -0.05)),
        Node("turnstile", "obstacle", Box((1.0, 0.05, 1.0)), Pose(0, 0, 0.6, 0, 0, 0.3), static=False, mass=3.0),
        Node("anchor", "obstacle", None, Pose(1, 1, 0)),
        Node("post", "obstacle", Box((0.1, 0.1, 1.0)), Pose(0, 0, 0.5), parent="anchor"),
    )
    joint = Joint("spin", "revolute", "world", "turnstile", axis=(0, 0, 1), limits=(-math.pi, math.pi), initial=0.3)
    model, data = load_and_step(mjcf_text(Scene(nodes, (joint,))))
    assert model.body("turnstile").parentid[0] == 0
    assert model.jnt_type[model.joint("spin").id] == mujoco.mjtJoint.mjJNT_HINGE
    assert model.nq == 1  # no free joint for a hinged dynamic root
    np.testing.assert_allclose(data.geom("post").xpos, (1, 1, 0.5), atol=1e-9)


def test_tiny_bodies_keep_a_valid_mass_and_inertia():
    """A 1 g bead's moments (~1e-8) would round to 0 at 6 decimals; MuJoCo would reject that."""
    nodes = (
        Node("floor", "floor", Box((4, 4, 0.1)), Pose(0, 0, -0.05)),
        Node("bead", "obstacle", Box((0.01, 0.01, 0.01)), Pose(0, 0, 0.005), static=False, mass=1e-3),
        Node("dust", "obstacle", Box((0.001, 0.001, 0.001)), Pose(1, 0, 0.0005), static=False, mass=1e-9),
    )
    model, _ = load_and_step(mjcf_text(Scene(nodes)))
    assert model.body("dust").mass[0] == pytest.approx(1e-6)
    assert np.all(model.body("bead").inertia >= 1e-6)
