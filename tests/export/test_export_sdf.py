"""SDF export: strict libsdformat acceptance, read-back through libsdformat, physics, determinism.

Every comparison goes through what libsdformat itself understood of the file
(``reftools_sdf.dump_sdf``), not through our own reading of the XML, so a pose
written in the wrong frame or a size in the wrong unit shows up here.
"""

from __future__ import annotations

import hashlib
import math
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
from support import draft
from support.reftools_sdf import check_sdf, dump_sdf

from worldgen.errors import ParameterError, WorldgenError
from worldgen.export.meshes import mesh_files
from worldgen.export.sdf import MIN_MOMENT, to_sdf
from worldgen.export.xml import parse_bytes
from worldgen.scene import Box, Cylinder, Joint, Material, Mesh, Node, Physics, Pose, Scene, Sphere, rpy_matrix

VERSIONS = ("1.9", "1.6")
TOL = 2e-6  # floats are written with 6 decimals

#: (seed, params) draws of the cluttered generator: defaults and the corners of its options.
CLUTTERED_CASES = [(seed, {}) for seed in range(8)] + [
    (8, {"walls": False}),
    (9, {"obstacle_shapes": "box", "n_obstacles": 40}),
    (10, {"obstacle_shapes": "cylinder", "size": [6.0, 14.0]}),
    (11, {"random_yaw": False, "n_obstacles": 0}),
    (12, {"density": 0.3, "real_time_factor": 0.0}),
    (13, {"size": [20.0, 20.0], "n_obstacles": 50, "step_size": 0.004}),
]


def rock(uri: str = "meshes/rock.stl") -> Mesh:
    """A closed octahedron whose bounding-box centre is off its frame's origin."""
    v = np.array([[0.3, 0, 0], [-0.2, 0, 0], [0, 0.25, 0], [0, -0.15, 0], [0, 0, 0.35], [0, 0, -0.1]]) + [0.05, 0.02, 0]
    f = [[0, 2, 4], [2, 1, 4], [1, 3, 4], [3, 0, 4], [2, 0, 5], [1, 2, 5], [3, 1, 5], [0, 3, 5]]
    return Mesh(uri, v, f)


def hand_scene() -> Scene:
    """Every shape kind, tilted shapes, dynamic bodies, a marker and a door on a turned hinge frame."""
    wood = Material("wood", (0.6, 0.4, 0.2, 1.0), 0.6)
    grey = Material("grey", (0.5, 0.5, 0.5, 1.0), 0.9)
    stone = rock()
    nodes = (
        Node("floor", "floor", Box((8.0, 8.0, 0.1)), Pose(0, 0, -0.05), material=grey),
        Node("wall_a", "wall", Box((6.0, 0.1, 1.0)), Pose(0, 3.5, 0.5), material=grey),
        Node("tilted_box", "obstacle", Box((0.4, 0.6, 0.8)), Pose(-2.0, 1.0, 0.6, 0.3, -0.2, 1.1), material=wood),
        Node("tilted_cylinder", "obstacle", Cylinder(0.2, 1.2), Pose(-1.0, -2.0, 0.7, 1.2, 0.1, -0.4)),
        Node("ball", "obstacle", Sphere(0.3), Pose(2.0, -2.0, 0.3), static=False, mass=3.0),
        Node("rock", "obstacle", stone, Pose(-2.5, -1.0, 0.2, 0.1, 0.2, 0.7)),
        Node("big_rock", "obstacle", Mesh(stone.uri, stone.vertices, stone.faces, (2.0, 1.5, 1.0)),
             Pose(2.5, 2.0, 0.2, 0, 0, -0.5)),
        Node("loose_rock", "obstacle", stone, Pose(-0.5, 1.5, 0.12, 0, 0, 0.3), static=False, mass=2.0),
        Node("pebble", "obstacle", Sphere(0.01), Pose(1.0, 1.0, 0.01), static=False, mass=0.001),
        Node("goal_marker", "marker", Cylinder(0.25, 0.01), Pose(1.5, 0.0, 0.005),
             material=Material("goal", (0.1, 0.9, 0.1, 0.5))),
        Node("door_post", "door_frame", Box((0.1, 0.1, 2.0)), Pose(-1.0, 0.5, 1.0, 0, 0, 0.2), material=grey),
        Node("door_leaf", "door", Box((0.9, 0.04, 1.8)), Pose(0.41, 0.27, -0.05, 0, 0, 0.4), parent="door_post",
             static=False, mass=10.0, material=wood),
        Node("door_handle", "door", Sphere(0.04), Pose(0.35, 0.06, 0.0, 0.2, 0.3, 0.1), parent="door_leaf", mass=0.2),
    )
    hinge = Joint("door_hinge", "revolute", "door_post", "door_leaf",
                  pose=Pose(-0.45, 0.0, 0.0, math.pi / 2, 0.0, 0.0), axis=(0.0, 1.0, 0.0),
                  limits=(-1.5, 1.5), initial=0.4, damping=2.0)
    return Scene(nodes, (hinge,), ((-3.0, -3.0), (3.0, 3.0)), Physics(0.002, 1.0))


def write_world(scene: Scene, folder: Path, version: str) -> Path:
    """The SDF file plus the mesh files it names, as World.write lays them out."""
    path = folder / f"world-{version}.sdf"
    path.write_bytes(to_sdf(scene, version, name="test_world"))
    for rel, data in mesh_files(scene).items():
        (folder / rel).parent.mkdir(parents=True, exist_ok=True)
        (folder / rel).write_bytes(data)
    return path


def pose_matrix(values) -> np.ndarray:
    m = np.eye(4)
    m[:3, :3] = rpy_matrix(*values[3:])
    m[:3, 3] = values[:3]
    return m


def shape_values(shape) -> tuple[str, list]:
    if isinstance(shape, Box):
        return "box", list(shape.size)
    if isinstance(shape, Cylinder):
        return "cylinder", [shape.radius, shape.length]
    if isinstance(shape, Sphere):
        return "sphere", [shape.radius]
    return "mesh", [shape.uri, *shape.scale]


def assert_same_values(got, want, what):
    assert len(got) == len(want), what
    for g, w in zip(got, want):
        if isinstance(w, str):
            assert g == w, what
        else:
            assert g == pytest.approx(w, abs=TOL), what


def assert_matches_scene(dump: dict, scene: Scene) -> None:
    """Everything libsdformat read equals the scene: names, world poses, shapes, mass, surfaces."""
    roots = {}
    for node in scene.nodes:
        root = node
        while root.parent is not None:
            root = scene.node(root.parent)
        roots[node.name] = root.name
    assert sorted(dump["models"]) == sorted({r for r in roots.values()})
    assert len(dump["links"]) == len(scene.nodes)
    for node in scene.nodes:
        model = dump["models"][roots[node.name]]
        key = f"{roots[node.name]}::{node.name}"
        link = dump["links"][key]
        world = pose_matrix(model["pose"]) @ pose_matrix(link["pose"])
        np.testing.assert_allclose(world, scene.world_matrix(node.name), atol=1e-5, err_msg=key)
        subtree_static = all(n.static for n in scene.nodes if roots[n.name] == roots[node.name])
        assert model["static"] is subtree_static, key
        if not subtree_static:
            assert link["mass"] == pytest.approx(node.mass, abs=TOL), key
            want = [max(i, MIN_MOMENT) for i in node.inertia]
            assert_same_values(link["inertia"], want, key)
        if node.shape is None:  # a pure frame: a link with nothing in it
            assert f"{key}::visual" not in dump["visuals"] and f"{key}::collision" not in dump["collisions"]
            continue
        kind, values = shape_values(node.shape)
        visual = dump["visuals"][f"{key}::visual"]
        assert visual[0] == kind, key
        assert_same_values(visual[1], values, key)
        ambient, diffuse = dump["materials"][f"{key}::visual"]
        assert_same_values(ambient, node.material.rgba, key)
        assert_same_values(diffuse, node.material.rgba, key)
        if node.collision:
            collision = dump["collisions"][f"{key}::collision"]
            assert collision[0] == kind and collision[1] == visual[1], key
            mu = node.material.friction
            assert dump["friction"][f"{key}::collision"] == pytest.approx((mu, mu), abs=TOL), key
        else:
            assert f"{key}::collision" not in dump["collisions"], f"{key} must have no collision"


# -- the checker itself must be strict ------------------------------------------------------------

@pytest.mark.parametrize("version", VERSIONS)
def test_checker_rejects_a_misspelt_element(tmp_path, version):
    scene, _ = draft("cluttered", seed=1)
    good = write_world(scene, tmp_path, version)
    ok, messages = check_sdf(good)
    assert ok, messages
    bad = tmp_path / "misspelt.sdf"
    bad.write_text(good.read_text().replace("<static>", "<statik>", 1).replace("</static>", "</statik>", 1))
    ok, messages = check_sdf(bad)
    assert not ok
    assert any("statik" in m for m in messages), messages


def test_checker_holds_a_16_file_to_the_16_spec(tmp_path):
    """<intensity> is a light element of 1.9 only: fine in a 1.9 file, an error in a 1.6 one."""
    scene, _ = draft("cluttered", seed=2)
    for version, expect_ok in (("1.9", True), ("1.6", False)):
        text = write_world(scene, tmp_path, version).read_text()
        newer = tmp_path / f"newer-{version}.sdf"
        newer.write_text(text.replace("<direction>", "<intensity>2</intensity><direction>", 1))
        ok, messages = check_sdf(newer)
        assert ok is expect_ok, (version, messages)
        if not expect_ok:
            assert any("intensity" in m for m in messages), messages


def test_checker_rejects_a_mesh_file_that_is_not_there(tmp_path):
    path = tmp_path / "world.sdf"
    path.write_bytes(to_sdf(hand_scene(), "1.9"))
    ok, messages = check_sdf(path)
    assert not ok
    assert any("meshes/rock.stl" in m for m in messages), messages


# -- generated and hand-built worlds --------------------------------------------------------------

@pytest.mark.parametrize("version", VERSIONS)
@pytest.mark.parametrize("seed,params", CLUTTERED_CASES, ids=[f"s{s}" for s, _ in CLUTTERED_CASES])
def test_cluttered_worlds_pass_and_read_back(tmp_path, version, seed, params):
    scene, _ = draft("cluttered", seed=seed, **params)
    dump = dump_sdf(write_world(scene, tmp_path, version))
    assert_matches_scene(dump, scene)
    assert dump["world"] == "test_world"
    assert dump["lights"] == ["sun"]
    assert not dump["joints"]


@pytest.mark.parametrize("version", VERSIONS)
def test_hand_scene_passes_and_reads_back(tmp_path, version):
    scene = hand_scene()
    dump = dump_sdf(write_world(scene, tmp_path, version))
    assert_matches_scene(dump, scene)
    hinge = dump["joints"]["door_post::door_hinge"]
    assert (hinge["type"], hinge["parent"], hinge["child"]) == ("revolute", "door_post", "door_leaf")
    assert hinge["axis"] == pytest.approx([0, 1, 0], abs=TOL)
    # The poses written are the joint's zero, so the limits count from the initial angle.
    assert hinge["limits"] == pytest.approx([-1.5 - 0.4, 1.5 - 0.4], abs=TOL)
    assert hinge["damping"] == pytest.approx(2.0)
    handle = dump["joints"]["door_post::door_handle_fixed"]
    assert (handle["type"], handle["parent"], handle["child"]) == ("fixed", "door_leaf", "door_handle")
    # The post is static but carries a swinging leaf: the model moves, the post is welded to the world.
    weld = dump["joints"]["door_post::door_post_world"]
    assert (weld["type"], weld["parent"], weld["child"]) == ("fixed", "world", "door_post")
    assert not dump["models"]["door_post"]["static"]


@pytest.mark.parametrize("version", VERSIONS)
def test_frames_and_a_root_hinged_to_the_world(tmp_path, version):
    """A shape-less frame between two links, and a root swinging on a revolute joint to the world."""
    nodes = (
        Node("floor", "floor", Box((4.0, 4.0, 0.1)), Pose(0, 0, -0.05)),
        Node("flap", "door", Box((0.6, 0.05, 0.4)), Pose(1.0, 0.0, 0.5, 0, 0, 0.7), static=False, mass=2.0),
        Node("mount", "obstacle", None, Pose(0.2, 0.0, 0.1, 0.3, 0, 0), parent="flap"),
        Node("knob", "obstacle", Cylinder(0.02, 0.05), Pose(0.0, 0.05, 0.0, 0, 1.2, 0), parent="mount", mass=0.05),
    )
    hinge = Joint("flap_hinge", "revolute", "world", "flap", Pose(-0.3, 0, 0), (0, 0, 1), (-1.0, 1.0), 0.0, 0.1)
    scene = Scene(nodes, (hinge,))
    dump = dump_sdf(write_world(scene, tmp_path, version))
    assert_matches_scene(dump, scene)
    assert dump["joints"]["flap::flap_hinge"]["parent"] == "world"
    assert dump["joints"]["flap::knob_fixed"]["parent"] == "mount"
    assert sorted(dump["joints"]) == ["flap::flap_hinge", "flap::knob_fixed", "flap::mount_fixed"]


def test_16_and_19_describe_the_same_world(tmp_path):
    scene = hand_scene()
    old, new = (dump_sdf(write_world(scene, tmp_path, v)) for v in ("1.6", "1.9"))
    for key, link in new["links"].items():
        model = key.split("::")[0]
        a = pose_matrix(old["models"][model]["pose"]) @ pose_matrix(old["links"][key]["pose"])
        b = pose_matrix(new["models"][model]["pose"]) @ pose_matrix(link["pose"])
        np.testing.assert_allclose(a, b, atol=1e-5, err_msg=key)
    assert old["joints"] == new["joints"]
    assert old["collisions"] == new["collisions"]


def test_markers_and_collision_free_nodes_have_only_a_visual():
    tree = parse_bytes(to_sdf(hand_scene()))
    link = tree.find(".//model[@name='goal_marker']/link[@name='goal_marker']")
    assert link.find("collision") is None
    assert link.find("visual/geometry/cylinder") is not None
    assert link.find("visual/transparency").text == "0.5"


def test_mesh_inertial_sits_at_the_bounding_box_centre():
    tree = parse_bytes(to_sdf(hand_scene()))
    pose = tree.find(".//link[@name='loose_rock']/inertial/pose")
    v = rock().scaled_vertices()
    want = (v.min(axis=0) + v.max(axis=0)) / 2
    assert [float(x) for x in pose.text.split()] == pytest.approx([*want, 0, 0, 0], abs=TOL)


# -- physics, names, determinism, errors ----------------------------------------------------------

@pytest.mark.parametrize("version", VERSIONS)
@pytest.mark.parametrize("step,rtf,rate", [(0.002, 1.0, 500.0), (0.001, 2.5, 2500.0), (0.004, 0.0, 0.0)])
def test_physics_values_are_written(tmp_path, version, step, rtf, rate):
    base = hand_scene()
    scene = Scene(base.nodes, base.joints, base.bounds, Physics(step, rtf, (0.0, 0.5, -3.7)))
    dump = dump_sdf(write_world(scene, tmp_path, version))
    assert dump["physics"] == pytest.approx((step, rtf))
    assert dump["update_rate"] == pytest.approx(rate)
    assert dump["gravity"] == pytest.approx([0.0, 0.5, -3.7])


def test_the_world_is_named_and_self_contained():
    scene, _ = draft("cluttered", seed=4)
    text = to_sdf(scene, name="cluttered-s4-0123abcd").decode()
    root = parse_bytes(text.encode()).getroot()
    assert root.find("world").get("name") == "cluttered-s4-0123abcd"
    assert "model://" not in text and "<include" not in text
    assert root.find(".//ground_plane") is None and root.find(".//plane") is None
    assert [m.get("name") for m in root.iter("model")] == [n.name for n in scene.nodes]


@pytest.mark.parametrize("version", VERSIONS)
def test_output_bytes_are_deterministic(version):
    scene = hand_scene()
    first = to_sdf(scene, version)
    assert to_sdf(hand_scene(), version) == first
    assert b"-0 " not in first and b">-0<" not in first and b"e-0" not in first


def test_output_bytes_match_in_a_fresh_process():
    code = (
        "import hashlib, sys; sys.path.insert(0, 'tests')\n"
        "from support import draft\n"
        "from worldgen.export.sdf import to_sdf\n"
        "scene, _ = draft('cluttered', seed=0)\n"
        "print(hashlib.sha256(to_sdf(scene, '1.9') + to_sdf(scene, '1.6')).hexdigest())\n"
    )
    root = Path(__file__).resolve().parents[2]
    out = subprocess.run([sys.executable, "-c", code], cwd=root, capture_output=True, text=True, check=True)
    scene, _ = draft("cluttered", seed=0)
    here = hashlib.sha256(to_sdf(scene, "1.9") + to_sdf(scene, "1.6")).hexdigest()
    assert out.stdout.strip() == here


def test_unknown_version_names_the_parameter():
    with pytest.raises(ParameterError, match=r"sdf_version.*1\.9, 1\.6.*'1\.7'"):
        to_sdf(hand_scene(), "1.7")


def test_a_joint_across_models_is_refused():
    nodes = (Node("a", "obstacle", Sphere(0.1)), Node("b", "obstacle", Sphere(0.1), Pose(1, 0, 0)))
    scene = Scene(nodes, (Joint("j", "fixed", "a", "b"),))
    with pytest.raises(WorldgenError, match="'j'.*not in the model of 'b'"):
        to_sdf(scene)


def test_generated_joint_names_avoid_scene_names():
    nodes = (
        Node("base", "door_frame", Box((0.1, 0.1, 1.0))),
        Node("arm", "door", Box((0.5, 0.1, 0.1)), Pose(0.3, 0, 0), parent="base"),
        Node("arm_fixed", "marker", Sphere(0.05), Pose(0, 0, 2)),
    )
    names = [j.get("name") for j in parse_bytes(to_sdf(Scene(nodes))).iter("joint")]
    assert names == ["arm_fixed_1"]


def test_world_to_sdf_names_the_world_after_its_id():
    from worldgen.generators import robot_from_params
    from worldgen.generators.registry import get
    from worldgen.world import World

    scene, tasks = draft("cluttered", seed=5)
    robot = robot_from_params(get("cluttered").resolve({}))
    world = World("cluttered", 5, {}, scene, tasks, robot, feasibility=None, attempts=1)
    for version in VERSIONS:
        root = parse_bytes(world.to_sdf(version).encode()).getroot()
        assert root.get("version") == version
        assert root.find("world").get("name") == world.world_id


def test_a_missing_compiler_is_reported_not_crashed(monkeypatch):
    from support import reftools_sdf

    monkeypatch.setattr(reftools_sdf.shutil, "which", lambda name: None)
    assert reftools_sdf._build.__wrapped__() == "missing:g++ (to build tests/tools/sdf_check.cc)"
