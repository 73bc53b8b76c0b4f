"""world.json: its schema, its canonical form, and that what it says is true of the world.

The first half builds metadata from hand-made worlds (a feasibility report is
plain data, so it can be written down); the second half generates and writes
real worlds end to end and checks every world.json against the files beside it.
"""

from __future__ import annotations

import copy
import hashlib
import json
import math
import re

import jsonschema
import numpy as np
import pytest
import shapely
from support import draft

import worldgen
from worldgen.export import metadata
from worldgen.feasibility.report import CHECKER, REQUIRED_CHECKS, Check, FeasibilityReport, TaskPath
from worldgen.generators import get, robot_from_params
from worldgen.scene import Box, Cylinder, Joint, Mesh, Node, Pose, Scene, Sphere, Task
from worldgen.scene.footprint import scene_footprints
from worldgen.world import World

VALIDATOR = jsonschema.Draft202012Validator(metadata.schema())


# -- hand-made worlds ---------------------------------------------------------

def _tetra(uri="meshes/tetra.stl", scale=(1.0, 1.0, 1.0)) -> Mesh:
    v = [[0, 0, 0], [0.4, 0, 0], [0, 0.4, 0], [0, 0, 0.4]]
    f = [[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]]
    return Mesh(uri, v, f, scale)


def every_shape_scene() -> Scene:
    """Every shape kind, a dynamic body, a marker, and a child on a revolute joint."""
    nodes = (
        Node("floor", "floor", Box((10.2, 10.2, 0.1)), Pose(0, 0, -0.05)),
        Node("crate", "obstacle", Box((0.5, 0.4, 0.3)), Pose(1.0, 2.0, 0.15, 0, 0, 0.3)),
        Node("pole", "obstacle", Cylinder(0.2, 1.2), Pose(-2.0, 1.0, 0.6)),
        Node("ball", "obstacle", Sphere(0.25), Pose(2.0, -2.0, 0.25), static=False, mass=2.0),
        Node("rock", "obstacle", _tetra(scale=(2.0, 1.0, 1.5)), Pose(-3.0, -3.0, 0.0, 0, 0, 0.5)),
        Node("spot", "marker", Cylinder(0.3, 0.01), Pose(0.0, -4.0, 0.005)),
        Node("post", "door_frame", Box((0.1, 0.1, 2.0)), Pose(3.0, 3.0, 1.0, 0, 0, math.pi / 2)),
        Node("leaf", "door", Box((0.8, 0.04, 1.8)), Pose(0.45, 0.0, -0.05), parent="post", static=False, mass=8.0),
    )
    joints = (Joint("hinge", "revolute", "post", "leaf", Pose(-0.4, 0, 0), limits=(-1.5, 1.5)),)
    return Scene(nodes, joints, ((-5.0, -5.0), (5.0, 5.0)))


def fake_report(tasks, feasible=True, with_paths=True) -> FeasibilityReport:
    """A report as the contract in feasibility/report.py defines it; straight paths."""
    checks = tuple(Check(name, feasible or name != "path_exists", 0.25, f"{name} detail") for name in REQUIRED_CHECKS)
    paths = tuple(
        TaskPath(t.id, np.array([[t.spawn.x, t.spawn.y], [0.1, 0.2], [t.goal.x, t.goal.y]]),
                 math.dist((t.spawn.x, t.spawn.y), (0.1, 0.2)) + math.dist((0.1, 0.2), (t.goal.x, t.goal.y)), 0.31)
        if with_paths else None
        for t in tasks
    )
    return FeasibilityReport(checks, paths, 0.9 if with_paths else None, CHECKER)


def hand_world(scene=None, tasks=None, feasible=True, with_paths=True, **params) -> World:
    resolved = get("cluttered").resolve(params)
    scene = scene or every_shape_scene()
    tasks = tasks or (Task("task_0", Pose(-4.0, 0.0, 0.0, 0, 0, 0.5), Pose(4.0, -1.0, 0.0, 0, 0, -1.0), 0.2),)
    return World("cluttered", 11, resolved, scene, tasks, robot_from_params(resolved),
                 fake_report(tasks, feasible, with_paths), 3)


FILES = {"sdf": ("world.sdf", "a" * 64), "mesh:meshes/tetra.stl": ("meshes/tetra.stl", "b" * 64)}


# -- the schema itself ---------------------------------------------------------

def test_schema_is_valid_draft_2020_12_and_shipped_with_the_package():
    schema = metadata.schema()
    jsonschema.Draft202012Validator.check_schema(schema)
    assert schema["$schema"] == "https://json-schema.org/draft/2020-12/schema"
    assert schema["properties"]["schema"]["enum"] == [metadata.SCHEMA_ID, metadata.SCHEMA_TERRAIN_ID]


def _walk_properties(node, path="$"):
    if isinstance(node, dict):
        for name, sub in node.get("properties", {}).items():
            yield f"{path}.{name}", sub
        for key, sub in node.items():
            yield from _walk_properties(sub, f"{path}.{key}")
    elif isinstance(node, list):
        for i, sub in enumerate(node):
            yield from _walk_properties(sub, f"{path}[{i}]")


def test_every_schema_field_is_documented():
    schema = metadata.schema()
    fields = list(_walk_properties(schema))
    assert len(fields) > 60
    undocumented = [path for path, sub in fields
                    if "description" not in sub and "description" not in _resolve(schema, sub)]
    assert undocumented == []


_NUMERIC_REFS = {"#/$defs/finite", "#/$defs/nonneg", "#/$defs/positive", "#/$defs/pose", "#/$defs/floor_pose",
                 "#/$defs/point2", "#/$defs/point3"}
_UNIT = re.compile(r"\b(m|rad|s|kg|m/s|count|unitless)\b")


def _numeric(sub) -> bool:
    if sub.get("$ref") in _NUMERIC_REFS or sub.get("type") in ("number", "integer"):
        return True
    if sub.get("type") == "array":
        return _numeric(sub.get("items", {}))
    return any(_numeric(option) for option in sub.get("oneOf", []))


def test_every_numeric_field_states_its_unit():
    numeric = [(path, sub) for path, sub in _walk_properties(metadata.schema()) if _numeric(sub)]
    assert len(numeric) > 40
    assert [path for path, sub in numeric if not _UNIT.search(sub.get("description", ""))] == []


def _resolve(schema, sub):
    ref = sub.get("$ref")
    if not ref:
        return {}
    node = schema
    for part in ref.lstrip("#/").split("/"):
        node = node[part]
    return node


# -- build() on a hand-made world -----------------------------------------------

def test_hand_world_validates_and_says_what_the_scene_says():
    world = hand_world()
    meta = metadata.build(world, FILES)
    VALIDATOR.validate(meta)
    scene = world.scene
    assert [e["name"] for e in meta["entities"]] == [n.name for n in scene.nodes]
    by_name = {e["name"]: e for e in meta["entities"]}
    # World-frame pose of the child = parent's transform composed with its own.
    leaf = by_name["leaf"]
    expected = scene.world_matrix("post") @ Pose(0.45, 0.0, -0.05).matrix()
    assert np.allclose(Pose(*leaf["pose"]).matrix(), expected, atol=1e-6)
    assert leaf["static"] is False and leaf["role"] == "door"
    # SDF sizes, never half sizes.
    assert by_name["crate"]["shape"] == {"type": "box", "size": [0.5, 0.4, 0.3]}
    assert by_name["pole"]["shape"] == {"type": "cylinder", "radius": 0.2, "length": 1.2}
    assert by_name["ball"]["shape"] == {"type": "sphere", "radius": 0.25}
    assert by_name["rock"]["shape"] == {"type": "mesh", "uri": "meshes/tetra.stl", "scale": [2.0, 1.0, 1.5]}
    for e in meta["entities"]:
        assert np.allclose(e["aabb"], scene.aabb(e["name"]), atol=1e-6)
    assert meta["metrics"]["obstacle_count"] == 4
    assert meta["feasibility"]["attempts"] == 3
    assert meta["feasibility"]["checks"][0] == {"name": "inside_bounds", "ok": True, "value": 0.25,
                                                 "detail": "inside_bounds detail"}
    assert meta["files"] == {"sdf": {"path": "world.sdf", "sha256": "a" * 64},
                             "mesh:meshes/tetra.stl": {"path": "meshes/tetra.stl", "sha256": "b" * 64}}
    assert meta["content_hash"] == world.content_hash and meta["world_id"] == world.world_id
    assert meta["worldgen_version"] == worldgen.__version__
    assert meta["params"] == world.params  # every parameter, resolved


def test_task_ground_truth_and_time_limit():
    world = hand_world(robot_speed=0.8)
    task = metadata.build(world, FILES)["tasks"][0]
    path = world.feasibility.paths[0]
    assert task["straight_line_distance"] == pytest.approx(math.hypot(8.0, 1.0), abs=1e-6)
    assert task["path"]["length"] == pytest.approx(path.length, abs=1e-6)
    assert task["time_limit"] == pytest.approx(2 * path.length / 0.8 + 10, abs=1e-6)
    assert task["path"]["waypoints"][0] == task["spawn"][:2]
    assert task["path"]["waypoints"][-1] == task["goal"][:2]
    assert task["requires_door_open"] is False


def test_infeasible_world_on_purpose_still_follows_the_schema():
    meta = metadata.build(hand_world(feasible=False, with_paths=False), FILES)
    VALIDATOR.validate(meta)
    assert meta["feasibility"]["feasible"] is False
    assert meta["tasks"][0]["path"] is None and meta["tasks"][0]["time_limit"] is None


def test_unbounded_figures_become_null_not_infinity():
    world = hand_world()
    report = world.feasibility
    world.feasibility = FeasibilityReport(
        tuple(Check(c.name, True, math.inf) for c in report.checks),
        tuple(TaskPath(p.task_id, p.waypoints, p.length, math.inf) for p in report.paths), math.inf, CHECKER)
    meta = metadata.build(world, FILES)
    VALIDATOR.validate(meta)
    assert meta["feasibility"]["narrowest_passage"] is None
    assert meta["tasks"][0]["path"]["min_clearance"] is None
    assert "Infinity" not in metadata.dumps(meta)


# -- canonical text --------------------------------------------------------------

def test_dumps_is_canonical_and_rounds_every_float():
    meta = metadata.build(hand_world(), FILES)
    text = metadata.dumps(meta)
    assert text.endswith("}\n") and not text.endswith("\n\n")
    assert metadata.dumps(json.loads(text)) == text
    assert json.loads(text) == meta
    assert text.splitlines()[1].startswith('  "') and not text.splitlines()[1].startswith('   ')
    assert "-0.0," not in text and "-0.0]" not in text
    keys = [line.split('"')[1] for line in text.splitlines() if line.startswith('  "')]
    assert keys == sorted(keys)
    assert metadata.dumps({"b": [1.23456789, -1e-9, 2], "a": {"z": True, "y": None}}) == (
        '{\n  "a": {\n    "y": null,\n    "z": true\n  },\n  "b": [1.234568, 0.0, 2]\n}\n')


def test_dumps_refuses_non_finite_numbers():
    with pytest.raises(ValueError):
        metadata.dumps({"x": float("nan")})
    with pytest.raises(ValueError):
        metadata.dumps({"x": [1.0, float("inf")]})


# -- the schema rejects what it must -----------------------------------------------

def _drop(key):
    def f(m, key=key):
        parts = key.split(".")
        for p in parts[:-1]:
            m = m[int(p)] if p.isdigit() else m[p]
        del m[parts[-1]]
    return f


MUTATIONS = {
    "no world_id": _drop("world_id"),
    "no tasks path": _drop("tasks.0.path"),
    "no entity aabb": _drop("entities.0.aabb"),
    "no feasibility checks": _drop("feasibility.checks"),
    "unknown top-level field": lambda m: m.update(extra=1),
    "unknown entity field": lambda m: m["entities"][0].update(colour="red"),
    "pose of five numbers": lambda m: m["entities"][1].update(pose=[0, 0, 0, 0, 0]),
    "text in a pose": lambda m: m["entities"][1].update(pose=[0, 0, 0, 0, 0, "0"]),
    "spawn above the floor": lambda m: m["tasks"][0]["spawn"].__setitem__(2, 0.5),
    "unknown role": lambda m: m["entities"][0].update(role="tree"),
    "half-size box": lambda m: m["entities"][1].update(shape={"type": "box", "half_size": [1, 1, 1]}),
    "negative radius": lambda m: m["entities"][2]["shape"].update(radius=-0.2),
    "required check missing": lambda m: m["feasibility"].update(
        checks=[c for c in m["feasibility"]["checks"] if c["name"] != "path_clearance"]),
    "check name not snake case": lambda m: m["feasibility"]["checks"][0].update(name="Spawn Free"),
    "no tasks": lambda m: m.update(tasks=[]),
    "bad sha256": lambda m: m["files"]["sdf"].update(sha256="xyz"),
    "absolute file path": lambda m: m["files"]["sdf"].update(path="/etc/passwd"),
    "file path escaping": lambda m: m["files"]["sdf"].update(path="../world.sdf"),
    "unknown file key": lambda m: m["files"].update(obj={"path": "w.obj", "sha256": "c" * 64}),
    "wrong schema id": lambda m: m.update(schema="worldgen.world/3"),
    "a flat world saying it has terrain": lambda m: m.update(schema="worldgen.world/2"),
    "content hash without prefix": lambda m: m.update(content_hash="0" * 64),
    "huge number": lambda m: m["robot"].update(radius=1e301),
    "free_area_ratio above 1": lambda m: m["metrics"].update(free_area_ratio=1.5),
    "float seed": lambda m: m.update(seed=1.5),
    "missing robot_speed param": lambda m: m["params"].pop("robot_speed"),
}


@pytest.mark.parametrize("mutation", sorted(MUTATIONS))
def test_schema_rejects(mutation):
    meta = metadata.build(hand_world(), FILES)
    VALIDATOR.validate(meta)
    bad = copy.deepcopy(meta)
    MUTATIONS[mutation](bad)
    assert not VALIDATOR.is_valid(bad), mutation


def test_schema_accepts_the_optional_blocks():
    meta = metadata.build(hand_world(), FILES)
    meta["metrics"].update(tortuosity=1.2, dispersion=0.3)
    meta["sensors"] = {"lidar": {"pose": [0, 0, 0.3, 0, 0, 0], "angle_min": -3.1, "angle_max": 3.1, "samples": 3,
                                 "range_min": 0.1, "range_max": 10.0, "ranges": [1.0, 10.0, 2.5]}}
    meta["occupancy"] = {"image": "map.pgm", "yaml": "map.yaml", "resolution": 0.05, "origin": [-5.0, -5.0, 0.0]}
    VALIDATOR.validate(meta)


# -- free_area_ratio against an independent union ---------------------------------

def _union_ratio(scene, height):
    """Every shadow unioned as a fine polygon, clipped to the bounds: slow and plain."""
    (x0, y0), (x1, y1) = scene.bounds
    area = shapely.box(x0, y0, x1, y1)
    geoms = [shapely.Point(fp.centre).buffer(fp.radius, quad_segs=256) if fp.is_disc else fp.polygon
             for fp in scene_footprints(scene, height)]
    return 1 - shapely.intersection(shapely.union_all(geoms), area).area / area.area


def test_free_area_ratio_of_known_layouts():
    floor = Node("floor", "floor", Box((10.2, 10.2, 0.1)), Pose(0, 0, -0.05))
    bounds = ((-5.0, -5.0), (5.0, 5.0))
    one_box = Scene((floor, Node("b", "obstacle", Box((2, 2, 1)), Pose(0, 0, 0.5, 0, 0, 0.7))), (), bounds)
    assert metadata.free_area_ratio(one_box, 0.4) == pytest.approx(0.96, abs=1e-9)
    one_disc = Scene((floor, Node("c", "obstacle", Cylinder(1.0, 1.0), Pose(0, 0, 0.5))), (), bounds)
    assert metadata.free_area_ratio(one_disc, 0.4) == pytest.approx(1 - math.pi / 100, abs=1e-9)
    # Above the robot's head, or a marker: no shadow at all.
    high = Scene((floor, Node("h", "obstacle", Box((2, 2, 1)), Pose(0, 0, 2.0)),
                  Node("m", "marker", Box((3, 3, 0.01)), Pose(0, 0, 0.005))), (), bounds)
    assert metadata.free_area_ratio(high, 0.4) == 1.0


def test_free_area_ratio_counts_overlaps_once_and_clips_to_bounds():
    floor = Node("floor", "floor", Box((10.2, 10.2, 0.1)), Pose(0, 0, -0.05))
    nodes = [floor,
             Node("a", "obstacle", Box((2, 2, 1)), Pose(0, 0, 0.5)),
             Node("b", "obstacle", Box((2, 2, 1)), Pose(1, 1, 0.5, 0, 0, 0.3)),       # overlaps a
             Node("c", "obstacle", Cylinder(0.5, 1), Pose(-1, 0, 0.5)),             # overlaps a
             Node("d", "obstacle", Cylinder(0.5, 1), Pose(-3, -3, 0.5)),
             Node("e", "obstacle", Cylinder(0.6, 1), Pose(-3, -2.2, 0.5)),          # overlaps d
             Node("f", "obstacle", Box((2, 2, 1)), Pose(5, 0, 0.5)),                # half outside
             Node("g", "obstacle", Sphere(0.5), Pose(3, -3, 0.3)),
             Node("w", "wall", Box((10, 0.1, 1)), Pose(0, 5.05, 0.5))]              # outside: none
    scene = Scene(tuple(nodes), (), ((-5.0, -5.0), (5.0, 5.0)))
    assert metadata.free_area_ratio(scene, 0.4) == pytest.approx(_union_ratio(scene, 0.4), abs=2e-4)


@pytest.mark.parametrize("seed", [0, 1, 2])
def test_free_area_ratio_of_cluttered_drafts(seed):
    scene, _ = draft(seed=seed, n_obstacles=60, min_gap=0.0)
    assert metadata.free_area_ratio(scene, 0.4) == pytest.approx(_union_ratio(scene, 0.4), abs=2e-4)


# -- real worlds, end to end ------------------------------------------------------

SEEDS = list(range(12))


@pytest.fixture(scope="module")
def written(tmp_path_factory):
    """Worlds of many seeds (and a few parameter sets) written to disk once."""
    out = tmp_path_factory.mktemp("worlds")
    cases = [(seed, {}) for seed in SEEDS] + [
        (3, {"size": [20, 20], "n_obstacles": 50, "n_tasks": 3}),
        (4, {"walls": False, "obstacle_shapes": "cylinder"}),
        (5, {"n_obstacles": 0}),
    ]
    return [(worldgen.generate("cluttered", seed, **params).write(out), params) for seed, params in cases]


def test_written_world_json_is_valid_canonical_and_true(written):
    for folder, params in written:
        text = (folder / "world.json").read_text()
        meta = json.loads(text)
        VALIDATOR.validate(meta)
        assert metadata.dumps(meta) == text, folder
        assert meta["world_id"] == folder.name
        assert meta["feasibility"]["feasible"] is True
        assert {c["name"] for c in meta["feasibility"]["checks"]} >= set(REQUIRED_CHECKS)
        assert set(meta["files"]) >= {"sdf", "mjcf", "urdf"}
        for key, entry in meta["files"].items():
            data = (folder / entry["path"]).read_bytes()
            assert hashlib.sha256(data).hexdigest() == entry["sha256"], (folder, key)
        # Every file in the folder is listed (nothing stray, nothing unhashed), but for
        # preview.png: a picture of world.json, deliberately unlisted (worldgen.export.preview).
        listed = {e["path"] for e in meta["files"].values()} | {"world.json", "preview.png"}
        on_disk = {str(p.relative_to(folder)) for p in folder.rglob("*") if p.is_file()}
        assert on_disk == listed

        regenerated = worldgen.generate(meta["generator"], meta["seed"], **meta["params"])
        assert regenerated.content_hash == meta["content_hash"]  # params are enough to rebuild it
        names = [e["name"] for e in meta["entities"]]
        assert len(names) == len(set(names))
        assert names == [n.name for n in regenerated.scene.nodes]

        robot = meta["robot"]
        assert len(meta["tasks"]) == params.get("n_tasks", 1)
        for task in meta["tasks"]:
            path = task["path"]
            assert path["waypoints"][0] == pytest.approx(task["spawn"][:2], abs=1e-6)
            assert path["waypoints"][-1] == pytest.approx(task["goal"][:2], abs=1e-6)
            polyline = sum(math.dist(a, b) for a, b in zip(path["waypoints"], path["waypoints"][1:]))
            # length: the exact taut path (arcs included); the polyline rounds each arc on a
            # circumscribed polygon, so it is a hair longer (METADATA allows 2 %, we keep 0.5 %).
            assert path["length"] - 1e-5 <= polyline <= path["length"] * 1.005 + 1e-5
            assert path["length"] >= task["straight_line_distance"] - 1e-6
            if path["min_clearance"] is not None:
                assert path["min_clearance"] >= robot["clearance"] - 1e-6
            assert task["time_limit"] == pytest.approx(
                2 * path["length"] / meta["params"]["robot_speed"] + 10, abs=1e-5)
        expected_obstacles = params.get("n_obstacles", 20)
        assert meta["metrics"]["obstacle_count"] == expected_obstacles
        assert 0 < meta["metrics"]["free_area_ratio"] <= 1
        if expected_obstacles == 0:
            assert meta["metrics"]["free_area_ratio"] == 1.0


def test_in_memory_metadata_equals_the_written_one(written):
    folder, _ = written[0]
    meta = json.loads((folder / "world.json").read_text())
    world = worldgen.generate("cluttered", meta["seed"], **meta["params"])
    assert world.metadata == meta
    assert world.to_json() == (folder / "world.json").read_text()


def test_feasibility_names_its_method_and_keeps_no_shim_fields():
    meta = worldgen.generate("cluttered", 0, size=[6, 6], n_obstacles=3).metadata
    assert meta["feasibility"]["checker"] == "exact_tangent_graph+fcl"
    assert "resolution" not in meta["feasibility"]  # the grid planner's cell size: the exact planner has none
