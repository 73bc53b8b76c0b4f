"""The social-navigation figures (worldgen.judge.social) against hand-checked cases, and the oracles
in worlds with movers and people together."""

from __future__ import annotations

import numpy as np
import pytest

import worldgen
from worldgen import oracles
from worldgen.groundtruth.ground import Ground
from worldgen.judge import social

#: A person of radius 0.25 walking from (5, 0) to (0, 0) at 1 m/s, then waiting there; robot radius 0.2.
META = {"robot": {"radius": 0.2, "height": 0.4, "clearance": 0.05},
        "people": [{"name": "person_0", "radius": 0.25, "height": 1.7, "trajectory": [[0.0, 5.0, 0.0], [5.0, 0.0, 0.0]]}]}


def test_a_person_passing_at_three_metres():
    robot = [[0.0, 0.0, -3.0], [10.0, 0.0, -3.0]]  # standing 3 m to the side of the person's line
    ground = Ground(META)
    assert social.min_person_distance(robot, ground) == pytest.approx(3.0 - 0.45, abs=1e-12)
    assert social.personal_space_time(robot, ground) == 0.0
    assert social.min_time_to_collision(robot, ground) is None  # never on a collision course


def test_a_person_walking_into_a_robot_standing_on_its_line():
    robot = [[0.0, 0.0, 0.0], [10.0, 0.0, 0.0]]
    ground = Ground(META)
    # The discs touch when the centres are 0.45 m apart: 4.55 s after the start, at 1 m/s; over the whole run
    # they do touch (0), and over its first second the last step, from 0.95 s, is 3.6 s from touching.
    assert social.min_time_to_collision(robot, ground) == 0.0
    assert social.min_time_to_collision([[0.0, 0.0, 0.0], [1.0, 0.0, 0.0]], ground) == pytest.approx(3.6, abs=1e-9)
    # Inside 1.2 m of the robot's centre from t = 3.8 s to the end (10 s), to within one 0.05 s step.
    assert social.personal_space_time(robot, ground) == pytest.approx(6.2, abs=0.05 + 1e-9)
    assert social.min_person_distance(robot, ground) == pytest.approx(-0.45, abs=1e-12)  # they overlap at the end
    # A wider personal space counts from earlier: 2.0 m is reached at t = 3.0 s.
    assert social.personal_space_time(robot, ground, radius=2.0) == pytest.approx(7.0, abs=0.05 + 1e-9)


def test_figures_are_none_without_people():
    ground = Ground({"robot": META["robot"]})
    robot = [[0.0, 0.0, 0.0], [1.0, 1.0, 0.0]]
    assert social.min_person_distance(robot, ground) is None
    assert social.personal_space_time(robot, ground) is None
    assert social.min_time_to_collision(robot, ground) is None


@pytest.fixture(scope="module")
def crowded():
    return worldgen.generate("cluttered", 1, n_people=2, n_movers=1)


def test_oracles_take_movers_and_people_together(crowded):
    """Movers and people are discs in one order (movers, then people); the oracles once broke on both."""
    path = np.asarray(crowded.metadata["tasks"][0]["path"]["waypoints"])
    run = oracles.run(np.c_[np.arange(len(path)) * 2.0, path], crowded)
    assert run.min_separation is not None and run.min_person_distance is not None
    assert run.min_separation <= run.min_person_distance
    assert oracles.min_person_distance(np.c_[np.arange(len(path)) * 2.0, path], crowded) == run.min_person_distance


def test_standing_in_a_persons_way_is_a_collision_with_that_person(crowded):
    person = crowded.metadata["people"][0]
    t, x, y = person["trajectory"][len(person["trajectory"]) // 2]
    robot = [[0.0, x, y], [2.0 * t + 1.0, x, y]]  # where the person walks, the whole time it walks there
    contacts = [c.entity for c in oracles.collisions(robot, crowded)]
    assert person["name"] in contacts
    assert social.min_person_distance(robot, crowded) <= 0.0


def test_social_criteria(crowded):
    path = np.asarray(crowded.metadata["tasks"][0]["path"]["waypoints"])
    run = (np.c_[np.arange(len(path)) * 2.0, path], crowded)
    got = oracles.run(*run)
    report = oracles.evaluate([run], {"social": {"min_person_distance": got.min_person_distance,
                                                 "personal_space_time": got.personal_space_time}})
    assert report.passed, report.failures
    report = oracles.evaluate([run], {"social": {"min_person_distance": got.min_person_distance + 0.01}})
    assert not report.passed and report.failures[0].startswith("social.min_person_distance: required >= ")
    # Without people nothing can come near: the social criteria hold.
    plain = worldgen.generate("cluttered", 1, size=[8, 8], n_obstacles=3)
    wp = np.asarray(plain.metadata["tasks"][0]["path"]["waypoints"])
    report = oracles.evaluate([(np.c_[np.arange(len(wp)) * 2.0, wp], plain)],
                              {"social": {"min_person_distance": 0.5, "min_time_to_collision": 2.0}})
    assert report.passed and report.summary["min_person_distance"] is None
