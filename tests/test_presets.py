"""Presets: each generates and is what its description says; every mistake in a preset file gets one
line naming the file and the key; the API and the CLI both reach them."""

from __future__ import annotations

import json
import math
from importlib import resources

import numpy as np
import pytest

from test_cli import run, world_dirs
from test_corridor import PASSAGE_CELLS, recheck
from test_minimal import ray
import worldgen
from worldgen import presets
from worldgen.errors import InfeasibleError, ParameterError

SHIPPED = ["clutter_50_boxes", "door_crossing", "drl_arena", "empty_room", "lidar_wall", "narrow_corridor",
           "room_5_obstacles"]


def roles(world, role):
    return [n for n in world.scene.nodes if n.role == role]


def test_the_shipped_presets_are_the_files_in_templates():
    folder = resources.files("worldgen.templates").joinpath("presets")
    assert presets.names() == SHIPPED == sorted(p.name[:-5] for p in folder.iterdir() if p.name.endswith(".yaml"))
    for p in presets.all_presets():
        assert p.description and p.reproduces and p.source.endswith(f"{p.name}.yaml")


# -- each preset is what it says -------------------------------------------------------------

def test_empty_room():
    world = worldgen.generate_preset("empty_room")
    recheck(world)
    assert not roles(world, "obstacle") and len(roles(world, "wall")) == 4
    assert world.scene.bounds == ((-5.0, -5.0), (5.0, 5.0))
    t = world.tasks[0]
    assert (t.spawn.x, t.spawn.y) == (-4.5, -4.5)  # the corner start, 0.5 m in from both walls
    assert (t.goal.x - t.spawn.x, t.goal.y - t.spawn.y) == (5.0, 5.0)
    assert world.feasibility.paths[0].length == pytest.approx(5 * math.sqrt(2), abs=1e-6)


def test_room_with_5_obstacles():
    for seed in range(3):
        world = worldgen.generate_preset("room_5_obstacles", seed=seed)
        recheck(world)
        assert len(roles(world, "obstacle")) == 5 and world.scene.bounds == ((-5.0, -5.0), (5.0, 5.0))


def test_narrow_corridor_is_0_8_m_wide_and_says_so():
    world = worldgen.generate_preset("narrow_corridor")
    recheck(world)
    report = world.feasibility
    assert 0.8 - PASSAGE_CELLS * report.resolution <= report.narrowest_passage <= 0.8 + 1e-6
    assert world.metadata["feasibility"]["narrowest_passage"] == pytest.approx(report.narrowest_passage, abs=1e-6)
    (x0, y0), (x1, y1) = world.scene.bounds
    assert y1 - y0 == pytest.approx(0.8) and x1 - x0 == pytest.approx(10.0)


def test_door_crossing_path_crosses_the_closed_door_at_x_3():
    world = worldgen.generate_preset("door_crossing")
    meta = world.metadata
    door = meta["doors"][0]
    assert door["state"] == "closed"
    assert abs(door["passage"]["center"][0] - 3.0) <= 0.1  # the doorway, in a wall at x = 3
    task = meta["tasks"][0]
    assert task["goal"][:2] == [6.0, 0.0] and task["requires_door_open"] is True
    xs = np.array(task["path"]["waypoints"])[:, 0]
    assert xs.min() < 3.0 < xs.max()


def test_50_random_boxes_in_20_by_20():
    world = worldgen.generate_preset("clutter_50_boxes", seed=1)
    recheck(world)
    obstacles = roles(world, "obstacle")
    assert len(obstacles) == 50 and {o.shape.kind for o in obstacles} == {"box"}
    assert world.scene.bounds == ((-10.0, -10.0), (10.0, 10.0))


def test_drl_arena_draws_spawn_and_goal_within_4_5_m_where_free():
    for seed in range(6):
        world = worldgen.generate_preset("drl_arena", seed=seed)
        recheck(world)
        assert len(roles(world, "wall")) == 4 and {o.shape.kind for o in roles(world, "obstacle")} == {"box"}
        for pose in (world.tasks[0].spawn, world.tasks[0].goal):
            assert abs(pose.x) <= 4.5 and abs(pose.y) <= 4.5


def test_lidar_wall_is_2_m_straight_ahead():
    world = worldgen.generate_preset("lidar_wall")
    spawn = world.tasks[0].spawn
    d, name = ray(world, (spawn.x, spawn.y), spawn.yaw, 0.3)
    assert name == "target" and abs(d - 2.0) <= 1e-6


# -- the API ---------------------------------------------------------------------------------

def test_overrides_win_and_the_world_regenerates_without_the_preset():
    world = worldgen.generate_preset("narrow_corridor", seed=5, width=1.0, shape="L")
    assert world.generator == "corridor" and world.params["width"] == 1.0 and world.params["shape"] == "L"
    again = worldgen.generate(world.generator, seed=5, **world.metadata["params"])
    assert again.content_hash == world.content_hash


def test_a_preset_file_by_path(tmp_path):
    path = tmp_path / "mine.yaml"
    path.write_text("name: mine\ndescription: d\nreproduces: r\ngenerator: corridor\n"
                    "params: {shape: zigzag, segments: [3, 3, 3], turns: [left, right]}\n")
    world = worldgen.generate_preset(str(path))
    assert world.params["turns"] == "left,right" and world.params["segments"] == [3.0, 3.0, 3.0]


# -- bad preset files: one line naming the file and the key ----------------------------------

GOOD = {"name": "p", "description": "d", "reproduces": "r", "generator": "cluttered", "params": "{n_obstacles: 3}"}


def _text(**changes):
    fields = {**GOOD, **changes}
    return "".join(f"{k}: {v}\n" for k, v in fields.items() if v is not None)


@pytest.mark.parametrize("text,pattern", [
    (_text(extra="1"), r"preset file '.*p.yaml': unknown key 'extra'; allowed: name, description, reproduces, generator, params$"),
    (_text(reproduces=None), r"preset file '.*p.yaml': key 'reproduces' is missing$"),
    (_text(name="other"), r"preset file '.*p.yaml': key 'name' must equal the file's name 'p', got 'other'$"),
    (_text(description="''"), r"preset file '.*p.yaml': key 'description' must be a non-empty string"),
    (_text(params="[1, 2]"), r"preset file '.*p.yaml': key 'params' must be a mapping"),
    (_text(params="{n_obstacles: -1}"),
     r"preset file '.*p.yaml': key 'params' \(generator 'cluttered'\): parameter 'n_obstacles' must be in \[0, 5000\], got -1$"),
    (_text(params="{colour: red}"), r"preset file '.*p.yaml': key 'params' \(generator 'cluttered'\): unknown parameter 'colour'"),
    (_text(generator="maze"), r"preset file '.*p.yaml': key 'params' \(generator 'maze'\): unknown generator 'maze'"),
    ("name: p\n  description: [unclosed\n", r"preset file '.*p.yaml' is not valid YAML at line \d+"),
    ("- just\n- a list\n", r"preset file '.*p.yaml' must hold a mapping with keys name, description"),
    ("!!python/object/apply:os.system [echo hi]\n", r"preset file '.*p.yaml' is not valid YAML"),  # safe_load only
])
def test_bad_preset_files_get_one_line_naming_file_and_key(tmp_path, text, pattern):
    path = tmp_path / "p.yaml"
    path.write_text(text)
    with pytest.raises(worldgen.WorldgenError, match=pattern) as err:
        presets.load(str(path))
    assert "\n" not in str(err.value)


def test_unknown_preset_names_the_available_ones(tmp_path):
    with pytest.raises(ParameterError, match=r"^unknown preset 'nope'; available: clutter_50_boxes, door_crossing"):
        worldgen.generate_preset("nope")
    with pytest.raises(ParameterError, match=r"^preset file '.*missing.yaml' does not exist$"):
        worldgen.generate_preset(str(tmp_path / "missing.yaml"))
    with pytest.raises(ParameterError, match=r"^parameter 'width' must be in \[0.05, 50\], got -1"):
        worldgen.generate_preset("narrow_corridor", width=-1)
    with pytest.raises(InfeasibleError, match=r"^corridor width 0.8 m cannot pass a 0.45 m radius robot"):
        worldgen.generate_preset("narrow_corridor", robot_radius=0.45)


# -- the command line, end to end ------------------------------------------------------------

def test_cli_presets_lists_every_name_with_its_description():
    done = run("presets")
    assert done.returncode == 0, done.stderr
    lines = done.stdout.splitlines()
    assert [line.split()[0] for line in lines] == SHIPPED
    for line, preset in zip(lines, presets.all_presets()):
        assert line.endswith(preset.description)
    as_json = json.loads(run("presets", "--json").stdout)
    assert [p["name"] for p in as_json] == SHIPPED and as_json[0]["generator"] == "cluttered"


def test_cli_generate_with_a_preset_and_an_override(tmp_path):
    done = run("generate", "--preset", "narrow_corridor", "--set", "length=6", "--seed", "2", "--out", tmp_path)
    assert done.returncode == 0, done.stderr
    (folder,) = world_dirs(tmp_path)
    meta = json.loads((folder / "world.json").read_text())
    assert meta["generator"] == "corridor" and meta["params"]["width"] == 0.8 and meta["params"]["length"] == 6.0
    assert meta["seed"] == 2 and folder.name.startswith("corridor-s2-")


@pytest.mark.parametrize("args,message", [
    (["--preset", "nope"], "error: unknown preset 'nope'; available: clutter_50_boxes"),
    (["cluttered", "--preset", "empty_room"], "error: give either GENERATOR or --preset, not both"),
    ([], "error: give a GENERATOR (see 'worldgen list') or --preset NAME (see 'worldgen presets')"),
    (["--preset", "narrow_corridor", "--set", "robot_radius=0.45"],
     "error: corridor width 0.8 m cannot pass a 0.45 m radius robot with 0.05 m clearance (needs >= 1.0 m)"),
    (["--preset", "lidar_wall", "--set", "target_distance=0.1"], "error: parameter 'target_distance' must be at least"),
])
def test_cli_preset_mistakes_get_one_line_and_status_2(tmp_path, args, message):
    done = run("generate", *args, "--out", tmp_path / "out")
    assert done.returncode == 2 and done.stderr.startswith(message), done.stderr
    assert len(done.stderr.strip().splitlines()) == 1 and not (tmp_path / "out").exists()


def test_cli_allow_infeasible_writes_the_too_narrow_corridor(tmp_path):
    done = run("generate", "--preset", "narrow_corridor", "--set", "robot_radius=0.45", "--set", "max_attempts=1",
               "--allow-infeasible", "--out", tmp_path)
    assert done.returncode == 0, done.stderr
    (folder,) = world_dirs(tmp_path)
    meta = json.loads((folder / "world.json").read_text())
    assert meta["feasibility"]["feasible"] is False
    assert "spawn_free" in {c["name"] for c in meta["feasibility"]["checks"] if not c["ok"]}
