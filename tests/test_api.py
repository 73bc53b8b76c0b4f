"""The Python entry point: ``worldgen.generate`` and the World it returns, in memory."""

from __future__ import annotations

import json
import re

import mujoco
import pytest
from lxml import etree

import worldgen
from worldgen.errors import InfeasibleError, OutputError, ParameterError, UnknownGeneratorError, WorldgenError
from worldgen.export import metadata
from worldgen.export.xml import safe_parser


@pytest.fixture(scope="module")
def world():
    return worldgen.generate("cluttered", seed=0)


def _names(xml: str) -> set[str]:
    return set(etree.fromstring(xml.encode(), safe_parser()).xpath("//@name"))


def test_generate_returns_a_checked_world(world):
    assert isinstance(world, worldgen.World)
    assert world.seed == 0 and world.generator == "cluttered"
    assert world.feasibility.feasible and 1 <= world.attempts <= world.params["max_attempts"]
    assert world.path is None  # nothing touched the disk
    assert re.fullmatch(r"cluttered-s0-[0-9a-f]{8}", world.world_id)
    assert world.world_id.endswith(world.content_hash.split(":")[1][:8])
    assert len(world.tasks) == len(world.feasibility.paths) == 1


def test_every_format_loads_in_memory(world):
    names = {n.name for n in world.scene.nodes}
    mjcf = world.to_mjcf()
    model = mujoco.MjModel.from_xml_string(mjcf)
    data = mujoco.MjData(model)
    mujoco.mj_forward(model, data)
    assert names <= _names(mjcf)
    urdf = world.to_urdf()
    model = mujoco.MjModel.from_xml_string(urdf)
    mujoco.mj_forward(model, mujoco.MjData(model))
    assert names <= _names(urdf)
    for version in ("1.9", "1.6"):
        sdf = world.to_sdf(version)
        root = etree.fromstring(sdf.encode(), safe_parser())
        assert root.tag == "sdf" and root.get("version") == version
        assert names <= _names(sdf)


def test_metadata_in_memory_is_valid_and_matches_the_report(world):
    meta = world.metadata
    metadata.validate(meta)
    path = world.feasibility.paths[0]
    assert meta["tasks"][0]["path"]["length"] == pytest.approx(path.length, abs=1e-6)
    assert meta["feasibility"]["attempts"] == world.attempts
    assert json.loads(world.to_json()) == meta


def test_write_and_file(world, tmp_path):
    with pytest.raises(OutputError, match="not been written yet"):
        world.file("sdf")
    folder = world.write(tmp_path)
    assert folder == tmp_path / world.world_id and world.path == folder
    assert world.file("json").read_text() == world.to_json()
    assert world.file("mjcf").read_text() == world.to_mjcf()


# -- infeasible requests ----------------------------------------------------------

def test_infeasible_names_the_check_the_seed_and_the_budget():
    with pytest.raises(InfeasibleError) as info:
        worldgen.generate("cluttered", seed=5, size=[5, 5], n_obstacles=400, max_attempts=4)
    message = str(info.value)
    assert "\n" not in message
    assert message.startswith("no feasible 'cluttered' world for seed 5 within max_attempts=4: ")
    assert "obstacle_placement failed 4x" in message and "400 obstacles" in message
    assert info.value.failures == {"obstacle_placement": 4}


def test_unreachable_spawn_goal_distance_is_infeasible_not_a_hang():
    # 4.949 m is allowed by the parameter check (the usable diagonal is 4.9497 m) but no
    # spawn/goal pair of free points can be that far apart once the screening margin is kept.
    with pytest.raises(InfeasibleError) as info:
        worldgen.generate("cluttered", seed=2, size=[4, 4], n_obstacles=0, min_spawn_goal_distance=4.949,
                          max_attempts=2)
    message = str(info.value)
    assert "seed 2" in message and "max_attempts=2" in message and "task_placement failed 2x" in message
    assert info.value.failures == {"task_placement": 2}


#: Boxes too dense for a robot this wide: spawn and goal are free, the way between is not.
BLOCKED = {"size": [6, 6], "robot_radius": 0.5, "n_obstacles": 12, "min_spawn_goal_distance": 3.0,
           "box_size": [0.8, 1.5], "obstacle_shapes": "box", "min_gap": 0.0}


def test_a_failed_feasibility_check_is_named_with_its_count():
    with pytest.raises(InfeasibleError) as info:
        worldgen.generate("cluttered", seed=1, max_attempts=2, **BLOCKED)
    message = str(info.value)
    assert message.startswith("no feasible 'cluttered' world for seed 1 within max_attempts=2: ")
    assert "path_exists failed 2x" in message
    assert info.value.failures["path_exists"] == 2


def test_infeasible_on_purpose_is_returned_and_written_with_the_reason(tmp_path):
    world = worldgen.generate("cluttered", seed=1, max_attempts=2, allow_infeasible=True, **BLOCKED)
    assert not world.feasibility.feasible
    assert world.attempts == 2
    folder = world.write(tmp_path)
    meta = json.loads((folder / "world.json").read_text())
    metadata.validate(meta)
    assert meta["feasibility"]["feasible"] is False
    failed = {c["name"] for c in meta["feasibility"]["checks"] if not c["ok"]}
    assert "path_exists" in failed
    assert any(t["path"] is None and t["time_limit"] is None for t in meta["tasks"])


# -- parameter mistakes -------------------------------------------------------------

PARAMETER_MISTAKES = [
    ({"n_obstacles": -1}, r"parameter 'n_obstacles' must be in \[0, 5000\], got -1"),
    ({"n_obstacles": 2.5}, r"parameter 'n_obstacles' must be an integer in \[0, 5000\], got 2\.5"),
    ({"n_obstacles": True}, r"parameter 'n_obstacles' must be an integer in \[0, 5000\], got True"),
    ({"clearance": float("nan")}, r"parameter 'clearance' must be a number in \[0, 2\], got nan"),
    ({"size": [10]}, r"parameter 'size' must be two numbers, each in \[1, 500\], got \[10\]"),
    ({"size": "10x10"}, r"parameter 'size' must be two numbers, each in \[1, 500\], got '10x10'"),
    ({"box_size": [1.0, 0.5]}, r"parameter 'box_size' must be \[min, max\] with min <= max, got \[1\.0, 0\.5\]"),
    ({"random_yaw": "yes"}, r"parameter 'random_yaw' must be true or false, got 'yes'"),
    ({"obstacle_shapes": "cone"}, r"parameter 'obstacle_shapes' must be one of box, cylinder, mixed, got 'cone'"),
    ({"trees": 3}, r"unknown parameter 'trees'; known parameters: box_size, .*, walls"),
    ({"size": [1, 1], "robot_radius": 0.6},
     r"parameter 'size' must exceed 2 x \(robot_radius \+ clearance\) = 1\.3 m on both axes, got \[1\.0, 1\.0\]"),
    ({"seed": -1}, r"parameter 'seed' must be an integer in \[0, 9223372036854775807\], got -1"),
    ({"seed": 1.5}, r"parameter 'seed' must be an integer in \[0, 9223372036854775807\], got 1\.5"),
    ({"seed": True}, r"parameter 'seed' must be an integer in \[0, 9223372036854775807\], got True"),
    ({"seed": 2**63}, r"parameter 'seed' must be an integer in \[0, 9223372036854775807\], got 9223372036854775808"),
]


@pytest.mark.parametrize("params, pattern", PARAMETER_MISTAKES,
                         ids=[",".join(f"{k}={v!r}" for k, v in p.items()) for p, _ in PARAMETER_MISTAKES])
def test_parameter_errors_name_the_parameter_the_rule_and_the_value(params, pattern):
    params = dict(params)
    seed = params.pop("seed", 0)
    with pytest.raises(ParameterError) as info:
        worldgen.generate("cluttered", seed, **params)
    assert isinstance(info.value, WorldgenError) and isinstance(info.value, ValueError)
    assert re.fullmatch(pattern, str(info.value)), str(info.value)


def test_unknown_generator():
    with pytest.raises(UnknownGeneratorError) as info:
        worldgen.generate("forest", seed=1)
    assert isinstance(info.value, WorldgenError) and isinstance(info.value, LookupError)
    assert re.fullmatch(r"unknown generator 'forest'; available: .*cluttered.*", str(info.value))


def test_export_option_mistakes(world, tmp_path):
    with pytest.raises(ParameterError, match=r"^parameter 'sdf_version' must be one of 1\.9, 1\.6, got '2\.0'$"):
        world.to_sdf("2.0")
    with pytest.raises(ParameterError, match=r"^parameter 'formats' must name formats among sdf, mjcf, urdf, usd, usdc, osc, pedsim, hunav, got 'obj'$"):
        world.write(tmp_path, formats="sdf,obj")
    assert list(tmp_path.iterdir()) == []
    blocker = tmp_path / "file"
    blocker.write_text("x")
    with pytest.raises(OutputError, match="cannot write to output folder"):
        world.write(blocker / "worlds")


def test_a_map_too_fine_for_the_floor_is_refused_before_any_planning(monkeypatch):
    from worldgen import feasibility

    def no_planning(*args, **kwargs):
        raise AssertionError("feasibility ran before the map's size was checked")

    monkeypatch.setattr(feasibility, "check", no_planning)
    with pytest.raises(worldgen.ParameterError, match=r"parameter 'map_resolution' must be at least 0\.1000 m"):
        worldgen.generate("cluttered", size=[500, 500], n_obstacles=0)


def test_each_format_is_rendered_once_per_world(monkeypatch):
    """to_sdf(), to_mjcf(), to_urdf(), metadata and write share one rendering per format (issue 9, item 7)."""
    from worldgen.export import mjcf, sdf, urdf

    calls = []
    for module, name in ((sdf, "to_sdf"), (mjcf, "to_mjcf"), (urdf, "to_urdf")):
        original = getattr(module, name)
        monkeypatch.setattr(module, name, lambda *a, _o=original, _n=name, **k: calls.append(_n) or _o(*a, **k))
    world = worldgen.generate("cluttered", seed=4, n_obstacles=5)
    texts = (world.to_sdf(), world.to_mjcf(), world.to_urdf())
    world.metadata
    assert world.read("world.sdf").decode() == texts[0]
    assert world.to_sdf("1.6") != texts[0]
    assert sorted(calls) == ["to_mjcf", "to_sdf", "to_sdf", "to_urdf"]


def test_every_generator_and_the_command_work_with_only_the_core_dependencies(tmp_path):
    """The optional extras (scipy, gymnasium, rosbags) are not needed to make, write and check a world of
    any generator: a fresh `pip install worldgen` has none of them (the barn generator once imported scipy
    and broke `worldgen` itself on such an install)."""
    import subprocess
    import sys

    script = (
        "import sys\n"
        "for name in ('scipy', 'gymnasium', 'rosbags'):\n"
        "    sys.modules[name] = None  # as if not installed\n"
        "import worldgen\n"
        "from worldgen.cli import main\n"
        "from worldgen.generators.registry import all_specs\n"
        "from worldgen.verify import check_folder\n"
        "for spec in all_specs():\n"
        "    folder = worldgen.generate(spec.name, 0).write(sys.argv[1], preview=False)\n"
        "    outcome = check_folder(folder)\n"
        "    assert outcome.ok, outcome.line()\n"
        "print('ok')\n"
    )
    run = subprocess.run([sys.executable, "-c", script, str(tmp_path)], capture_output=True, text=True, timeout=300)
    assert run.returncode == 0 and run.stdout.strip() == "ok", run.stderr[-2000:]


def test_a_worlds_provenance_is_set_in_one_place():
    """preset and difficulty_request are read-only: World.set_provenance is the one setter, and neither changes
    the world's identity."""
    world = worldgen.generate("minimal", seed=0)
    before = world.content_hash
    with pytest.raises(AttributeError):
        world.preset = "somewhere"  # type: ignore[misc]
    assert world.set_provenance(preset="drl_arena") is world and world.preset == "drl_arena"
    assert world.folder_name == f"drl_arena--{world.world_id}" and world.content_hash == before
    with pytest.raises(ParameterError, match="preset"):
        world.set_provenance(preset=3)
    world.set_provenance(difficulty_request={"level": "3/10"})
    assert world.preset == "drl_arena" and world.difficulty_request == {"level": "3/10"}
