"""world.osc, the OpenSCENARIO 2 export for scenario_execution: every generator and preset writes one, the
tool's own parser resolves them, worldgen's lint refuses what the tool lets through, `worldgen check`
re-renders it, and a world without a task is refused before anything is written."""

from __future__ import annotations

import hashlib
import json
import re
import subprocess
import sys

import pytest
from support.bundle import bundle_world
from support.reftools_osc import DATA, LIBRARY_FILES, declarations, osc_libraries, resolve

import worldgen
from worldgen import presets
from worldgen.cli import main
from worldgen.errors import ParameterError
from worldgen.export import osc, osc_lint
from worldgen.export.contract import RECORDED
from worldgen.export.formats import FILE_NAMES, FORMATS
from worldgen.generators import registry
from worldgen.world import World

_SOURCES = [("generator", g) for g in registry.names()] + [("preset", p) for p in presets.names()]
#: What scenario_execution's parser resolves: every generator, the presets with people, two tasks, a mover.
_RESOLVED = {"barn", "cluttered", "corridor", "door", "minimal", "crowd_reacting", "group_in_corridor",
             "person_crossing"}


def _world(kind: str, name: str):
    return worldgen.generate(name, seed=0) if kind == "generator" else presets.generate_preset(name, seed=0)


def _numbers(text: str, call: str) -> list[dict[str, float]]:
    """The x, y, yaw (m, m, rad) of every pose_3d given to ``call`` in ``text``."""
    out = []
    for m in re.finditer(rf"{call}\(\w+: pose_3d\(position: position_3d\(x: (\S+)m, y: (\S+?)m.*?"
                         r"orientation_3d\(yaw: (\S+)rad\)", text):
        out.append({"x": float(m.group(1)), "y": float(m.group(2)), "yaw": float(m.group(3))})
    return out


@pytest.mark.parametrize("kind,name", _SOURCES, ids=[n for _, n in _SOURCES])
def test_every_generator_and_preset_exports_its_osc(kind, name):
    world = _world(kind, name)
    text = world.export("osc")
    meta = world.metadata
    tasks = meta["tasks"]
    assert text.count("\nscenario ") == len(tasks) and "import osc.nav2" in text
    for task, spawn, goal in zip(tasks, _numbers(text, "init_nav2"), _numbers(text, "nav_to_pose"), strict=True):
        # world.json's poses are [x, y, z, roll, pitch, yaw]
        assert spawn == {"x": task["spawn"][0], "y": task["spawn"][1], "yaw": task["spawn"][5]}
        assert goal == {"x": task["goal"][0], "y": task["goal"][1], "yaw": task["goal"][5]}
    limits = [float(v) for v in re.findall(r"^            timeout\((\S+)s\)$", text, re.M)]
    assert limits == [t["time_limit"] for t in tasks if t["time_limit"] is not None]
    recorded = re.findall(r"bag_record\(topics: \[(.*?)\]", text)
    assert recorded == [", ".join(f"'{t.name}'" for t in RECORDED)] * len(tasks)
    actors = re.findall(r"^    (\w+): osc_actor$", text, re.M)
    assert len(actors) == len(tasks) * len(world.scene.movers)
    assert f"launch_file: 'ros2/launch/{osc.ros_name(world.world_id)}.launch.py'" in text


def test_every_quantity_has_its_unit():
    text = bundle_world().export("osc")
    # every number but the launch arguments' text values stands right before a unit of osc.types
    bare = re.findall(r"(?<![\w.'])(-?\d+(?:\.\d+)?)(?![\w.\d'])", text.split("import osc.nav2", 1)[1])
    assert bare == []
    assert re.search(r"timeout\(\d+(\.\d+)?s\)", text) and re.search(r"yaw: -?\d+(\.\d+)?rad", text)


@pytest.fixture(scope="module")
def libraries(tmp_path_factory):
    with osc_libraries(tmp_path_factory.mktemp("osc_libs")):
        yield


@pytest.fixture(scope="module")
def sample(tmp_path_factory):
    """world.osc of each world of _RESOLVED, of the two-task bundle world and of a door world with a mover."""
    out = tmp_path_factory.mktemp("osc")
    worlds = [_world(k, n) for k, n in _SOURCES if n in _RESOLVED]
    worlds += [bundle_world(), worldgen.generate("door", seed=2, n_movers=1)]
    paths = []
    for i, world in enumerate(worlds):
        paths.append(out / f"{i}-{world.world_id}.osc")
        paths[-1].write_bytes(world.export_bytes("osc"))
    return paths


def test_scenario_executions_parser_resolves_every_exported_osc(libraries, sample):
    from scenario_execution.model.types import ScenarioDeclaration

    seen = 0
    for path in sample:
        model = resolve(path)
        scenarios = model.find_children_of_type(ScenarioDeclaration)
        assert len(scenarios) == path.read_text().count("\nscenario ") >= 1
        seen += len(scenarios)
    assert seen >= len(sample) + 1  # the bundle world has two tasks


def test_the_lints_declarations_are_the_libraries(libraries, sample):
    """ACTIONS, STRUCTS and MODIFIERS name each parameter, its type and whether it has a default exactly as
    the declaration files do (read through the parser, not by worldgen)."""
    model = resolve(sample[0])
    for kind, table in (("action", osc_lint.ACTIONS), ("struct", osc_lint.STRUCTS), ("modifier", osc_lint.MODIFIERS)):
        declared = declarations(model, kind)
        for name, params in table.items():
            assert declared[name] == params, name
    assert sorted(LIBRARY_FILES.values()) == sorted(p.name for p in DATA.glob("*.osc"))
    # UNITS: the units osc.types declares for length, time and angle, as the installed library spells them
    from importlib.resources import files
    types_osc = files("scenario_execution").joinpath("lib_osc", "types.osc").read_text()
    for kind, units in osc_lint.UNITS.items():
        assert sorted(units) == sorted(re.findall(rf"^unit (\w+) +of {kind} ", types_osc, re.M)), kind


#: (what is changed, into what, what the lint says); the parser refuses the first two as well.
_FAULTS = [
    ("robot.nav_to_pose(", "robot.nav_to_pos(", "unknown action 'robot.nav_to_pos'"),
    ("nav_to_pose(goal_pose:", "nav_to_pose(goal_pos:", "has no parameter 'goal_pos'"),
    ("timeout: 120s", "timeout: 120", "wait_for_sim's timeout is a time: 120 has no unit"),
    ("x: ", "x: 3s, x_was: ", "position_3d's x is a length: 's' is not a unit of length"),
    ("bag_record(topics: [", "bag_record(use_sim_time: true, tpics: [", "has no parameter 'tpics'"),
    ("robot: differential_drive_robot", "robot: differential_robot", "is not an actor type"),
    ("wait_for_shutdown: false", "wait_for_shutdown: 'no'", "is true or false, got \"'no'\""),
]


@pytest.mark.parametrize("before,after,message", _FAULTS, ids=[f[2].split(":")[0][:30] for f in _FAULTS])
def test_the_lint_refuses_with_one_line(before, after, message):
    text = bundle_world().export("osc")
    osc_lint.lint(text)
    with pytest.raises(ParameterError) as caught:
        osc_lint.lint(text.replace(before, after, 1))
    assert message in str(caught.value) and "\n" not in str(caught.value)
    assert str(caught.value).startswith(".osc line ")
    assert caught.value.exit_status == 2


def test_the_parser_refuses_a_misspelt_action_and_a_wrong_argument_but_not_a_missing_unit(libraries, tmp_path):
    """Why worldgen lints before writing: scenario_execution's own resolver lets a bare number through."""
    text = bundle_world().export("osc")
    refused = ["uses unknown behavior", "Named argument goal_pos unknown", None]
    for i, ((before, after, _), message) in enumerate(zip(_FAULTS[:3], refused)):
        path = tmp_path / f"{i}.osc"
        path.write_text(text.replace(before, after, 1))
        if message:
            with pytest.raises(ValueError, match=message):
                resolve(path)
        else:
            resolve(path)


def test_a_fault_in_the_export_is_refused_before_anything_is_written(monkeypatch, tmp_path, capsys):
    """A fault the lint finds (here a misspelt action forced into the writer) ends `worldgen generate` with one
    line and exit 2, and no world folder."""
    written = osc._scenario
    monkeypatch.setattr(osc, "_scenario", lambda *a: [s.replace("nav_to_pose(", "nav_to_pos(") for s in written(*a)])
    out = tmp_path / "out"
    status = main(["generate", "cluttered", "--seed", "0", "--out", str(out), "--formats", "sdf,osc", "--ros"])
    err = capsys.readouterr().err.strip().splitlines()
    assert status == 2 and len(err) == 1 and "unknown action 'robot.nav_to_pos'" in err[0], err
    assert not out.exists() or list(out.iterdir()) == []


def test_a_world_without_a_task_is_refused_before_anything_is_written(tmp_path, monkeypatch, capsys):
    world = bundle_world()
    taskless = World(world.generator, world.seed, world.params, world.scene, (), world.robot, world.feasibility,
                     world.attempts)
    with pytest.raises(ParameterError, match="has no task: the osc format writes one scenario per task") as caught:
        taskless.write(tmp_path / "api", formats=["sdf", "osc"])
    assert caught.value.exit_status == 2 and not (tmp_path / "api").exists()
    # the command line: a world whose tasks the writer finds empty
    monkeypatch.setattr(osc, "writer_args", lambda w: {"tasks": [], "world_id": w.world_id})
    status = main(["generate", "cluttered", "--seed", "0", "--out", str(tmp_path / "cli"), "--formats", "osc", "--ros"])
    err = capsys.readouterr().err.strip().splitlines()
    assert status == 2 and len(err) == 1 and "has no task" in err[0]
    assert not (tmp_path / "cli").exists() or list((tmp_path / "cli").iterdir()) == []


def test_osc_without_the_bundle_is_refused_on_the_command_line(tmp_path, capsys):
    status = main(["generate", "cluttered", "--seed", "0", "--out", str(tmp_path), "--formats", "sdf,osc"])
    err = capsys.readouterr().err.strip().splitlines()
    assert status == 2 and err == ["error: --formats osc writes scenarios that start the world's ROS 2 bundle: add --ros"]
    assert list(tmp_path.iterdir()) == []


def test_osc_without_the_bundle_is_refused_in_a_pack_recipe():
    from worldgen.pack.recipe import RecipeError, parse_recipe

    worlds = "seeds: 1\nworlds:\n  - generator: minimal\n"
    with pytest.raises(RecipeError) as caught:
        parse_recipe("formats: [sdf, osc]\n" + worlds, "r.yaml")
    assert str(caught.value) == ("r.yaml:1: key 'formats': osc writes scenarios that start each world's ROS 2 bundle: "
                                 "add 'ros: true'")
    assert parse_recipe("formats: [sdf, osc]\nros: true\n" + worlds, "r.yaml").formats == ("sdf", "osc")


def test_worldgen_check_knows_world_osc(tmp_path, capsys):
    world = worldgen.generate("door", seed=2, n_movers=1)
    folder = world.write(tmp_path, formats=["sdf", "mjcf", "urdf", "osc"], ros=True)
    meta = json.loads((folder / "world.json").read_text())
    data = (folder / FILE_NAMES["osc"]).read_bytes()
    assert meta["files"]["osc"]["sha256"] == hashlib.sha256(data).hexdigest()
    assert meta["dynamic_obstacles"][0]["formats"]["osc"] == "osc_actor"
    assert main(["check", str(folder)]) == 0
    capsys.readouterr()
    # a scenario edited by hand is caught by its hash
    (folder / FILE_NAMES["osc"]).write_bytes(data.replace(b"timeout(", b"timeout(1", 1))
    assert main(["check", str(folder)]) == 1
    assert "world.osc" in capsys.readouterr().out
    # a world.json whose hash agrees with an edited world.osc is caught by the re-rendering
    edited = data.replace(b"wait_for_sim(timeout: 120s", b"wait_for_sim(timeout: 121s", 1)
    (folder / FILE_NAMES["osc"]).write_bytes(edited)
    meta["files"]["osc"]["sha256"] = hashlib.sha256(edited).hexdigest()
    from worldgen.export.metadata import dumps
    (folder / "world.json").write_text(dumps(meta))
    assert main(["check", str(folder)]) == 1
    assert "reproduce: world.json differs from a fresh export at files.osc.sha256" in capsys.readouterr().out


def test_the_default_formats_are_unchanged_and_osc_is_the_same_bytes_in_another_process():
    assert "osc" not in FORMATS
    world = bundle_world()
    meta = world.metadata
    assert "osc" not in meta["files"]
    assert all("osc" not in e.get("formats", {}) for e in meta.get("dynamic_obstacles", []) + meta.get("people", []))
    code = ("import hashlib, worldgen; w = worldgen.generate('cluttered', seed=7, size=[6, 6], n_obstacles=6, "
            "n_tasks=2); print(hashlib.sha256(w.export_bytes('osc')).hexdigest())")
    other = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True).stdout.strip()
    assert other == hashlib.sha256(world.export_bytes("osc")).hexdigest()


def test_worldgen_judge_judges_the_bag_a_scenario_records(tmp_path):
    """A run of world.osc leaves a bag `rosbag2_<date-time>` in the scenario's output folder, with the topics its
    bag_record lists and no worldgen metadata; a runs table names the world and the task (docs/osc.md)."""
    pytest.importorskip("rosbags")
    from support.runs import along, write_bag

    from worldgen.judge import judge

    folder = worldgen.generate("cluttered", seed=0, size=[8, 8], n_obstacles=6).write(
        tmp_path / "worlds", formats=["sdf", "osc"], ros=True)
    text = (folder / FILE_NAMES["osc"]).read_text()
    words = ("clock", "ground_truth", "cmd_vel", "odom", "tf")  # what the test writer can write, each recorded
    assert all(f"'/{w}'" in re.search(r"bag_record\(topics: \[(.*?)\]", text).group(1) for w in words)
    [name] = re.findall(r"^scenario (\w+):$", text, re.M)
    bag = write_bag(tmp_path / "results" / name / "rosbag2_2026_11_29-03_40_00", folder, along(folder),
                    topics=words, world_id=None, task=None)
    (tmp_path / "runs.csv").write_text(f"bag,world,task\nresults/{name}/{bag.name},worlds/{folder.name},task_0\n")
    [row] = judge(runs=tmp_path / "runs.csv").report["runs"]
    assert row["outcome"] == "success" and row["source"] == "ground_truth", row
