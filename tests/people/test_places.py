"""People: where they start and go (generators.people), and how every format carries them (the movers' path:
SDF actors without a loop, MJCF mocap bodies, left out of URDF, world.json people[])."""

from __future__ import annotations

import json

import mujoco
import numpy as np
import pytest
from support.reftools_mujoco import assert_no_warnings, load_and_step
from support.reftools_sdf import check_sdf

import worldgen
from worldgen.errors import InfeasibleError, ParameterError
from worldgen.export import metadata
from worldgen.export.actor_path import TENSION, actor_waypoints, spline_positions
from worldgen.export.sdf import HOLD_SECONDS, script_rows
from worldgen.export.xml import parse_bytes
from worldgen.people.places import KEEP_OUT, LEG_MAX, LEG_MIN, SLACK, draw_people, people_footprints
from worldgen.scene.footprint import FootprintIndex
from worldgen.scene.motion import drive_mocap, mover_names, mover_positions
from worldgen.seeding import people_rng

PEOPLE = {"size": [8.0, 8.0], "n_obstacles": 8, "n_people": 4, "people_duration": 15.0, "n_movers": 1}


@pytest.fixture(scope="module")
def world():
    return worldgen.generate("cluttered", seed=4, **PEOPLE)


def test_draws_start_free_apart_and_off_the_robots_discs_with_legs_of_the_stated_length():
    base = worldgen.generate("cluttered", seed=1, size=[8.0, 8.0], n_obstacles=8, n_tasks=2)
    params = dict(base.params, n_people=8, person_radius=0.3, person_speed=[0.8, 1.2], people_duration=30.0)
    plan, reason = draw_people(base.scene, base.tasks, base.robot, params, people_rng(1, 0))
    assert reason is None and plan is not None
    index = FootprintIndex(people_footprints(base.scene, base.tasks, base.robot))
    assert not index.blocked(plan.starts, 0.3 + 2 * SLACK).any()
    assert not index.blocked(plan.places.reshape(-1, 2), 0.3 + 2 * SLACK).any()
    gaps = np.hypot(*(plan.starts[:, None] - plan.starts[None]).transpose(2, 0, 1))
    assert np.all(gaps[~np.eye(8, dtype=bool)] >= 0.6)
    robot_points = np.array([[p.x, p.y] for t in base.tasks for p in (t.spawn, t.goal)])
    to_robot = np.hypot(*(plan.starts[:, None] - robot_points[None]).transpose(2, 0, 1))
    assert to_robot.min() >= base.robot.inflation + KEEP_OUT + 0.3
    legs = np.hypot(*np.diff(np.concatenate([plan.starts[:, None], plan.places], axis=1), axis=1).transpose(2, 0, 1))
    assert legs.min() >= LEG_MIN and legs.max() <= LEG_MAX
    # Enough places to walk the whole time at the fastest speed, and speeds drawn in the range.
    assert plan.places.shape[1] * LEG_MIN >= 30.0 * 1.2
    assert np.all((plan.speeds >= 0.8) & (plan.speeds <= 1.2))


def test_world_json_lists_people_apart_from_movers(world):
    meta = world.metadata
    metadata.validate(meta)
    assert [m["name"] for m in meta["dynamic_obstacles"]] == ["mover_0"]
    assert [p["name"] for p in meta["people"]] == [f"person_{i}" for i in range(4)]
    assert mover_names(meta) == ["mover_0"] + [f"person_{i}" for i in range(4)] == mover_names(world)
    for p in meta["people"]:
        rows = np.array(p["trajectory"])
        assert p["radius"] == 0.25 and "loop" not in p
        assert rows[0, 0] == 0.0 and np.all(np.diff(rows[:, 0]) > 0) and rows[-1, 0] <= 15.0
        assert p["formats"] == {"sdf": "actor", "mjcf": "mocap_body", "urdf": None}
        # Rows at the 0.1 s step (stays shortened to their ends), never faster than 1.3 x 1.4 m/s.
        assert np.allclose(np.round(rows[:, 0] / 0.1), rows[:, 0] / 0.1, atol=1e-6)
        assert np.max(np.hypot(*np.diff(rows[:, 1:], axis=0).T) / np.diff(rows[:, 0])) <= 1.3 * 1.4 + 1e-4
    assert meta["robot"]["max_speed"] == 0.5 and meta["params"]["n_people"] == 4


def test_sdf_actors_play_the_rows_once_and_then_stand(world, tmp_path):
    folder = world.write(tmp_path)
    sdf = folder / "world.sdf"
    ok, messages = check_sdf(sdf)
    assert ok, "\n".join(messages)
    meta = json.loads((folder / "world.json").read_text())
    actors = {a.get("name"): a for a in parse_bytes(sdf.read_bytes()).getroot().findall("world/actor")}
    for p in meta["people"]:
        actor = actors[p["name"]]
        # Written looping, the rows then a stay of HOLD_SECONDS at the last one: a script that does not loop
        # hangs Gazebo Sim with a rendering sensor (docs/gazebo.md).
        assert actor.findtext("script/loop") == "true"
        points = [(float(w.findtext("time")), *map(float, w.findtext("pose").split()[:2]))
                  for w in actor.findall("script/trajectory/waypoint")]
        # The rows, with points added on the legs for Gazebo's spline (tests/export/test_people_exports.py).
        np.testing.assert_array_equal(np.array(points), actor_waypoints(script_rows(p["trajectory"], False)))
        assert points[-1] == (p["trajectory"][-1][0] + HOLD_SECONDS, *p["trajectory"][-1][1:])
    links = {link.get("name") for link in parse_bytes((folder / "world.urdf").read_bytes()).getroot().findall("link")}
    assert not links & {p["name"] for p in meta["people"]}


def test_mjcf_mocap_bodies_follow_world_json_within_a_micrometre(world):
    model, data = load_and_step(world.to_mjcf(), steps=20)
    meta = world.metadata
    assert model.nmocap == 5
    for t in np.linspace(0.0, 20.0, 61):  # past the end too: people then stand where they stopped
        drive_mocap(model, data, meta, t)
        mujoco.mj_step(model, data)
        for p in meta["people"]:
            rows = np.array(p["trajectory"])
            expect = [np.interp(t, rows[:, 0], rows[:, 1]), np.interp(t, rows[:, 0], rows[:, 2]), p["height"] / 2]
            np.testing.assert_allclose(data.xpos[model.body(p["name"]).id], expect, atol=1e-6)
    assert_no_warnings(model, data, "driven people")
    np.testing.assert_allclose(mover_positions(meta, 7.3), mover_positions(world, 7.3), atol=1e-12)


def test_people_leave_obstacles_tasks_and_movers_where_they_were(world):
    without = worldgen.generate("cluttered", seed=4, **{k: v for k, v in PEOPLE.items() if k not in
                                                         ("n_people", "people_duration")})
    assert world.attempts == without.attempts == 1  # the same draw (a later one would differ anyway)
    assert world.scene.nodes == without.scene.nodes and world.tasks == without.tasks
    assert world.scene.movers[0] == without.scene.movers[0]
    assert world.content_hash != without.content_hash


@pytest.mark.parametrize("params, pattern", [
    ({"n_people": 65}, r"parameter 'n_people' must be in \[0, 64\], got 65"),
    ({"person_radius": 0.05}, r"parameter 'person_radius' must be in \[0.1, 1\], got 0.05"),
    ({"person_speed": [1.5, 1.0]}, r"parameter 'person_speed' must be \[min, max\] with min <= max"),
    ({"people_duration": 0}, r"parameter 'people_duration' must be in \[1, 600\], got 0"),
])
def test_bad_people_parameters_get_one_line(params, pattern):
    with pytest.raises(ParameterError, match=pattern) as err:
        worldgen.generate("cluttered", seed=0, **params)
    assert "\n" not in str(err.value)


def test_people_that_cannot_fit_say_so():
    with pytest.raises(InfeasibleError, match=r"people_placement failed 2x") as err:
        worldgen.generate("minimal", seed=0, n_people=40, person_radius=1.0, max_attempts=2)
    assert "\n" not in str(err.value) and "could not place 40 people" in str(err.value)


def test_a_standing_person_stands_still_in_every_format(tmp_path):
    """person_in_doorway: the person stands in the doorway for 8 s; world.json says so with two rows at
    the same place (t = 0 and t = 8), the SDF actor with the same two waypoints and nothing between them,
    played by Gazebo's spline (worldgen.export.actor_path's player of it, checked against the reference
    in tests/export/test_people_exports.py) it stays there within 1 mm, and MuJoCo's mocap body, driven
    by drive_mocap, stays there (within 1 um) at every sampled time of the stay."""
    world = worldgen.generate_preset("person_in_doorway")
    meta = world.metadata
    (person,) = meta["people"]
    rows = np.array(person["trajectory"])
    centre = meta["doors"][0]["passage"]["center"]
    np.testing.assert_array_equal(rows[:2], [[0.0, *centre], [8.0, *centre]])
    assert np.hypot(*(rows[2, 1:] - rows[1, 1:])) > 0  # and then it moves
    actor = parse_bytes(world.to_sdf().encode()).getroot().find("world/actor")
    assert float(actor.find("script/trajectory").get("tension")) == TENSION
    points = np.array([(float(w.findtext("time")), *map(float, w.findtext("pose").split()[:2]))
                       for w in actor.findall("script/trajectory/waypoint")])
    np.testing.assert_array_equal(points, actor_waypoints(script_rows(rows, False)))
    np.testing.assert_array_equal(points[:2], rows[:2])  # the stay: its two rows, nothing between
    stay = np.linspace(0.0, 8.0, 8001)
    assert np.hypot(*(spline_positions(points, stay) - centre).T).max() <= 1e-3
    ok, messages = check_sdf(world.write(tmp_path, preview=False) / "world.sdf")
    assert ok, "\n".join(messages)
    model, data = load_and_step(world.to_mjcf(), steps=1)
    for t in np.linspace(0.0, 8.0, 17):
        drive_mocap(model, data, meta, t)
        mujoco.mj_step(model, data)
        np.testing.assert_allclose(data.xpos[model.body(person["name"]).id][:2], centre, atol=1e-6)


def test_groups_share_speed_and_start_together_and_walk_beside_each_other():
    from worldgen.people.places import GROUP_SPACING, GROUP_START

    base = worldgen.generate("cluttered", seed=1, size=[12.0, 12.0], n_obstacles=4)
    params = dict(base.params, n_people=7, person_radius=0.25, person_speed=[0.8, 1.4], people_duration=30.0,
                  group_size=3)
    plan, reason = draw_people(base.scene, base.tasks, base.robot, params, people_rng(1, 0))
    assert reason is None and plan is not None
    np.testing.assert_array_equal(plan.groups, [0, 0, 0, 3, 3, 3, -1])  # the last group has one member: alone
    for lead in (0, 3):
        members = slice(lead, lead + 3)
        assert len(set(plan.speeds[members])) == 1
        assert np.hypot(*(plan.starts[members] - plan.starts[lead]).T).max() <= GROUP_START
        # Each place of the group: the members side by side across the leg, GROUP_SPACING apart where free
        # (at least half that, or together, where not).
        gaps = np.hypot(*(plan.places[lead + 1] - plan.places[lead]).T)
        assert np.all((np.abs(gaps - GROUP_SPACING) < 1e-5) | (np.abs(gaps - GROUP_SPACING / 2) < 1e-5) | (gaps < 1e-5))
        assert np.mean(np.abs(gaps - GROUP_SPACING) < 1e-5) > 0.5
    index = FootprintIndex(people_footprints(base.scene, base.tasks, base.robot))
    assert not index.blocked(plan.places.reshape(-1, 2), 0.25 + 2 * SLACK).any()
    # Without groups the draw is what it was: group_size 1 is not even recorded.
    alone = worldgen.generate("cluttered", seed=1, size=[8.0, 8.0], n_people=2, people_duration=5.0, group_size=1)
    assert "group_size" not in alone.params and "group_size" not in alone.metadata["params"]


def test_group_scenarios_say_what_is_wrong_in_one_line():
    with pytest.raises(ParameterError, match=r"^people_scenario 'group_passing' needs group_size from 2 to n_people \(1\), "
                                             r"got 1$"):
        worldgen.generate("cluttered", seed=0, n_people=1, people_scenario="group_passing")
    with pytest.raises(ParameterError, match=r"^people_scenario 'doorway' needs a world with a door \(generator 'door'\)$"):
        worldgen.generate("cluttered", seed=0, n_people=1, people_scenario="doorway")
    with pytest.raises(ParameterError, match=r"parameter 'group_size' must be in \[1, 8\], got 9"):
        worldgen.generate("cluttered", seed=0, n_people=9, group_size=9)
