"""The same world in every format: what MuJoCo compiles from the MJCF and from the URDF has the
scene's names, world poses and (SDF-convention) sizes, and world.json's entities say the same.

Everything is read back from the *compiled* model after ``mj_forward`` (``geom_xpos``,
``geom_xmat``, ``geom_size``, mesh vertices), never from our own XML.
"""

from __future__ import annotations

import json

import mujoco
import numpy as np
import pytest
from support import draft
from support.reftools_mujoco import load
from support.scenes import showcase_scene

from worldgen.export import meshes, metadata, mjcf, urdf
from worldgen.feasibility import FeasibilityReport
from worldgen.feasibility.report import CHECKER
from worldgen.scene import Robot, rpy_matrix
from worldgen.world import World

TOL = 2e-5  # 6-decimal output, composed through at most a few frames of a metre or two


def _quat_matrix(q) -> np.ndarray:
    m = np.zeros(9)
    mujoco.mju_quat2Mat(m, np.asarray(q, dtype=float))
    return m.reshape(3, 3)


def compiled(scene, fmt: str):
    """(model, data) after mj_forward from the model's own initial state."""
    if fmt == "mjcf":
        model = load(mjcf.to_mjcf(scene))
    else:
        model = load(urdf.to_urdf(scene), assets=meshes.mesh_files(scene))
    data = mujoco.MjData(model)
    mujoco.mj_forward(model, data)
    return model, data


def joint_value(fmt: str, joint, angle: float) -> float:
    """The joint position that puts ``joint`` at ``angle`` (the scene's measure) in a format.

    MJCF measures the scene's angle (ref = initial); URDF, like SDF, has no initial
    angle and counts from it.
    """
    return angle if fmt == "mjcf" else angle - joint.initial


def geom_frame(model, data, name: str) -> tuple[np.ndarray, np.ndarray]:
    """The world frame (position, rotation) of the entity a geom stands for.

    MuJoCo re-centres a mesh on its centroid and turns it to its principal axes
    (``mesh_pos``/``mesh_quat``); undo that to get back the entity's own frame.
    """
    g = model.geom(name)
    pos, rot = data.geom(name).xpos.copy(), data.geom(name).xmat.reshape(3, 3).copy()
    if g.type[0] == mujoco.mjtGeom.mjGEOM_MESH:
        mesh = g.dataid[0]
        mrot = _quat_matrix(model.mesh_quat[mesh])
        rot = rot @ mrot.T
        pos = pos - rot @ model.mesh_pos[mesh]
    return pos, rot


def world_aabb(model, data, name: str) -> np.ndarray:
    """(2, 3) world AABB of a box or mesh geom, from the compiled model.

    A box's is the box around its turned corners; a mesh's is tight around its
    turned vertices, which MuJoCo stores in the geom's (re-centred) frame.
    """
    g = model.geom(name)
    pos, rot = data.geom(name).xpos, data.geom(name).xmat.reshape(3, 3)
    if g.type[0] == mujoco.mjtGeom.mjGEOM_BOX:
        signs = np.array([[x, y, z] for x in (-1, 1) for y in (-1, 1) for z in (-1, 1)])
        local = signs * g.size
    else:
        mesh = g.dataid[0]
        start, count = model.mesh_vertadr[mesh], model.mesh_vertnum[mesh]
        local = model.mesh_vert[start:start + count]
    pts = local @ rot.T + pos
    return np.array([pts.min(axis=0), pts.max(axis=0)])


def sdf_size(model, name: str) -> dict:
    """The geom's size in SDF's conventions (full box extents, cylinder radius and length)."""
    g = model.geom(name)
    kind, size = g.type[0], g.size
    if kind == mujoco.mjtGeom.mjGEOM_BOX:
        return {"type": "box", "size": list(2 * size)}
    if kind == mujoco.mjtGeom.mjGEOM_CYLINDER:
        return {"type": "cylinder", "radius": size[0], "length": 2 * size[1]}
    if kind == mujoco.mjtGeom.mjGEOM_SPHERE:
        return {"type": "sphere", "radius": size[0]}
    assert kind == mujoco.mjtGeom.mjGEOM_MESH
    return {"type": "mesh", "scale": list(model.mesh_scale[g.dataid[0]])}


def assert_same_shape(got: dict, want: dict, what: str):
    assert got["type"] == want["type"], what
    for key, value in want.items():
        if key in ("type", "uri"):
            continue
        np.testing.assert_allclose(got[key], value, atol=TOL, err_msg=f"{what} {key}")


def scenes():
    yield "showcase", showcase_scene()
    for seed in (0, 1, 7):
        yield f"cluttered-{seed}", draft("cluttered", seed)[0]
    yield "cluttered-big", draft("cluttered", 2, size=[20.0, 20.0], n_obstacles=100)[0]


SCENES = dict(scenes())


@pytest.mark.parametrize("fmt", ["mjcf", "urdf"])
@pytest.mark.parametrize("key", list(SCENES))
def test_compiled_model_matches_the_scene(key, fmt):
    scene = SCENES[key]
    model, data = compiled(scene, fmt)
    shaped = [n for n in scene.nodes if n.shape is not None]
    # MJCF draws markers too; URDF's collision geoms are what MuJoCo keeps.
    expected = [n for n in shaped if fmt == "mjcf" or n.collision]
    assert sorted(model.geom(i).name for i in range(model.ngeom)) == sorted(n.name for n in expected)
    for node in expected:
        m = scene.world_matrix(node.name)
        pos, rot = geom_frame(model, data, node.name)
        np.testing.assert_allclose(pos, m[:3, 3], atol=TOL, err_msg=f"{fmt} {node.name} position")
        np.testing.assert_allclose(rot, m[:3, :3], atol=TOL, err_msg=f"{fmt} {node.name} orientation")
        assert_same_shape(sdf_size(model, node.name), node.shape.describe(), f"{fmt} {node.name}")
        if node.shape.kind in ("box", "mesh"):
            np.testing.assert_allclose(world_aabb(model, data, node.name), scene.aabb(node.name),
                                       atol=1e-4, err_msg=f"{fmt} {node.name} aabb")


@pytest.mark.parametrize("fmt", ["mjcf", "urdf"])
def test_door_starts_at_its_initial_angle_and_keeps_its_range(fmt):
    scene = showcase_scene()
    joint = scene.joints[0]
    model, data = compiled(scene, fmt)
    assert data.joint(joint.name).qpos[0] == pytest.approx(joint_value(fmt, joint, joint.initial))
    lo, hi = joint.limits
    np.testing.assert_allclose(model.jnt_range[model.joint(joint.name).id],
                               (joint_value(fmt, joint, lo), joint_value(fmt, joint, hi)), atol=1e-9)


def test_door_turns_the_same_way_in_mjcf_and_urdf():
    """Same angle, same leaf pose: axis, hinge point and angle offset agree between formats."""
    scene = showcase_scene()
    joint = scene.joints[0]
    poses = []
    for fmt in ("mjcf", "urdf"):
        model, data = compiled(scene, fmt)
        data.joint(joint.name).qpos[0] = joint_value(fmt, joint, 1.2)
        mujoco.mj_forward(model, data)
        poses.append((data.geom("door_leaf").xpos.copy(), data.geom("door_handle").xmat.copy()))
        # The hinge line stays put while the leaf turns: the leaf's centre keeps its distance.
        hinge_world = data.body("door_post").xpos + data.body("door_post").xmat.reshape(3, 3) @ (0.0, 0.1, -0.05)
        assert np.linalg.norm((data.geom("door_leaf").xpos - hinge_world)[:2]) == pytest.approx(0.45, abs=TOL)
    np.testing.assert_allclose(poses[0][0], poses[1][0], atol=TOL)
    np.testing.assert_allclose(poses[0][1], poses[1][1], atol=TOL)
    # And the turn really happened: 1.2 rad is not where the door started.
    assert np.linalg.norm(poses[0][0] - scene.world_matrix("door_leaf")[:3, 3]) > 0.1


def _world_json(scene) -> dict:
    """world.json of ``scene`` through the metadata exporter, parsed back from its canonical text."""
    world = World("cluttered", 0, {}, scene, (), Robot(0.2, 0.5, 0.1), FeasibilityReport((), (), None, CHECKER), 1)
    return json.loads(metadata.dumps(world.metadata_for({})))


@pytest.mark.parametrize("fmt", ["mjcf", "urdf"])
@pytest.mark.parametrize("key", ["showcase", "cluttered-1"])
def test_compiled_model_matches_world_json(key, fmt):
    scene = SCENES[key]
    model, data = compiled(scene, fmt)
    entities = _world_json(scene)["entities"]
    assert [e["name"] for e in entities] == [n.name for n in scene.nodes]
    body_names = {model.body(i).name for i in range(1, model.nbody)}
    for entity in entities:
        name = entity["name"]
        if fmt == "urdf":
            assert name in body_names  # every entity is a link, markers included
        if entity["shape"] is None or (fmt == "urdf" and entity["role"] == "marker"):
            continue
        pose = np.asarray(entity["pose"])
        pos, rot = geom_frame(model, data, name)
        np.testing.assert_allclose(pos, pose[:3], atol=TOL, err_msg=f"{fmt} {name} position")
        np.testing.assert_allclose(rot, rpy_matrix(*pose[3:]), atol=TOL, err_msg=f"{fmt} {name} orientation")
        assert_same_shape(sdf_size(model, name), entity["shape"], f"{fmt} {name}")
        if entity["shape"]["type"] in ("box", "mesh"):
            np.testing.assert_allclose(world_aabb(model, data, name), entity["aabb"], atol=1e-4,
                                       err_msg=f"{fmt} {name} aabb")


@pytest.mark.parametrize("seed", [0, 11])
def test_written_world_files_agree_with_their_world_json(tmp_path, seed):
    """End to end: generate, write, then load world.mjcf.xml and world.urdf from the folder."""
    import worldgen

    folder = worldgen.generate("cluttered", seed=seed, n_obstacles=25).write(tmp_path)
    meta = json.loads((folder / "world.json").read_text())
    for fmt in ("mjcf", "urdf"):
        path = folder / meta["files"][fmt]["path"]
        model = load(path)
        data = mujoco.MjData(model)
        mujoco.mj_forward(model, data)
        assert model.names.split(b"\0")[0].decode() == meta["world_id"]
        for entity in meta["entities"]:
            if entity["shape"] is None or (fmt == "urdf" and entity["role"] == "marker"):
                continue
            pos, rot = geom_frame(model, data, entity["name"])
            np.testing.assert_allclose(pos, entity["pose"][:3], atol=TOL, err_msg=f"{fmt} {entity['name']}")
            np.testing.assert_allclose(rot, rpy_matrix(*entity["pose"][3:]), atol=TOL)
            assert_same_shape(sdf_size(model, entity["name"]), entity["shape"], f"{fmt} {entity['name']}")
