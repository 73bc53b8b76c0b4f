"""URDF exporter and mesh files: check_urdf accepts every world, MuJoCo loads and steps it cleanly."""

from __future__ import annotations

import math
import struct

import mujoco
import numpy as np
import pytest
import trimesh
from support import draft
from support.reftools_mujoco import load_and_step
from support.reftools_urdf import check_urdf
from support.scenes import rock_mesh, showcase_scene

from worldgen.export import meshes, urdf
from worldgen.export.xml import parse_bytes
from worldgen.scene import Box, Mesh, Node, Pose, Scene

CLUTTERED_CASES = [(seed, {}) for seed in range(30)] + [
    (0, {"size": [20.0, 20.0], "n_obstacles": 200}),
    (4, {"walls": False, "n_obstacles": 30}),
    (6, {"n_obstacles": 0}),
]


def write_world(folder, scene: Scene, name: str = "world"):
    """world.urdf and its mesh files in ``folder``, as World.write lays them out; returns the URDF path."""
    data = urdf.to_urdf(scene, name=name)
    for rel, blob in meshes.mesh_files(scene).items():
        (folder / rel).parent.mkdir(parents=True, exist_ok=True)
        (folder / rel).write_bytes(blob)
    path = folder / "world.urdf"
    path.write_bytes(data)
    return path


@pytest.mark.parametrize("seed,params", CLUTTERED_CASES, ids=lambda v: str(v) if isinstance(v, int) else None)
def test_cluttered_worlds_pass_check_urdf_and_mujoco(tmp_path, seed, params):
    scene, _ = draft("cluttered", seed, **params)
    path = write_world(tmp_path, scene)
    out = check_urdf(path)
    assert f"root Link: world has {len(scene.nodes)} child(ren)" in out
    model, _ = load_and_step(path)
    assert {model.body(i).name for i in range(1, model.nbody)} == {n.name for n in scene.nodes}
    assert {model.geom(i).name for i in range(model.ngeom)} == {n.name for n in scene.nodes}
    assert model.nq == 0  # every static entity is welded to the world


def test_showcase_passes_check_urdf_and_loads_from_file_and_from_memory(tmp_path):
    scene = showcase_scene()
    path = write_world(tmp_path, scene, name="showcase")
    out = check_urdf(path)
    assert "robot name is: showcase" in out
    assert "door_leaf" in out and "door_handle" in out
    model, data = load_and_step(path)
    same, _ = load_and_step(path.read_text(), assets=meshes.mesh_files(scene))
    assert same.ngeom == model.ngeom and same.nbody == model.nbody
    # Markers are visual only: a link, but no collision geom.
    assert model.body("goal_marker").geomnum[0] == 0
    hinge = model.joint("door_hinge")
    assert hinge.type[0] == mujoco.mjtJoint.mjJNT_HINGE
    # The written pose is the initial angle (0.4 rad): limits (-1.5, 1.5) are counted from it.
    np.testing.assert_allclose(model.jnt_range[hinge.id], (-1.9, 1.1))
    assert model.dof_damping[model.jnt_dofadr[hinge.id]] == pytest.approx(2.0)
    free = {model.joint(i).name for i in range(model.njnt) if model.jnt_type[i] == mujoco.mjtJoint.mjJNT_FREE}
    assert free == {"crate", "pebble", "loose_rock"}
    for name, height in (("crate", 0.15), ("pebble", 0.1)):
        assert data.body(name).xpos[2] == pytest.approx(height, abs=0.01)
    for node in scene.nodes:
        assert model.body(node.name).mass[0] == pytest.approx(node.mass)


def test_revolute_joints_carry_limit_and_dynamics_and_friction_goes_to_gazebo_tags():
    scene = showcase_scene()
    root = parse_bytes(urdf.to_urdf(scene)).getroot()
    joint = root.find("joint[@name='door_hinge']")
    assert joint.get("type") == "revolute"
    limit = joint.find("limit")
    assert {k: float(limit.get(k)) for k in ("lower", "upper", "effort", "velocity")} == {
        "lower": -1.9, "upper": 1.1, "effort": 100.0, "velocity": 2.0}
    assert float(joint.find("dynamics").get("damping")) == 2.0
    for node in scene.nodes:
        gz = root.find(f"gazebo[@reference='{node.name}']")
        if not node.collision:
            assert gz is None and root.find(f"link[@name='{node.name}']/collision") is None
            continue
        assert float(gz.findtext("mu1")) == float(gz.findtext("mu2")) == pytest.approx(node.material.friction)
    # Every link has a positive mass and inertia; the root link has none at all.
    assert root.find("link[@name='world']/inertial") is None
    for link in root.findall("link")[1:]:
        inertia = link.find("inertial/inertia")
        assert float(link.find("inertial/mass").get("value")) > 0
        assert all(float(inertia.get(k)) > 0 for k in ("ixx", "iyy", "izz"))


def test_materials_are_shared_by_name_and_split_when_a_name_has_two_colours():
    from worldgen.scene import Material

    a = Material("paint", (1.0, 0.0, 0.0, 1.0))
    b = Material("paint", (0.0, 0.0, 1.0, 1.0))
    nodes = tuple(Node(f"n{i}", "obstacle", Box((1, 1, 1)), Pose(2 * i, 0, 0.5), material=m)
                  for i, m in enumerate((a, a, b)))
    root = parse_bytes(urdf.to_urdf(Scene(nodes))).getroot()
    colours = {m.get("name"): m.find("color").get("rgba") for m in root.findall("material")}
    assert colours == {"paint": "1 0 0 1", "paint_1": "0 0 1 1"}
    used = [root.find(f"link[@name='n{i}']/visual/material").get("name") for i in range(3)]
    assert used == ["paint", "paint", "paint_1"]


def test_same_scene_same_bytes():
    a = urdf.to_urdf(showcase_scene(), name="x")
    assert a == urdf.to_urdf(showcase_scene(), name="x")
    assert b"-0 " not in a and b'"-0"' not in a


# -- mesh files ----------------------------------------------------------------

def test_mesh_files_are_binary_stl_with_a_blank_header_and_stable_bytes():
    scene = showcase_scene()
    files = meshes.mesh_files(scene)
    assert list(files) == ["meshes/rock.stl"]  # three nodes, one geometry: one file
    data = files["meshes/rock.stl"]
    assert data == meshes.mesh_files(showcase_scene())["meshes/rock.stl"]
    assert data[:80] == b"\0" * 80  # no name, no date, nothing that changes between runs
    rock = rock_mesh()
    (count,) = struct.unpack("<I", data[80:84])
    assert count == len(rock.faces) and len(data) == 84 + 50 * count
    back = trimesh.load(trimesh.util.wrap_as_stream(data), file_type="stl", process=False)
    np.testing.assert_allclose(back.triangles, rock.vertices[rock.faces], atol=1e-6)
    # Normals point outward, as written (the mesh is closed and outward-facing).
    assert back.is_volume or back.volume > 0


def test_mesh_bytes_hold_no_negative_zero():
    v = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1]], dtype=float) * -1.0  # -0.0 entries
    mesh = Mesh("meshes/t.stl", v, [[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]])
    data = meshes.stl_bytes(mesh)
    floats = np.frombuffer(b"".join(data[84 + 50 * i: 84 + 50 * i + 48] for i in range(4)), dtype="<f4")
    assert not np.any(np.signbit(floats) & (floats == 0))


def test_one_uri_for_two_geometries_is_refused():
    rock = rock_mesh("meshes/same.stl")
    other = Mesh("meshes/same.stl", rock.vertices * 2, rock.faces)
    scene = Scene((Node("a", "obstacle", rock), Node("b", "obstacle", other, Pose(2, 0, 0))))
    with pytest.raises(ValueError, match="meshes/same.stl"):
        meshes.mesh_files(scene)


def test_hinged_root_and_child_on_a_fixed_scene_joint(tmp_path):
    from worldgen.scene import Joint

    nodes = (
        Node("floor", "floor", Box((4, 4, 0.1)), Pose(0, 0, -0.05)),
        Node("gate", "door", Box((1.0, 0.05, 1.0)), Pose(0, 0, 0.6, 0, 0, 0.3), static=False, mass=3.0),
        Node("sign", "obstacle", Box((0.2, 0.02, 0.2)), Pose(0.3, 0, 0.3), parent="gate"),
    )
    joints = (Joint("swing", "revolute", "world", "gate", axis=(0, 0, 1), limits=(-math.pi, math.pi), initial=0.3),
              Joint("bolt", "fixed", "gate", "sign"))
    path = write_world(tmp_path, Scene(nodes, joints))
    check_urdf(path)
    model, _ = load_and_step(path)
    assert model.nq == 1 and model.joint("swing").type[0] == mujoco.mjtJoint.mjJNT_HINGE
    assert model.body("sign").parentid[0] == model.body("gate").id
