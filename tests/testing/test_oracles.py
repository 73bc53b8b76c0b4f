"""Oracles against runs whose figures are computed by hand in the lidar_wall world.

lidar_wall (minimal generator): the robot (radius 0.2 m) spawns at the origin, a
box wall occupies x in [2.0, 2.1], y in [-2, 2], z in [0, 1]; the task's goal is
(2.0, 2.5) and its reference path is the straight segment to it.
"""

import hashlib
import json
import math

import numpy as np
import pytest
import yaml

import worldgen
from worldgen import oracles
from worldgen.errors import ParameterError
from worldgen.judge.evaluate import evaluate, load_criteria
from worldgen.presets import generate_preset

GOAL = (2.0, 2.5)
REF_LENGTH = math.hypot(*GOAL)


@pytest.fixture(scope="module")
def wall():
    return generate_preset("lidar_wall")


@pytest.fixture(scope="module")
def wall_folder(wall, tmp_path_factory):
    return wall.write(tmp_path_factory.mktemp("w"), preview=False)


def line(a, b, t0, t1, n=11):
    s = np.linspace(0.0, 1.0, n)
    return np.c_[t0 + s * (t1 - t0), a[0] + s * (b[0] - a[0]), a[1] + s * (b[1] - a[1])]


def test_straight_line_to_goal(wall):
    run = line((0, 0), GOAL, 0.0, 10.0)
    assert oracles.path_length(run) == pytest.approx(REF_LENGTH, abs=1e-9)
    assert oracles.path_efficiency(run, wall) == pytest.approx(REF_LENGTH / 3.201562, abs=1e-6)
    assert oracles.reached_goal(run, wall)
    # The first sample within 0.2 m of the goal: 9/10 of the way is 0.318 m short, 10/10 is on it.
    assert oracles.time_to_goal(run, wall) == pytest.approx(10.0)
    # The wall's corner (2, 2) is the nearest point: its distance to the segment, minus the radius.
    exact = abs(GOAL[0] * 2.0 - GOAL[1] * 2.0) / REF_LENGTH - 0.2
    got = oracles.min_clearance(run, wall)
    assert exact - 1e-6 <= got <= exact + 1e-3
    assert oracles.collisions(run, wall) == []
    assert oracles.min_separation(run, wall) is None  # no movers in this world


def test_run_through_the_wall(wall):
    run = line((0, 0), (3, 0), 0.0, 3.0, n=4)  # 1 m/s along +x, straight through the wall
    hits = oracles.collisions(run, wall)
    assert [h.entity for h in hits] == ["target"]
    # The footprint's edge reaches x = 2.0 when its centre is at x = 1.8, at t = 1.8 s (samples every 0.05 m).
    assert 1.8 - 1e-9 <= hits[0].time <= 1.85 + 1e-9
    assert oracles.min_clearance(run, wall) < -0.1  # penetration
    assert not oracles.reached_goal(run, wall)
    assert oracles.time_to_goal(run, wall) is None


def test_in_out_in_is_two_contacts(wall):
    run = np.vstack([line((0, 0), (2, 0), 0, 2, 3), line((2, 0), (0, 0), 2, 4, 3)[1:], line((0, 0), (2, 0), 4, 6, 3)[1:]])
    hits = oracles.collisions(run, wall)
    assert [h.entity for h in hits] == ["target", "target"]
    assert hits[0].time == pytest.approx(1.8, abs=0.06) and hits[1].time == pytest.approx(5.8, abs=0.06)


def test_run_that_stops_short(wall):
    run = line((0, 0), (0.8 * GOAL[0], 0.8 * GOAL[1]), 0.0, 8.0)
    assert oracles.path_efficiency(run, wall) == pytest.approx(0.8 * REF_LENGTH / 3.201562, abs=1e-6)
    assert not oracles.reached_goal(run, wall)
    assert oracles.time_to_goal(run, wall) is None
    fig = oracles.run(run, wall)
    assert fig.duration == 8.0 and fig.max_velocity == pytest.approx(0.8 * REF_LENGTH / 8.0)


def test_folder_gives_the_same_figures(wall, wall_folder):
    run = line((0, 0), (3, 0.5), 0.0, 3.0)
    a, b = oracles.run(run, wall), oracles.run(run, wall_folder)
    assert a.collisions == b.collisions and a.reached_goal == b.reached_goal
    assert a.min_clearance == pytest.approx(b.min_clearance, abs=1e-5)


def test_yaw_column_accepted_and_bad_trajectories_refused(wall):
    run = line((0, 0), GOAL, 0.0, 10.0)
    assert oracles.path_length(np.c_[run, np.zeros(len(run))]) == oracles.path_length(run)
    for bad, words in [([[0, 1]], "(n, 3)"), ([[1, 0, 0], [0, 1, 1]], "non-decreasing"),
                       ([[0, float("nan"), 0]], "finite"), ("abc", "array")]:
        with pytest.raises(ParameterError, match=r"parameter 'trajectory'") as exc:
            oracles.path_length(bad)
        assert words in str(exc.value) and "\n" not in str(exc.value)
    with pytest.raises(ParameterError, match="parameter 'task' must be one of task_0"):
        oracles.reached_goal(run, wall, task="nope")


def test_min_separation_standing_on_a_mover():
    world = worldgen.generate("cluttered", seed=2, size=[8, 8], n_obstacles=3, n_movers=1)
    mover = world.metadata["dynamic_obstacles"][0]
    t0, x0, y0 = mover["trajectory"][0]
    stand = [[t0, x0, y0], [t0, x0, y0]]
    assert oracles.min_separation(stand, world) == pytest.approx(-(mover["radius"] + 0.2), abs=1e-9)
    far = [[0.0, 100.0, 100.0]]
    assert oracles.min_separation(far, world) > 90


def test_driving_through_a_mover_is_a_collision():
    world = worldgen.generate("cluttered", seed=2, size=[8, 8], n_obstacles=3, n_movers=1)
    mover = world.metadata["dynamic_obstacles"][0]
    t0, x0, y0 = mover["trajectory"][0]
    stand = [[t0, x0, y0], [t0 + 1e-3, x0, y0]]
    assert oracles.collisions(stand, world) == [oracles.Contact(t0, mover["name"])]
    report = evaluate([(stand, world)], {"safety": {"collision_tolerance": 0}})
    assert not report.passed and report.summary["collision_count"] == 1
    # Just out of reach of the mover's disc at that instant: no contact.
    r = mover["radius"] + world.robot.radius
    beside = [[t0, x0 + r + 1e-3, y0], [t0, x0 + r + 1e-3, y0]]
    assert [c.entity for c in oracles.collisions(beside, world)] == []


CRITERIA = """
navigation: {success_rate: 0.5, path_efficiency: 1.1}
safety: {obstacle_clearance: 0.05, collision_tolerance: 0, max_velocity: 1.0, min_obstacle_distance: 0.3}
performance: {max_time: 20, avg_time_to_goal: 15}
"""


def test_evaluate_pass_and_fail(wall, wall_folder, tmp_path):
    good = line((0, 0), GOAL, 0.0, 10.0)
    crash = line((0, 0), (3, 0), 0.0, 3.0)
    report = evaluate([(good, wall_folder), (good, wall)], CRITERIA)
    assert report.passed and report.failures == []
    assert report.summary["success_rate"] == 1.0 and report.summary["collision_count"] == 0

    report = evaluate([(good, wall_folder), {"trajectory": crash, "world": wall}], CRITERIA)
    assert not report.passed
    assert report.summary["success_rate"] == 0.5 and report.summary["collision_count"] == 1
    lines = report.failures
    assert any(line.startswith("safety.collision_tolerance: required <= 0, measured 1, failed by 1") for line in lines)
    assert any(line.startswith("safety.obstacle_clearance: required >= 0.05") for line in lines)
    assert report.runs[1]["reason"].startswith("collision with target at t=1.8")
    text = str(report)
    assert text.splitlines()[0].split() == ["criterion", "required", "measured", "verdict", "margin"]
    assert "FAIL" in text and text.splitlines()[-1] == "2 runs, 1 succeeded: FAIL"
    assert report.write_csv(tmp_path / "r.csv").read_text().startswith("criterion,required,measured,verdict,margin\n")
    data = json.loads(report.write_json(tmp_path / "r.json").read_text())
    assert data["passed"] is False and len(data["runs"]) == 2


def test_evaluate_reads_the_scenario_time_limit(wall_folder, tmp_path):
    # Reaching the goal after the scenario's max_time is a failed run, however clean.
    spec = yaml.safe_load((wall_folder / "scenario.yaml").read_text())
    limit = spec["tasks"][0]["success_criteria"][1]["seconds"]
    slow = line((0, 0), GOAL, 0.0, limit + 1.0)
    report = evaluate([(slow, wall_folder)], {"navigation": {"success_rate": 1.0}})
    assert not report.passed and report.runs[0]["reason"].startswith("timeout")


def test_criteria_mistakes_are_one_line(tmp_path):
    cases = {"safety: {speed: 1}": "unknown key safety.speed; allowed in safety:",
             "comfort: {x: 1}": "unknown section 'comfort'",
             "navigation: {success_rate: 2}": "success_rate must be in [0, 1]",
             "performance: {max_time: fast}": "performance.max_time must be a finite number"}
    for text, words in cases.items():
        with pytest.raises(ParameterError) as exc:
            load_criteria(text)
        assert words in str(exc.value) and "\n" not in str(exc.value)
    path = tmp_path / "c.yaml"
    path.write_text("safety: {speed: 1}\n")
    with pytest.raises(ParameterError, match=r"c\.yaml: unknown key safety\.speed"):
        load_criteria(str(path))


def test_scenario_yaml_is_listed_and_matches_the_task(wall, wall_folder):
    meta = json.loads((wall_folder / "world.json").read_text())
    entry = meta["files"]["scenario"]
    data = (wall_folder / entry["path"]).read_bytes()
    assert hashlib.sha256(data).hexdigest() == entry["sha256"]
    spec = yaml.safe_load(data)
    task = meta["tasks"][0]
    assert spec["name"] == meta["world_id"] and spec["world"] == "world.sdf"
    assert spec["robot"]["spawn"] == {"x": 0.0, "y": 0.0, "z": 0.0, "yaw": 0.0}
    assert spec["success_criteria"][0] == {"type": "robot_reaches_waypoint", "waypoint": task["goal"][:2],
                                           "tolerance": task["goal_tolerance"]}
    assert {"type": "max_time", "seconds": task["time_limit"]} in spec["success_criteria"]
    assert spec["failure_conditions"] == [{"type": "collision"}, {"type": "timeout", "seconds": task["time_limit"]}]


def test_folder_colliders_match_the_scene_for_every_shape(tmp_path):
    """world.json entities (tilted boxes and cylinders, spheres, STL meshes, a hinged leaf) rebuild the same FCL world."""
    from support.scenes import showcase_scene

    from worldgen import feasibility
    from worldgen.generators import get, robot_from_params
    from worldgen.scene import Pose, Task
    from worldgen.world import World

    resolved = get("cluttered").resolve({})
    tasks = (Task("task_0", Pose(-3.5, -3.2, 0.0), Pose(3.5, -3.2, 0.0)),)
    robot = robot_from_params(resolved)
    scene = showcase_scene()
    world = World("cluttered", 0, resolved, scene, tasks, robot, feasibility.check(scene, tasks, robot), 1)
    folder = world.write(tmp_path, preview=False)
    for y in np.linspace(-2.6, 3.0, 8):  # sweeps across the room, through every kind of shape
        run = line((-3.5, y), (3.5, y + 0.3), 0.0, 7.0)
        a, b = oracles.run(run, world), oracles.run(run, folder)
        assert [(c.entity, c.time) for c in a.collisions] == [(c.entity, c.time) for c in b.collisions]
        # world.json keeps poses to 6 decimals: tilted shapes move by ~1e-5 m, contact depths as much.
        assert a.min_clearance == pytest.approx(b.min_clearance, abs=1e-4)
    assert {c.entity for y in (-2.0, -1.0, 1.0) for c in oracles.collisions(line((-3.5, y), (3.5, y), 0, 7), folder)} >= {"ball", "rock"}


def test_scenario_yaml_bytes_do_not_depend_on_libyaml(monkeypatch):
    """scenario.yaml is written by libyaml where PyYAML has it; without it the pure-Python emitter must give
    the same bytes, or world.json's sha256 would depend on how PyYAML was built."""
    from worldgen.export import scenario

    world = worldgen.generate("door", seed=3, n_doors=2, state="random", n_tasks=2)
    spec = scenario.scenario(world)
    fast = scenario.dumps(spec)
    assert "&id" not in fast and "*id" not in fast  # the repeated first task is written out, not aliased
    monkeypatch.setattr(scenario, "_DUMPER", None)
    monkeypatch.delattr(yaml, "CSafeDumper", raising=False)
    assert scenario.dumps(spec) == fast
    monkeypatch.setattr(scenario, "_DUMPER", None)  # the next caller gets libyaml again


def test_a_run_through_a_closed_door_keeps_its_clearance_to_everything_but_the_leaf(tmp_path):
    """The reference path pushes the leaf open: the leaf is a door contact, not a collision, and the
    clearance is the proven path's to the walls and frames (the leaf where it started is left out)."""
    world = worldgen.generate("door", 2)
    task = world.metadata["tasks"][0]
    assert task["requires_door_open"]
    path = np.asarray(task["path"]["waypoints"])
    trajectory = np.c_[np.arange(len(path), dtype=float), path]
    for where in (world, world.write(tmp_path, preview=False)):
        assert oracles.collisions(trajectory, where) == []
        assert [c.entity for c in oracles.door_contacts(trajectory, where)] == ["door_0"]
        assert oracles.min_clearance(trajectory, where) == pytest.approx(task["path"]["min_clearance"], abs=1e-4)


def test_a_leaf_touched_again_within_the_debounce_is_one_door_contact():
    """The footprint (0.2 m) touches the closed leaf (near face x = 0.01) from x = -0.19 on; the oracles
    sample every 0.05 m, so a leg from x = -1 to -0.1 in 1 s first touches it 17/18 of the way."""
    world = worldgen.generate("door", 0, size=[8, 4], door_x=0.0, door_y=0.0, hinge_side="left", swing="push",
                              state="closed", spawn=[-2.0, 0.0, 0.0], goal=[3.0, 0.0])
    assert oracles.DOOR_DEBOUNCE == 2.0
    back_soon = [(0, -1, 0), (1, -0.1, 0), (2, -1, 0), (3, -0.1, 0)]  # away from 1 + 1/18 s to 2 + 17/18 s
    back_late = [(0, -1, 0), (1, -0.1, 0), (2, -1, 0), (4, -1, 0), (5, -0.1, 0)]  # away until 4 + 17/18 s
    assert oracles.door_contacts(back_soon, world) == [oracles.Contact(17 / 18, "door_0")]
    assert oracles.door_contacts(back_late, world) == [oracles.Contact(17 / 18, "door_0"),
                                                       oracles.Contact(4 + 17 / 18, "door_0")]
    assert oracles.collisions(back_late, world) == []
    assert oracles.run(back_late, world).door_contacts == tuple(oracles.door_contacts(back_late, world))
