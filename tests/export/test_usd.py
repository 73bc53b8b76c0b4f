"""world.usda read back with usd-core agrees with world.json and the SDF, passes usd-core's validators,
and is the same bytes in every process; without usd-core, asking for it is one line and no folder.

Every generator and every preset: each collider's pose and size within 1 mm of world.json, door
hinges (axis, limits, where the hinge is) against the SDF's, every time sample of every mover and
person within 1 mm of world.json's trajectory (and halfway between samples, where USD interpolates).
"""

from __future__ import annotations

import hashlib
import json
import math
import subprocess
import sys
from functools import lru_cache
from pathlib import Path

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from support.cli import run, world_dirs
from support.reftools_usd import open_stage, pxr_modules, validation_issues, world_matrix

import worldgen
from worldgen.errors import OutputError
from worldgen.generators.registry import names as generator_names
from worldgen.presets import generate_preset
from worldgen.presets import names as preset_names
from worldgen.scene.ground import ground_scene
from worldgen.scene.motion import positions_at
from worldgen.scene.pose import rpy_matrix

TOL = 1e-3  # m: what every format promises to agree within
CASES = [("generator", g, s) for g in generator_names() for s in (0, 1)] + [("preset", p, 0) for p in preset_names()]
IDS = [f"{kind}-{name}-s{seed}" for kind, name, seed in CASES]


@lru_cache(maxsize=None)
def _world(kind: str, name: str, seed: int):
    world = generate_preset(name, seed) if kind == "preset" else worldgen.generate(name, seed)
    return world, open_stage(world.export("usd"))


def _meta(world) -> dict:
    return world.metadata_for(world.rendered_files(["sdf", "usd"]))


def _shape_prims(stage) -> dict:
    """Scene node name -> its Xform prim (the parent of a `shape` prim), movers and people left out."""
    out = {}
    for prim in stage.Traverse():
        path = str(prim.GetPath())
        if prim.GetName() == "shape" and not path.startswith(("/World/Movers/", "/World/People/")):
            out[prim.GetParent().GetName()] = prim.GetParent()
    return out


@pytest.mark.parametrize("kind,name,seed", CASES, ids=IDS)
def test_stage_opens_and_every_validator_passes(kind, name, seed):
    world, stage = _world(kind, name, seed)
    Usd, UsdGeom, UsdPhysics, *_ = pxr_modules()
    assert stage.GetCompositionErrors() == []
    assert validation_issues(stage) == []
    assert UsdGeom.GetStageUpAxis(stage) == "Z" and UsdGeom.GetStageMetersPerUnit(stage) == 1.0
    assert UsdPhysics.GetStageKilogramsPerUnit(stage) == 1.0
    assert stage.GetDefaultPrim().GetPath() == "/World" and stage.GetTimeCodesPerSecond() == 60
    scene = UsdPhysics.Scene(stage.GetPrimAtPath("/World/PhysicsScene"))
    g = np.array(world.scene.physics.gravity)
    assert np.allclose(np.array(scene.GetGravityDirectionAttr().Get()) * scene.GetGravityMagnitudeAttr().Get(), g, atol=1e-5)


@pytest.mark.parametrize("kind,name,seed", CASES, ids=IDS)
def test_every_collider_agrees_with_world_json(kind, name, seed):
    """Pose and size of each entity's shape within 1 mm; collider, rigid body and friction as the scene says."""
    world, stage = _world(kind, name, seed)
    if world.scene.terrain is not None:
        # The terrain is world.json's terrain block, not an entity: the stage carries it as the one mesh
        # the formats with mesh colliders share (worldgen.scene.ground), in place of a floor it cuts.
        ground = ground_scene(world.scene)
        _assert_colliders_agree(ground, _entities(ground), stage)
        return
    _assert_colliders_agree(world.scene, _meta(world)["entities"], stage)


def _entities(scene) -> list[dict]:
    """world.json's entities[] (name, pose, shape) of a scene that has no World."""
    return [{"name": n.name, "pose": scene.world_pose(n.name).as_list(), "shape": n.shape and n.shape.describe()}
            for n in scene.nodes]


def _assert_colliders_agree(scene, entities, stage) -> None:
    Usd, UsdGeom, UsdPhysics, *_ = pxr_modules()
    prims = _shape_prims(stage)
    entities = [e for e in entities if e["shape"] is not None]
    assert sorted(prims) == sorted(e["name"] for e in entities)
    for entity in entities:
        node = scene.node(entity["name"])
        xform, shape = prims[entity["name"]], prims[entity["name"]].GetChild("shape")
        m = world_matrix(shape)
        pose = entity["pose"]
        assert np.allclose(m[:3, 3], pose[:3], atol=TOL), entity["name"]
        r = rpy_matrix(*pose[3:])
        described = entity["shape"]
        if described["type"] == "box":
            assert shape.GetTypeName() == "Cube" and shape.GetAttribute("size").Get() == 1.0
            expected = r * np.array(described["size"])  # unit cube: columns scaled by the extents
        elif described["type"] == "cylinder":
            assert shape.GetTypeName() == "Cylinder" and shape.GetAttribute("axis").Get() == "Z"
            assert abs(shape.GetAttribute("radius").Get() - described["radius"]) < TOL
            assert abs(shape.GetAttribute("height").Get() - described["length"]) < TOL
            expected = r
        elif described["type"] == "sphere":
            assert shape.GetTypeName() == "Sphere"
            assert abs(shape.GetAttribute("radius").Get() - described["radius"]) < TOL
            expected = r
        else:
            assert shape.GetTypeName() == "Mesh"
            assert np.allclose(np.array(shape.GetAttribute("points").Get()), node.shape.vertices, atol=1e-6)
            assert list(shape.GetAttribute("faceVertexIndices").Get()) == node.shape.faces.reshape(-1).tolist()
            expected = r * np.array(described["scale"])
        # Each column is a shape axis times its extent, so 1 mm here is 1 mm at the shape's faces.
        assert np.allclose(m[:3, :3], expected, atol=TOL), entity["name"]
        assert shape.HasAPI(UsdPhysics.CollisionAPI) == node.collision
        if node.collision:
            (target,) = shape.GetRelationship("material:binding:physics").GetTargets()
            material = UsdPhysics.MaterialAPI(stage.GetPrimAtPath(target))
            assert abs(material.GetDynamicFrictionAttr().Get() - node.material.friction) < 1e-6
            assert abs(material.GetStaticFrictionAttr().Get() - node.material.friction) < 1e-6
        in_body = any(not scene.node(a).static for a in _ancestors(scene, node))
        assert xform.HasAPI(UsdPhysics.RigidBodyAPI) == (not node.static and not in_body), entity["name"]
        if not node.static:
            assert abs(UsdPhysics.MassAPI(xform).GetMassAttr().Get() - node.mass) < 1e-6


def _ancestors(scene, node) -> list[str]:
    out, parent = [], node.parent
    while parent is not None:
        out.append(parent)
        parent = scene.node(parent).parent
    return out


def test_every_shape_kind_and_attachment_of_the_showcase_scene():
    """What no generator makes: spheres, meshes (scaled too), tilted shapes, free dynamic bodies, a marker,
    a leaf on a hinge whose frame is rolled (axis (0, 1, 0) in it) and that starts ajar, a handle on the leaf."""
    from support.scenes import showcase_scene

    from worldgen.export.sdf import to_sdf
    from worldgen.export.usd import to_usd
    from worldgen.scene.doors import door_records

    scene = showcase_scene()
    stage = open_stage(to_usd(scene, name="showcase").decode())
    Usd, UsdGeom, UsdPhysics, *_ = pxr_modules()
    assert stage.GetCompositionErrors() == [] and validation_issues(stage) == []
    _assert_colliders_agree(scene, _entities(scene), stage)
    _assert_hinges_agree(to_sdf(scene).decode(), door_records(scene), stage)
    joints = sorted(str(p.GetPath()) for p in stage.Traverse() if p.IsA(UsdPhysics.Joint))
    # The free bodies (crate, pebble, loose rock) have no joint; the handle rides the leaf's body.
    assert joints == ["/World/door_post/door_leaf/door_hinge"]
    assert not stage.GetPrimAtPath("/World/door_post/door_leaf/door_handle").HasAPI(UsdPhysics.RigidBodyAPI)


@settings(max_examples=25, deadline=None)
@given(yaw=st.floats(-1e-2, 1e-2), roll=st.floats(-0.3, 0.3), length=st.floats(1.0, 40.0))
def test_long_walls_turned_by_tiny_angles_stay_within_a_millimetre(yaw, roll, length):
    """USD turns an orient into a matrix through 2 acos(w), most sensitive near no turn at all: a 40 m
    wall turned by a hair must still end within 1 mm of where world.json has it."""
    from worldgen.export.usd import to_usd
    from worldgen.scene import Box, Node, Pose, Scene

    scene = Scene((Node("wall", "wall", Box((length, 0.1, 2.0)), Pose(1.0, 2.0, 1.0, roll, 0.0, yaw)),))
    _assert_colliders_agree(scene, _entities(scene), open_stage(to_usd(scene).decode()))


def _sdf_frames(sdf_text: str) -> dict:
    """Joint name -> (world origin, world unit axis, lower, upper) read off an SDF 1.9 world by hand:
    model pose, link poses relative to their parent links, the joint's pose in its child, axis in the joint."""
    from lxml import etree

    from worldgen.export.xml import safe_parser

    def matrix(text):
        x, y, z, roll, pitch, yaw = (float(v) for v in (text or "0 0 0 0 0 0").split())
        m = np.eye(4)
        m[:3, :3], m[:3, 3] = rpy_matrix(roll, pitch, yaw), (x, y, z)
        return m

    out = {}
    root = etree.fromstring(sdf_text.encode(), safe_parser())
    for model in root.iter("model"):
        base = matrix(model.findtext("pose"))
        links = {link.get("name"): link for link in model.findall("link")}
        placed: dict = {}

        def world_of(name):
            if name not in placed:
                pose = links[name].find("pose")
                if pose is None:
                    placed[name] = base
                else:
                    placed[name] = world_of(pose.get("relative_to")) @ matrix(pose.text)
            return placed[name]

        for joint in model.findall("joint[@type='revolute']"):
            frame = world_of(joint.findtext("child")) @ matrix(joint.findtext("pose"))
            axis = frame[:3, :3] @ np.array([float(v) for v in joint.findtext("axis/xyz").split()])
            limit = joint.find("axis/limit")
            out[joint.get("name")] = (frame[:3, 3], axis / np.linalg.norm(axis),
                                      float(limit.findtext("lower")), float(limit.findtext("upper")))
    return out


def _quat_matrix(q) -> np.ndarray:
    w, (x, y, z) = q.GetReal(), q.GetImaginary()
    n = math.sqrt(w * w + x * x + y * y + z * z)
    w, x, y, z = w / n, x / n, y / n, z / n
    return np.array([[1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)],
                     [2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)],
                     [2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)]])


def _joint_frame(stage, joint, side: int) -> np.ndarray:
    """The joint's frame on body ``side`` (0 or 1) in the world."""
    targets = joint.GetRelationship(f"physics:body{side}").GetTargets()
    body = world_matrix(stage.GetPrimAtPath(targets[0])) if targets else np.eye(4)
    local = np.eye(4)
    local[:3, :3] = _quat_matrix(joint.GetAttribute(f"physics:localRot{side}").Get())
    local[:3, 3] = np.array(joint.GetAttribute(f"physics:localPos{side}").Get())
    return body @ local


DOOR_CASES = [(kind, name, seed) for kind, name, seed in CASES if name in ("door", "door_crossing", "person_in_doorway")]


@pytest.mark.parametrize("kind,name,seed", DOOR_CASES, ids=[f"{k}-{n}-s{s}" for k, n, s in DOOR_CASES])
def test_door_hinges_agree_with_the_sdf_and_world_json(kind, name, seed):
    world, stage = _world(kind, name, seed)
    _assert_hinges_agree(world.to_sdf(), _meta(world)["doors"], stage)


@settings(max_examples=12, deadline=None)
@given(seed=st.integers(0, 10**6), n_doors=st.integers(1, 3), hinge_side=st.sampled_from(["left", "right", "random"]),
       swing=st.sampled_from(["push", "pull", "random"]), angle=st.floats(0.05, 1.4), damping=st.floats(0.0, 50.0))
def test_door_hinges_agree_over_the_door_parameters(seed, n_doors, hinge_side, swing, angle, damping):
    """Every hinge side, swing and starting state (ajar at any angle): the frames still read world.json's angle."""
    world = worldgen.generate("door", seed, size=[4.0 * n_doors + 4.0, 4.0], n_doors=n_doors, hinge_side=hinge_side,
                              swing=swing, state="random", angle=angle, door_damping=damping)
    _assert_hinges_agree(world.to_sdf(), _meta(world)["doors"], open_stage(world.export("usd")))


def _assert_hinges_agree(sdf_text: str, door_records: list, stage) -> None:
    """Axis, hinge, limits: the SDF's (whose limits are measured from the initial angle) and world.json's."""
    Usd, UsdGeom, UsdPhysics, *_ = pxr_modules()
    sdf = _sdf_frames(sdf_text)
    doors = {d["joint"]: d for d in door_records}
    joints = {p.GetName(): p for p in stage.Traverse() if p.IsA(UsdPhysics.RevoluteJoint)}
    assert sorted(joints) == sorted(doors) == sorted(sdf) and doors
    for name_, prim in joints.items():
        door, (origin, axis, lower, upper) = doors[name_], sdf[name_]
        joint = UsdPhysics.RevoluteJoint(prim)
        assert joint.GetAxisAttr().Get() == "Z"
        f0, f1 = _joint_frame(stage, prim, 0), _joint_frame(stage, prim, 1)
        assert np.allclose(f0[:3, 2], axis, atol=1e-5) and np.allclose(f1[:3, 2], door["axis"], atol=1e-5)
        assert np.allclose(f0[:3, 3], origin, atol=TOL) and np.allclose(f1[:3, 3], origin, atol=TOL)
        # The hinge line of world.json passes through the joint's origin.
        offset = origin - np.array(door["hinge"])
        assert np.linalg.norm(offset - offset.dot(axis) * axis) < TOL
        # Frame 1 is frame 0 turned about z by world.json's angle: the angle PhysX reads at the start.
        turn = f0[:3, :3].T @ f1[:3, :3]
        assert abs(math.atan2(turn[1, 0], turn[0, 0]) - door["angle"]) < 1e-5 and abs(turn[2, 2] - 1) < 1e-6
        lo, hi = math.radians(joint.GetLowerLimitAttr().Get()), math.radians(joint.GetUpperLimitAttr().Get())
        assert abs(lo - (lower + door["angle"])) < 1e-5 and abs(hi - (upper + door["angle"])) < 1e-5
        assert abs(lo - door["limits"][0]) < 1e-5 and abs(hi - door["limits"][1]) < 1e-5
        damping = prim.GetAttribute("drive:angular:physics:damping")
        assert abs((math.degrees(damping.Get()) if damping else 0.0) - door["damping"]) < 1e-3


MOVING_CASES = [(kind, name, seed) for kind, name, seed in CASES if kind == "preset" and name.startswith(("person", "group"))]


def _moving_worlds():
    for kind, name, seed in MOVING_CASES:
        yield f"{name}", *_world(kind, name, seed)
    for generator in generator_names():  # scripted movers, looping
        # A 1.5 m corridor (the default) leaves a robot no way past a mover: no such world is certified.
        wide = {"width": 3.0} if generator == "corridor" else {}
        world = worldgen.generate(generator, 0, n_movers=2, **wide)
        yield f"{generator}-movers", world, open_stage(world.export("usd"))


@pytest.mark.parametrize("index", range(len(MOVING_CASES) + len(generator_names())))
def test_every_time_sample_agrees_with_world_json(index):
    """Each sample, and each midpoint between samples, within 1 mm of world.json's walk at that time."""
    label, world, stage = list(_moving_worlds())[index]
    Usd, UsdGeom, UsdPhysics, *_ = pxr_modules()
    meta = _meta(world)
    movers = [(m, "Movers") for m in meta["dynamic_obstacles"]] + [(m, "People") for m in meta.get("people", [])]
    assert movers, label
    rate = stage.GetTimeCodesPerSecond()
    for entry, group in movers:
        prim = stage.GetPrimAtPath(f"/World/{group}/{entry['name']}")
        assert UsdPhysics.RigidBodyAPI(prim).GetKinematicEnabledAttr().Get() is True
        assert entry["formats"]["usd"] == "kinematic_body"
        shape = prim.GetChild("shape")
        assert abs(shape.GetAttribute("radius").Get() - entry["radius"]) < TOL
        translate = prim.GetAttribute("xformOp:translate")
        codes = np.array(translate.GetTimeSamples())
        track, loop = np.asarray(entry["trajectory"], dtype=float), bool(entry.get("loop", False))
        mids = (codes[:-1] + codes[1:]) / 2
        for times in (codes, mids):
            got = np.array([translate.Get(c) for c in times])
            want = positions_at([track], [loop], times / rate)[:, 0, :]
            assert np.abs(got[:, :2] - want).max() < TOL, (label, entry["name"])
            assert np.allclose(got[:, 2], entry["height"] / 2, atol=1e-9)
        if loop:  # written out over the longest time limit a task allows
            longest = max(t["time_limit"] for t in meta["tasks"] if t["time_limit"] is not None)
            assert codes[-1] / rate >= min(longest, 1e9) - 1e-6
        else:
            assert len(codes) == len(track)
        assert stage.GetEndTimeCode() >= codes[-1]


@pytest.mark.parametrize("kind,name,seed", CASES[::3], ids=IDS[::3])
def test_tasks_are_named_xforms_at_world_json_poses(kind, name, seed):
    world, stage = _world(kind, name, seed)
    for task in _meta(world)["tasks"]:
        for label in ("spawn", "goal"):
            prim = stage.GetPrimAtPath(f"/World/Tasks/{task['id']}/{label}")
            m, pose = world_matrix(prim), task[label]
            assert np.allclose(m[:3, 3], pose[:3], atol=TOL)
            assert np.allclose(m[:3, :3], rpy_matrix(*pose[3:]), atol=1e-5)
        tolerance = stage.GetPrimAtPath(f"/World/Tasks/{task['id']}/goal").GetAttribute("worldgen:goalTolerance")
        assert tolerance.Get() == task["goal_tolerance"]


_WRITE = (
    "import sys, worldgen\n"
    "from worldgen.presets import generate_preset\n"
    "for name in ('person_in_doorway', 'door_crossing'):\n"
    "    sys.stdout.write(generate_preset(name, 1).export('usd'))\n"
    "sys.stdout.write(worldgen.generate('cluttered', 2, n_movers=2).export('usd'))\n"
)


def test_the_same_bytes_in_two_processes():
    outs = [subprocess.run([sys.executable, "-c", _WRITE], capture_output=True, text=True, timeout=300) for _ in range(2)]
    assert all(o.returncode == 0 for o in outs), outs[0].stderr[-2000:]
    assert outs[0].stdout == outs[1].stdout and len(outs[0].stdout) > 10000


def test_writing_usd_changes_world_json_only_by_its_file_and_notes():
    world = generate_preset("person_crossing", 0)
    with_usd, without = _meta(world), world.metadata_for(world.rendered_files(["sdf"]))
    assert with_usd["files"].pop("usd")["path"] == "world.usda"
    for entry in with_usd["people"]:
        assert entry["formats"].pop("usd") == "kinematic_body"
    assert json.dumps(with_usd, sort_keys=True) == json.dumps(without, sort_keys=True)


def test_command_writes_and_check_reverifies_world_usda(tmp_path):
    res = run("generate", "door", "--out", tmp_path, "--formats", "usd,sdf")
    assert res.returncode == 0, res.stderr
    (folder,) = world_dirs(tmp_path)
    assert (folder / "world.usda").read_text().startswith("#usda 1.0")
    assert run("check", folder).returncode == 0
    usda = folder / "world.usda"
    usda.write_text(usda.read_text().replace("physics:upperLimit = ", "physics:upperLimit = 1"))
    res = run("check", folder)
    assert res.returncode != 0 and "world.usda" in res.stdout + res.stderr


_BLOCKED = (
    "import sys\n"
    "sys.modules['pxr'] = None  # as if usd-core were not installed\n"
    "from pathlib import Path\n"
    "import worldgen\n"
    "from worldgen.errors import MissingDependencyError\n"
    "from worldgen.verify import check_folder\n"
    "out = Path(sys.argv[1])\n"
    "world = worldgen.generate('door', 0)\n"
    "try:\n"
    "    world.write(out / 'a', formats=['sdf', 'usd'])\n"
    "    raise SystemExit('usd written without pxr')\n"
    "except MissingDependencyError as exc:\n"
    "    assert \"pip install 'worldgen[usd]'\" in str(exc) and '\\n' not in str(exc), exc\n"
    "assert not (out / 'a').exists()\n"
    "assert check_folder(world.write(out / 'b')).ok\n"
    "from worldgen.cli import main\n"
    "sys.argv = ['worldgen', 'generate', 'door', '--out', str(out / 'c'), '--formats', 'sdf,usd']\n"
    "raise SystemExit(main())\n"
)


def test_without_usd_core_one_line_and_no_folder(tmp_path):
    res = subprocess.run([sys.executable, "-c", _BLOCKED, str(tmp_path)], capture_output=True, text=True, timeout=300)
    assert res.returncode == 2, res.stderr[-2000:]
    assert res.stderr.count("\n") == 1 and "pip install 'worldgen[usd]'" in res.stderr and "usd-core" in res.stderr
    assert "Traceback" not in res.stderr
    assert sorted(p.name for p in tmp_path.iterdir()) == ["b"]  # the world without usd, and nothing else
    assert {p.name for p in next((tmp_path / "b").iterdir()).iterdir()} >= {"world.sdf", "world.mjcf.xml", "world.urdf"}
    assert not any(p.name == "world.usda" for p in (tmp_path / "b").rglob("*"))


_CHECK_BLOCKED = (
    "import sys\n"
    "sys.modules['pxr'] = None  # as if usd-core were not installed\n"
    "from worldgen.verify import check_folder\n"
    "for folder in sys.argv[1:]:\n"
    "    print(check_folder(folder).line())\n"
)


def test_check_without_usd_core_reproduces_every_other_file_and_says_what_it_left(tmp_path):
    """A folder with world.usda checked where usd-core is not installed: every other file is rendered again
    and compared, the usda's hash against world.json; a tampered SDF still fails, a tampered usda too."""
    world = generate_preset("person_crossing", 0)  # people: world.json names usd in their formats notes
    good = world.write(tmp_path / "good", formats=["sdf", "mjcf", "usd"])
    bad_sdf = world.write(tmp_path / "bad_sdf", formats=["sdf", "mjcf", "usd"])
    bad_usda = world.write(tmp_path / "bad_usda", formats=["sdf", "mjcf", "usd"])
    for folder, name in ((bad_sdf, "world.sdf"), (bad_usda, "world.usda")):
        (folder / name).write_text((folder / name).read_text() + "\n")
        meta = json.loads((folder / "world.json").read_text())
        key = "sdf" if name == "world.sdf" else "usd"
        meta["files"][key]["sha256"] = hashlib.sha256((folder / name).read_bytes()).hexdigest()
        (folder / "world.json").write_text(json.dumps(meta, indent=2, sort_keys=True) + "\n")
    res = subprocess.run([sys.executable, "-c", _CHECK_BLOCKED, str(good), str(bad_sdf), str(bad_usda)],
                         capture_output=True, text=True, timeout=300)
    assert res.returncode == 0, res.stderr[-2000:]
    lines = res.stdout.splitlines()
    assert lines[0] == (f"OK {good} (world.usda not rendered again: the optional dependency is not installed "
                        "here (sha256 checked against world.json))")
    # the edited SDF with its hash re-recorded: world.json then differs from a fresh export (files.sdf)
    assert lines[1].startswith(f"FAIL {bad_sdf}: reproduce: world.json differs from a fresh export at files.sdf.sha256")
    # the edited usda with its hash re-recorded is not rendered again here: world.json itself is compared,
    # and its files.usd entry was left out of that comparison, so only usd-core can tell (below)
    assert lines[2].startswith(f"OK {bad_usda}")
    from worldgen.verify import check_folder

    assert check_folder(good).ok and not check_folder(bad_usda).ok  # with usd-core: rendered and compared


def test_a_pack_recipe_with_usd_and_without_usd_core(tmp_path):
    recipe = tmp_path / "r.yaml"
    recipe.write_text("formats: [sdf, usd]\nseeds: 1\nworlds:\n  - generator: minimal\n")
    script = ("import sys\nsys.modules['pxr'] = None\nfrom worldgen.cli import main\n"
              f"sys.argv = ['worldgen', 'pack', 'build', {str(recipe)!r}, '--out', {str(tmp_path / 'pack')!r}]\nraise SystemExit(main())\n")
    res = subprocess.run([sys.executable, "-c", script], capture_output=True, text=True, timeout=300)
    assert res.returncode == 2 and "pip install 'worldgen[usd]'" in res.stderr, res.stderr[-2000:]
    assert not (tmp_path / "pack").exists()
    res = run("pack", "build", recipe, "--out", tmp_path / "pack")
    assert res.returncode == 0, res.stderr
    assert len(list(Path(tmp_path / "pack").rglob("world.usda"))) == 1


def test_a_world_written_without_usd_never_imports_usd_core(tmp_path):
    """Not asking for usd costs nothing: neither pxr nor the USD writer is imported."""
    script = (
        "import sys, worldgen\n"
        "world = worldgen.generate('door', 0, n_movers=1)\n"
        "world.write(sys.argv[1])\n"
        "print(sorted(m for m in sys.modules if m == 'pxr' or m.startswith(('pxr.', 'worldgen.export.usd'))))\n"
    )
    res = subprocess.run([sys.executable, "-c", script, str(tmp_path)], capture_output=True, text=True, timeout=300)
    assert res.returncode == 0 and res.stdout.strip() == "[]", res.stdout + res.stderr[-2000:]


def test_usdc_is_the_same_stage_in_binary(tmp_path):
    """world.usdc read back by usd-core is, as text, exactly world.usda; both written by one folder and checked."""
    _, _, _, Sdf, _ = pxr_modules()
    world = generate_preset("person_in_doorway", 0)
    folder = world.write(tmp_path, formats=["usd", "usdc"], preview=False)
    data = (folder / "world.usdc").read_bytes()
    assert data.startswith(b"PXR-USDC") and data == world.export_bytes("usdc")
    layer = Sdf.Layer.FindOrOpen(str(folder / "world.usdc"))
    assert layer.ExportToString() == (folder / "world.usda").read_text()
    with pytest.raises(OutputError, match="export_bytes"):
        world.export("usdc")
    meta = json.loads((folder / "world.json").read_text())
    assert meta["files"]["usdc"]["path"] == "world.usdc" and meta["people"][0]["formats"]["usdc"] == "kinematic_body"
    from worldgen.verify import check_folder

    assert check_folder(folder).ok


def test_usdc_is_the_same_bytes_in_two_processes():
    script = "import sys, worldgen\nsys.stdout.buffer.write(worldgen.generate('door', 0, n_movers=2).export_bytes('usdc'))\n"
    outs = [subprocess.run([sys.executable, "-c", script], capture_output=True, timeout=300) for _ in range(2)]
    assert all(o.returncode == 0 for o in outs) and outs[0].stdout == outs[1].stdout and len(outs[0].stdout) > 1000
