"""The terrain generator: seeded, deterministic, its world.json valid against the schema with the terrain,
the robot's limits and each path's terrain; its paths proven on drivable ground; bad input one line, exit 2."""

import json
import math

import numpy as np
import pytest
from support.cli import run

import worldgen
from worldgen.errors import ParameterError
from worldgen.export import metadata
from worldgen.feasibility.terrain import samples
from worldgen.generators import get
from worldgen.params import CLIMB_PARAMS
from worldgen.scene.drivable import terrain_footprints
from worldgen.scene.robot import CLIMB_DEFAULTS
from worldgen.scene.terrain import Ramp, Rough, Step


def test_the_same_seed_gives_the_same_bytes_and_another_seed_other_terrain():
    a, b = (worldgen.generate("terrain", 5, size=[12, 12]) for _ in range(2))
    assert a.folder_blobs() == b.folder_blobs()
    assert worldgen.generate("terrain", 6, size=[12, 12]).content_hash != a.content_hash


def test_world_json_carries_the_terrain_the_limits_and_each_paths_figures():
    world = worldgen.generate("terrain", 2, size=[14, 14], n_ramps=2, n_kerbs=3, n_rough=2, robot_max_incline=12)
    meta = json.loads(world.folder_blobs(formats=["mjcf"])["world.json"])
    metadata.validate(meta)
    assert meta["schema"] == metadata.SCHEMA_TERRAIN_ID
    assert meta["robot"]["max_incline"] == pytest.approx(math.radians(12), abs=1e-6)
    kinds = [e["kind"] for e in meta["terrain"]["elements"]]
    assert kinds == ["ramp"] * 2 + ["step"] * 3 + ["rough"] * 2
    for task in meta["tasks"]:
        profile = np.array(task["terrain"]["incline_profile"])
        assert profile[0, 0] == 0 and profile[-1, 0] == pytest.approx(task["path"]["length"], rel=6e-3)
        assert task["terrain"]["largest_incline"] <= meta["robot"]["max_incline"] + 1e-9
        assert task["terrain"]["largest_step"] <= meta["robot"]["max_step_up"] + 1e-9
    # The heights recorded are the model's at the points the profile names along the written path.
    for task in meta["tasks"]:
        s, xy = samples(np.array(task["path"]["waypoints"]))
        profile = np.array(task["terrain"]["incline_profile"])
        np.testing.assert_allclose(profile[:, 0], s, atol=2e-6)
        np.testing.assert_allclose(profile[:, 1], world.scene.terrain.heights(xy), atol=2e-6)


def test_every_path_keeps_its_footprint_off_ground_it_cannot_drive():
    import shapely
    for seed in range(6):
        world = worldgen.generate("terrain", seed, size=[12, 12], n_kerbs=4, kerb_height=[0.03, 0.08])
        forbidden = terrain_footprints(world.scene, world.robot)
        for path in world.feasibility.paths:
            line = shapely.LineString(path.waypoints)
            assert all(line.distance(f.polygon) >= world.robot.radius for f in forbidden)


def test_elements_come_from_the_parameters_ranges():
    world = worldgen.generate("terrain", 9, size=[16, 16], n_ramps=2, ramp_incline=[6, 7], ramp_rise=[0.1, 0.12],
                              n_kerbs=2, kerb_height=[0.02, 0.03], pothole_share=1.0, n_rough=1,
                              rough_amplitude=0.004)
    for e in world.scene.terrain.elements:
        if isinstance(e, Ramp):
            assert 6 - 1e-4 <= e.incline <= 7 + 1e-4 and 0.1 <= e.rise <= 0.12
        elif isinstance(e, Step):
            assert -0.03 <= e.height <= -0.02
        else:
            assert isinstance(e, Rough) and np.abs(e.array).max() <= 0.004


def test_the_climbing_parameters_defaults_are_the_robots():
    defaults = {p.name: p.default for p in CLIMB_PARAMS}
    assert math.radians(defaults["robot_max_incline"]) == pytest.approx(CLIMB_DEFAULTS["max_incline"], abs=1e-6)
    for name in ("max_step_up", "max_step_down", "ground_clearance"):
        assert defaults[f"robot_{name}"] == CLIMB_DEFAULTS[name]


@pytest.mark.parametrize("setting, message", [
    ("robot_max_incline=50", "parameter 'robot_max_incline' must be in [0, 45]"),
    ("robot_max_step_up=-0.1", "parameter 'robot_max_step_up' must be in [0, 0.5]"),
    ("ramp_incline=0.1,5", "parameter 'ramp_incline'"),
    ("kerb_height=0.3,0.9", "parameter 'kerb_height'"),
    ("ramp_width=12,14", "parameter 'ramp_width' must fit in the room"),
])
def test_bad_input_is_one_line_and_exit_2(tmp_path, setting, message):
    got = run("generate", "terrain", "--set", setting, "--out", tmp_path)
    assert got.returncode == 2
    lines = got.stderr.strip().splitlines()
    assert len(lines) == 1 and message in lines[0], got.stderr


def test_a_rough_patch_smaller_than_two_cells_is_refused():
    with pytest.raises(ParameterError, match="rough_size"):
        get("terrain").resolve({"rough_size": [0.3, 0.4], "rough_cell": 0.25})


def test_worldgen_check_re_proves_a_terrain_world_and_catches_a_changed_limit(tmp_path):
    got = run("generate", "terrain", "--seed", "4", "--set", "n_kerbs=4", "--set", "pothole_share=0.5", "--out", tmp_path)
    assert got.returncode == 0, got.stderr
    (folder,) = [p for p in tmp_path.iterdir() if p.is_dir()]
    assert run("check", folder).returncode == 0
    meta_path = folder / "world.json"
    meta = json.loads(meta_path.read_text())
    meta["robot"]["max_step_up"] = 0.5  # a robot that could climb anything: not the world that was proven
    meta_path.write_text(json.dumps(meta, indent=2, sort_keys=True) + "\n")
    checked = run("check", folder)
    assert checked.returncode == 1 and "FAIL" in checked.stdout + checked.stderr


def test_cluttered_takes_terrain_as_an_option_and_keeps_its_obstacles():
    flat = worldgen.generate("cluttered", 2, size=[10, 10], n_obstacles=10)
    bumpy = worldgen.generate("cluttered", 2, size=[10, 10], n_obstacles=10, terrain=True, n_kerbs=3,
                              robot_max_incline=12)
    assert flat.scene.terrain is None and "terrain" not in flat.params and "n_kerbs" not in flat.params
    assert bumpy.params["terrain"] is True and bumpy.params["n_kerbs"] == 3
    assert bumpy.robot.max_incline == pytest.approx(math.radians(12), abs=1e-6)
    kinds = [type(e).__name__ for e in bumpy.scene.terrain.elements]
    assert kinds.count("Step") == 3
    assert flat.attempts == bumpy.attempts == 1
    obstacles = [n for n in flat.scene.nodes if n.role == "obstacle"]
    assert obstacles == [n for n in bumpy.scene.nodes if n.role == "obstacle"]  # the terrain has its own stream
    assert bumpy.feasibility.check("terrain_drivable").ok
    meta = json.loads(bumpy.folder_blobs(formats=["mjcf"])["world.json"])
    metadata.validate(meta)
    assert meta["schema"] == metadata.SCHEMA_TERRAIN_ID


def test_a_terrain_parameter_without_the_option_is_one_line_and_exit_2(tmp_path):
    got = run("generate", "cluttered", "--set", "n_kerbs=3", "--out", tmp_path)
    assert got.returncode == 2
    assert got.stderr.strip() == ("error: parameter 'n_kerbs' belongs to the terrain option, which is off: set "
                                  "terrain=true too, or leave it out; got n_kerbs=3")


def test_a_generator_without_the_terrain_option_refuses_it_in_one_line(tmp_path):
    got = run("generate", "door", "--set", "terrain=true", "--out", tmp_path)
    assert got.returncode == 2 and len(got.stderr.strip().splitlines()) == 1
    assert got.stderr.startswith("error: unknown parameter 'terrain'")


def test_a_terrain_world_is_the_same_bytes_in_another_process(tmp_path):
    params = {"size": [12, 12], "n_ramps": 2, "n_kerbs": 3, "n_rough": 2, "pothole_share": 0.5}
    sets = [a for k, v in params.items() for a in ("--set", f"{k}={','.join(map(str, v)) if isinstance(v, list) else v}")]
    got = run("generate", "terrain", "--seed", "8", *sets, "--out", tmp_path)
    assert got.returncode == 0, got.stderr
    (folder,) = [p for p in tmp_path.iterdir() if p.is_dir()]
    blobs = worldgen.generate("terrain", 8, **params).folder_blobs()
    written = {p.relative_to(folder).as_posix(): p.read_bytes() for p in folder.rglob("*") if p.is_file()}
    assert set(blobs) <= set(written)
    assert {k: v for k, v in written.items() if k in blobs} == blobs
