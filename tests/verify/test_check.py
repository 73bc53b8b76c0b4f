"""`worldgen check`: a fresh world passes; every kind of damage fails with the check named, exit 1."""

from __future__ import annotations

import json
import os
import shutil
import subprocess
import sys
from pathlib import Path

import pytest

import worldgen
from worldgen.cli import main
from worldgen.export.metadata import dumps
from worldgen.verify import CHECKS, check_folder


@pytest.fixture(scope="module")
def fresh(tmp_path_factory):
    """A written cluttered world (kept pristine) and a door world with a mover."""
    out = tmp_path_factory.mktemp("fresh")
    cluttered = worldgen.generate("cluttered", seed=11).write(out)
    door = worldgen.generate("door", seed=2, n_movers=1).write(out)
    return cluttered, door


@pytest.fixture
def world(fresh, tmp_path) -> Path:
    """A copy of the cluttered world to damage."""
    return Path(shutil.copytree(fresh[0], tmp_path / fresh[0].name))


def _edit_json(folder: Path, change) -> None:
    meta = json.loads((folder / "world.json").read_text())
    change(meta)
    (folder / "world.json").write_text(dumps(meta))


def _check(capsys, *folders) -> tuple[int, list[str]]:
    status = main(["check", *map(str, folders)])
    return status, capsys.readouterr().out.splitlines()


def _fails(capsys, folder: Path, check: str, *words: str) -> str:
    status, lines = _check(capsys, folder)
    assert status == 1 and len(lines) == 1, lines
    prefix = f"FAIL {folder}: {check}: "
    assert lines[0].startswith(prefix), lines
    for w in words:
        assert w in lines[0], lines
    return lines[0]


def test_fresh_worlds_pass_through_the_installed_script(fresh):
    run = subprocess.run([sys.executable, "-m", "worldgen", "check", *map(str, fresh)],
                         capture_output=True, text=True)
    assert run.returncode == 0, run.stdout + run.stderr
    assert run.stdout.splitlines() == [f"OK {f}" for f in fresh]


def test_an_altered_file_fails_files(world, capsys):
    with open(world / "world.sdf", "ab") as fh:
        fh.write(b"\n")
    _fails(capsys, world, "files", "world.sdf", "sha256")


def test_a_missing_file_fails_files(world, capsys):
    (world / "world.urdf").unlink()
    _fails(capsys, world, "files", "world.urdf is missing")


def test_a_changed_param_fails_regenerate_on_the_content_hash(world, capsys):
    _edit_json(world, lambda m: m["params"].__setitem__("n_obstacles", m["params"]["n_obstacles"] + 1))
    _fails(capsys, world, "regenerate", "content_hash")


def test_an_unknown_param_fails_regenerate_with_the_generators_message(world, capsys):
    _edit_json(world, lambda m: m["params"].__setitem__("n_obstacles", 10**6))
    _fails(capsys, world, "regenerate", "n_obstacles")


@pytest.mark.parametrize("path", ["../elsewhere/world.urdf", "/etc/passwd", "meshes/../../x", "C:/x", ""])
def test_a_path_outside_the_folder_fails_paths_before_anything_is_read(world, capsys, path):
    _edit_json(world, lambda m: m["files"]["urdf"].__setitem__("path", path))
    _fails(capsys, world, "paths", "files.urdf")


def test_a_symlink_out_of_the_folder_fails_paths(world, tmp_path, capsys):
    outside = tmp_path / "outside.urdf"
    outside.write_bytes((world / "world.urdf").read_bytes())  # same bytes: only the location is wrong
    (world / "world.urdf").unlink()
    os.symlink(outside, world / "world.urdf")
    _fails(capsys, world, "paths", "leads outside")


def test_a_schema_violation_fails_schema(world, capsys):
    _edit_json(world, lambda m: m["robot"].__setitem__("radius", -1.0))
    _fails(capsys, world, "schema", "robot/radius")


def test_broken_or_missing_world_json_fails_metadata(world, capsys):
    (world / "world.json").write_text("{")
    _fails(capsys, world, "metadata", "JSON")
    (world / "world.json").unlink()
    _fails(capsys, world, "metadata", "no world.json")


def test_a_moved_goal_fails_feasibility(world, capsys):
    _edit_json(world, lambda m: m["tasks"][0]["goal"].__setitem__(0, m["tasks"][0]["goal"][0] + 0.5))
    _fails(capsys, world, "feasibility", "task_0 goal")


def test_a_changed_path_length_fails_feasibility(world, capsys):
    _edit_json(world, lambda m: m["tasks"][0]["path"].__setitem__("length", m["tasks"][0]["path"]["length"] + 1e-5))
    _fails(capsys, world, "feasibility", "path length")


def test_a_recorded_path_through_an_obstacle_fails_feasibility(world, capsys):
    meta = json.loads((world / "world.json").read_text())
    obstacle = next(e for e in meta["entities"] if e["role"] == "obstacle")
    # Same length as before, but a detour through an obstacle's centre.
    def detour(m):
        w = m["tasks"][0]["path"]["waypoints"]
        m["tasks"][0]["path"]["waypoints"] = [w[0], obstacle["pose"][:2], w[-1]]
    _edit_json(world, detour)
    _fails(capsys, world, "feasibility", "recorded path", obstacle["name"])


def test_a_changed_entity_fails_reproduce(world, capsys):
    def grow(m):
        box = next(e for e in m["entities"] if e["role"] == "obstacle" and e["shape"]["type"] == "box")
        box["shape"]["size"][0] += 0.1
    _edit_json(world, grow)
    _fails(capsys, world, "reproduce", "entities[", "shape.size[0]")


def test_a_replaced_file_with_its_hash_updated_fails_reproduce(world, capsys):
    import hashlib

    text = (world / "world.sdf").read_bytes().replace(b"</sdf>", b"<!-- edited --></sdf>")
    (world / "world.sdf").write_bytes(text)
    _edit_json(world, lambda m: m["files"]["sdf"].__setitem__("sha256", hashlib.sha256(text).hexdigest()))
    _fails(capsys, world, "reproduce", "files.sdf.sha256")


def test_a_redrawn_or_missing_preview_is_not_a_failure(world, capsys):
    (world / "preview.png").unlink()
    assert _check(capsys, world) == (0, [f"OK {world}"])


def test_one_line_per_world_and_status_1_if_any_fails(fresh, world, capsys):
    (world / "world.mjcf.xml").write_text("x")
    status, lines = _check(capsys, fresh[0], world, fresh[1])
    assert status == 1
    assert lines[0] == f"OK {fresh[0]}" and lines[2] == f"OK {fresh[1]}"
    assert lines[1].startswith(f"FAIL {world}: files: world.mjcf.xml")


def test_usage_mistakes_are_status_2(tmp_path, capsys):
    assert main(["check"]) == 2
    assert main(["check", str(tmp_path / "nope")]) == 2
    err = capsys.readouterr().err
    assert err.count("error: ") == 2 and "does not exist" in err


def test_a_world_written_by_another_version_is_checked_but_not_byte_for_byte(world, capsys):
    _edit_json(world, lambda m: m.__setitem__("worldgen_version", "0.0.1"))
    status, lines = _check(capsys, world)
    assert status == 0 and lines == [f"OK {world} (written by worldgen 0.0.1, not compared byte for byte)"]


def test_an_infeasible_on_purpose_world_reproduces(tmp_path):
    folder = worldgen.generate("cluttered", seed=3, infeasible=True, allow_infeasible=True).write(tmp_path)
    assert json.loads((folder / "world.json").read_text())["feasibility"]["feasible"] is False
    outcome = check_folder(folder)
    assert outcome.ok, outcome.line()


def test_the_checks_are_named_in_order():
    assert CHECKS == ("metadata", "paths", "files", "schema", "regenerate", "feasibility", "timed", "reproduce")


# -- timed: the certificate among people, re-proved from world.json ------------------------------------

@pytest.fixture(scope="module")
def among_people(tmp_path_factory):
    """The person_head_on preset's world (a person walks the robot's 9 m line towards it: the timed path
    waits for it) and a cluttered world with six people, whose path bends."""
    from worldgen.presets import load

    out = tmp_path_factory.mktemp("people")
    head_on = load("person_head_on")
    return (worldgen.generate(head_on.generator, 0, **head_on.merged({})).write(out),
            worldgen.generate("cluttered", 0, size=[8.0, 8.0], n_obstacles=10, n_people=6,
                              people_duration=20.0).write(out))


@pytest.fixture
def head_on(among_people, tmp_path) -> Path:
    return Path(shutil.copytree(among_people[0], tmp_path / among_people[0].name))


def test_worlds_among_people_pass_timed(among_people, capsys):
    assert _check(capsys, *among_people) == (0, [f"OK {f}" for f in among_people])


def _timed(folder: Path, rows) -> None:
    def change(meta):
        meta["tasks"][0]["timed_path"] = rows
        meta["tasks"][0]["arrival_time"] = rows[-1][0]
    _edit_json(folder, change)


def test_driving_the_line_through_the_person_fails_timed(head_on, capsys):
    """On the path and under max_speed (0.4995 of 0.5 m/s), but straight through the person walking it."""
    task = json.loads((head_on / "world.json").read_text())["tasks"][0]
    assert task["arrival_time"] == 22.6  # the certificate waits: 9 m at 0.5 m/s would take 18 s
    _timed(head_on, [[0.0, *task["spawn"][:2]], [round(9.0 / 0.4995, 6), *task["goal"][:2]]])
    _fails(capsys, head_on, "timed", "task_0 timed_path at t = ", "from person_0's centre", "0.5300 m")


def test_a_timed_path_faster_than_max_speed_fails_timed(head_on, capsys):
    rows = json.loads((head_on / "world.json").read_text())["tasks"][0]["timed_path"]
    _timed(head_on, [[round(t * 0.9, 6), x, y] for t, x, y in rows])
    _fails(capsys, head_on, "timed", "above robot.max_speed 0.5 m/s")


def test_a_row_moved_off_the_path_fails_timed(head_on, capsys):
    """A timed path may leave the recorded path (a certificate off the path, docs/people.md), but every row is
    then held to what the robot can drive: 1 cm sideways in a 0.05 s row interval is a jump of speed."""
    rows = json.loads((head_on / "world.json").read_text())["tasks"][0]["timed_path"]
    rows[2][2] += 0.01
    _timed(head_on, rows)
    _fails(capsys, head_on, "timed", "at t = 0.05 s", "faster than robot.max_acceleration")


def test_a_timed_path_that_cuts_a_corner_fails_timed(among_people, tmp_path, capsys):
    folder = Path(shutil.copytree(among_people[1], tmp_path / among_people[1].name))
    task = json.loads((folder / "world.json").read_text())["tasks"][0]
    corner = task["path"]["waypoints"][3]
    rows = [r for r in task["timed_path"] if r[1:] != corner]  # the rows at the path's third corner dropped
    assert len(task["timed_path"]) - 3 <= len(rows) < len(task["timed_path"])  # come, (turn,) leave
    _timed(folder, rows)
    # Off the path is no fault in itself (a certificate off the path): the cut is what the robot cannot drive.
    _fails(capsys, folder, "timed", "changes speed", "faster than robot.max_acceleration")


def test_a_timed_path_that_does_not_start_at_the_spawn_fails_timed(head_on, capsys):
    rows = json.loads((head_on / "world.json").read_text())["tasks"][0]["timed_path"]
    _timed(head_on, [[t + 1.0, x, y] for t, x, y in rows])
    _fails(capsys, head_on, "timed", "not at t = 0 at the spawn")


# -- timed among reacting people: the certificate against every tube ---------------------------------------

@pytest.fixture(scope="module")
def reacting(tmp_path_factory) -> Path:
    """A cluttered world whose five people react (regular, scared, curious, surprised, regular)."""
    out = tmp_path_factory.mktemp("reacting")
    return worldgen.generate("cluttered", 0, size=[8.0, 8.0], n_obstacles=4, n_people=5, people_duration=12.0,
                             people_behaviour="regular,scared,curious,surprised").write(out)


def test_a_world_of_reacting_people_passes_timed(reacting, capsys):
    meta = json.loads((reacting / "world.json").read_text())
    assert [p["behaviour"] for p in meta["people"]] == ["regular", "scared", "curious", "surprised", "regular"]
    assert meta["people"][2]["tube"] == {"d": 0.8, "tau": 2.0}
    assert _check(capsys, reacting) == (0, [f"OK {reacting}"])


@pytest.mark.parametrize("field, value, words", [
    ("d", 0.9, ("person_0's tube d = 0.9 m, tau = 1.5 s is not its behaviour regular's",)),
    ("tau", 3.0, ("tau = 3.0 s is not its behaviour regular's",)),
])
def test_a_tampered_tube_fails_timed(reacting, tmp_path, capsys, field, value, words):
    folder = Path(shutil.copytree(reacting, tmp_path / reacting.name))
    _edit_json(folder, lambda meta: meta["people"][0]["tube"].__setitem__(field, value))
    _fails(capsys, folder, "timed", *words)


def test_a_timed_path_into_a_tube_fails_timed(reacting, tmp_path, capsys):
    """The recorded timed path made 0.3 s earlier throughout (as fast as allowed): it meets a tube."""
    folder = Path(shutil.copytree(reacting, tmp_path / reacting.name))
    task = json.loads((folder / "world.json").read_text())["tasks"][0]
    task_rows = task["timed_path"]
    spawn, goal = task["spawn"][:2], task["goal"][:2]
    way = task["path"]["waypoints"]
    length = sum(((b[0] - a[0]) ** 2 + (b[1] - a[1]) ** 2) ** 0.5 for a, b in zip(way, way[1:]))
    rows, t = [[0.0, *spawn]], 0.0
    for a, b in zip(way, way[1:]):  # straight down the path at 0.499 m/s, no waiting
        t += ((b[0] - a[0]) ** 2 + (b[1] - a[1]) ** 2) ** 0.5 / 0.499
        rows.append([round(t, 6), *b])
    assert task_rows[-1][0] > length / 0.5 + 0.5  # the certificate waits for somebody's tube
    _timed(folder, rows)
    line = _fails(capsys, folder, "timed", "recorded positions within", "its tube's d")
    assert goal == rows[-1][1:] and "\n" not in line


# -- timed within the robot's limits: the turns and the speed changes ---------------------------------------

@pytest.mark.parametrize("field, value, words", [
    ("max_turn_rate", 0.5, ("timed_path turns", "faster than robot.max_turn_rate 0.5 rad/s")),
    ("max_acceleration", 0.5, ("timed_path changes speed", "faster than robot.max_acceleration 0.5 m/s^2")),
])
def test_a_timed_path_beyond_the_stated_limits_fails_timed(among_people, tmp_path, capsys, field, value, words):
    """The world's schedule, against a robot stated slower to turn or to speed up than the one it was made for."""
    folder = Path(shutil.copytree(among_people[1], tmp_path / among_people[1].name))
    meta = json.loads((folder / "world.json").read_text())
    assert meta["robot"][field] == 1.0
    _edit_json(folder, lambda m: m["robot"].__setitem__(field, value))
    _fails(capsys, folder, "timed", *words)


def test_a_timed_path_that_sets_off_before_turning_from_the_spawn_fails_timed(among_people, tmp_path, capsys):
    """The world's schedule with its first stand (the turn from the spawn's yaw) cut short by one step."""
    folder = Path(shutil.copytree(among_people[1], tmp_path / among_people[1].name))
    task = json.loads((folder / "world.json").read_text())["tasks"][0]
    rows = task["timed_path"]
    assert rows[1][1:] == rows[0][1:] and rows[1][0] >= 0.1  # it stands at the spawn first, turning
    rows[1][0] = round(rows[1][0] - 0.05, 6)
    rows[2:] = [[round(t - 0.05, 6), x, y] for t, x, y in rows[2:]]
    _timed(folder, rows)
    _fails(capsys, folder, "timed", "timed_path turns", "after standing", "faster than robot.max_turn_rate 1 rad/s")


def test_corners_passed_on_the_move_are_re_proved_and_need_their_arc_clear(among_people):
    """The cluttered world's timed path passes small corners without stopping: worldgen check re-derives each
    arc from the recorded path (test_worlds_among_people_pass_timed passes it); with a robot 1 mm wider in
    clearance the arcs are no longer clear, those corners count as turns without a stand, and fail."""
    import dataclasses

    import numpy as np

    from worldgen.feasibility.collision import Colliders
    from worldgen.scene.doors import open_scene
    from worldgen.verify.timed import TimedPathError, _drivable, _moving

    meta = json.loads((among_people[1] / "world.json").read_text())
    world = worldgen.generate("cluttered", 0, size=[8.0, 8.0], n_obstacles=10, n_people=6, people_duration=20.0)
    task, robot = meta["tasks"][0], meta["robot"]
    rows = np.array(task["timed_path"])
    colliders = Colliders(open_scene(world.scene))
    moving = _moving(task, rows, robot, colliders, world.robot)
    assert len(moving) >= 2 and max(dev for _, _, (_, dev) in moving) > 1e-4
    wider = dataclasses.replace(world.robot, clearance=world.robot.clearance + 1e-3)
    kept = _moving(task, rows, robot, colliders, wider)
    assert len(kept) < len(moving)
    with pytest.raises(TimedPathError, match="timed_path turns"):
        _drivable(task, rows, robot["max_turn_rate"], robot["max_acceleration"], {k for k, _, _ in kept})
