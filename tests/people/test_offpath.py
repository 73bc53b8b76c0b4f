"""The certificate off the static path (worldgen.people.offpath): where no timed path keeps to the path, a route
that steps aside, timed within the robot's limits, re-proved by worldgen check's own code, refused when
tampered with, driven to the goal in MuJoCo; and made by generation only where the sweep along the path fails."""

from __future__ import annotations

import copy

import numpy as np
import pytest

import worldgen
from tests.support.unicycle import drive as unicycle
from worldgen.people.offpath import certify_off_path
from worldgen.people.timed import certify, limits_of
from worldgen.scene import Mover
from worldgen.verify.timed import TimedPathError, check_timed
from worldgen.world import World

#: A mover pacing a 3 m corridor's centreline (x from 7 to 2.5 m and back at 1 m/s), between its spawn at
#: x = 1.5 m and its goal at x = 8.5 m: along the centreline the robot can never get past it.
PACING = ((0.0, 7.0, 0.0), (4.5, 2.5, 0.0), (9.0, 7.0, 0.0))


@pytest.fixture(scope="module")
def pacing():
    """(the corridor world with the pacing mover and its certificate off the path, that certificate's report
    along the path, its world.json)."""
    static = worldgen.generate("corridor", seed=0, width=3.0)
    scene = static.scene.with_movers((Mover("mover_0", 0.25, 1.7, PACING, True, static.params["friction"]),))
    along = certify(static.feasibility, scene, static.tasks, static.robot, limits_of(static.params))
    off = certify_off_path(along, scene, static.tasks, static.robot, limits_of(static.params))
    world = World("corridor", 0, static.params, scene, static.tasks, static.robot, off, 1)
    return world, along, world.metadata_for({})


def test_a_mover_pacing_the_centreline_leaves_no_timed_path_along_it_and_one_off_it(pacing):
    world, along, meta = pacing
    assert not along.feasible and along.timed_paths == (None,)
    assert world.feasibility.feasible
    assert "1 off the static path" in world.feasibility.checks[-1].detail
    rows = np.asarray(meta["tasks"][0]["timed_path"])
    assert np.abs(rows[:, 2]).max() > 1.0  # it steps aside, toward a wall (the centreline is y = 0)
    assert np.abs(rows[:, 2]).max() <= 1.5 - 0.25  # and keeps its inflation off the wall
    assert meta["tasks"][0]["time_limit"] >= meta["tasks"][0]["arrival_time"] + 10.0


def test_the_certificate_off_the_path_passes_worldgen_checks_own_check(pacing):
    world, _, meta = pacing
    worldgen.export.metadata.validate(meta)
    check_timed(meta, world)


@pytest.mark.parametrize("tamper, message", [
    ("no_turn", "faster than robot.max_turn_rate"),
    ("straight", "from mover_0's centre"),
    ("into_wall", "under the clearance"),
])
def test_a_tampered_certificate_off_the_path_fails_the_check(pacing, tamper, message):
    world, _, meta = pacing
    meta = copy.deepcopy(meta)
    task = meta["tasks"][0]
    rows = [list(r) for r in task["timed_path"]]
    if tamper == "no_turn":  # the stand at the spawn, where it turns off the centreline, dropped
        assert rows[1][1:] == rows[0][1:] and rows[1][0] > 0.75
        rows = [rows[0]] + [[round(t - rows[2][0] + 0.05, 6), x, y] for t, x, y in rows[2:]]
        task["arrival_time"] = rows[-1][0]
    elif tamper == "straight":  # along the centreline instead, at the top speed
        rows = [[0.0, *task["spawn"][:2]], [round(7.0 / 0.4995, 6), *task["goal"][:2]]]
        task["arrival_time"] = rows[-1][0]
    else:  # stretched across 1.15 times (1.24 m off the centreline to 1.43 m), and slower
        rows = [[round(t * 1.2, 6), x, round(y * 1.15, 6)] for t, x, y in rows]
        task["arrival_time"] = rows[-1][0]
    task["timed_path"] = rows
    with pytest.raises(TimedPathError, match=message):
        check_timed(meta, world)


def test_an_independent_unicycle_at_the_stated_limits_keeps_to_the_certificate_off_the_path(pacing):
    _, _, meta = pacing
    task, robot = meta["tasks"][0], meta["robot"]
    rows = np.asarray(task["timed_path"])
    run = unicycle(rows, task["spawn"][-1], robot["max_speed"], robot["max_turn_rate"], robot["max_acceleration"])
    lag = np.hypot(run[:, 1] - np.interp(run[:, 0], rows[:, 0], rows[:, 1]),
                   run[:, 2] - np.interp(run[:, 0], rows[:, 0], rows[:, 2]))
    assert lag.max() < robot["tracking_margin"]


def test_the_certificate_off_the_path_drives_to_the_goal_in_mujoco(pacing, tmp_path):
    pytest.importorskip("mujoco")
    from worldgen.sim.drive import drive

    world, _, _ = pacing
    outcome = drive(world, tmp_path, sim="mujoco")
    assert outcome.plan == "timed_path"
    assert outcome.ended == "goal" and outcome.passed and not outcome.contacts


def test_generation_falls_back_off_the_path_only_where_the_sweep_along_it_fails():
    """A 1.5 m corridor with a mover: no draw of seed 2 has a timed path along the centreline (a robot and a
    mover do not pass there side by side); its first draw has one off it, which worldgen check re-proves.
    A draw the sweep along the path certifies is kept as it was (tests/test_golden_bytes.py: the same bytes)."""
    world = worldgen.generate("corridor", seed=2, n_movers=1, max_attempts=4)
    assert world.attempts == 1 and "1 off the static path" in world.feasibility.checks[-1].detail
    meta = world.metadata
    waypoints = np.asarray(meta["tasks"][0]["path"]["waypoints"])
    rows = np.asarray(meta["tasks"][0]["timed_path"])
    assert np.abs(rows[:, 2] - waypoints[0, 1]).max() > 0.2  # off the static path, the centreline
    check_timed(meta, world)
    along = worldgen.generate("corridor", seed=0, width=3.0, n_movers=1)
    assert "off the static path" not in along.feasibility.checks[-1].detail


def test_a_corner_passed_moving_is_granted_only_to_rows_that_come_and_leave_along_the_paths_legs():
    """worldgen check lets a turn of at most 0.3 rad at a waypoint of the recorded path go without a stand where
    the arc of the path's two legs covers it; rows off the path that pass through that waypoint from elsewhere
    turn there by their own angle, which no arc of the path's covers: they get no such leave (the FCL chord is
    never asked, hence no colliders)."""
    from worldgen.verify.timed import _moving

    task = {"path": {"waypoints": [[0.0, 0.0], [1.0, 0.0], [2.0, 0.2]]}}  # a 0.197 rad corner at (1, 0)
    robot = {"max_turn_rate": 1.0, "max_speed": 0.5}
    off = np.array([[0.0, 0.5, 0.5], [2.0, 1.0, 0.0], [4.0, 2.0, 0.2]])  # comes to it across the first leg
    assert _moving(task, off, robot, None, None) == []
    leaves = np.array([[0.0, 0.0, 0.0], [2.0, 1.0, 0.0], [4.0, 1.5, 0.5]])  # leaves it off the second leg
    assert _moving(task, leaves, robot, None, None) == []
