"""``worldgen drive --sim mujoco`` in a terrain world: the robot (worldgen.envs.terrain's base, whose height and
tilt follow its feet's contacts with the ground) drives up a ramp, along its landing and down again to the
goal, riding at the ramp's height; driven straight at a kerb twice its ground clearance high, its chassis
hits the kerb and it is stuck."""

from __future__ import annotations

import math

import numpy as np
import pytest
from support.terrain import KERB_PARAMS, KERB_SEED, ramp_world

import worldgen
from worldgen.groundtruth.folder import open_world
from worldgen.scene.terrain import Ramp
from worldgen.sim.drive import drive, run_loop
from worldgen.sim.mujoco import MujocoBackend

pytest.importorskip("mujoco")


@pytest.fixture(scope="module")
def world():
    return ramp_world()


def test_the_reference_path_crosses_the_ramp(world):
    (ramp,) = world.scene.terrain.elements
    assert isinstance(ramp, Ramp) and math.degrees(math.atan2(ramp.rise, ramp.run)) > 9.0
    (a, b), = [world.feasibility.paths[0].waypoints[[0, -1]]]
    line = a + np.linspace(0.0, 1.0, 601)[:, None] * (b - a)
    assert len(world.feasibility.paths[0].waypoints) == 2  # straight from spawn to goal
    assert world.scene.terrain.heights(line).max() == pytest.approx(ramp.rise)


def test_the_base_rides_up_the_ramp_along_its_landing_and_down_again(world):
    opened = open_world(world, "world")
    meta = opened.metadata
    backend = MujocoBackend(opened.file_bytes("mjcf"), meta)
    trajectory, _, ended = run_loop(backend, meta["tasks"][0])
    assert ended == "goal" and backend.contacts == []
    rise = np.array(backend.heights)[:, 1]
    (ramp,) = world.scene.terrain.elements
    terrain, radius = world.scene.terrain, world.robot.radius
    # Where the ground under the whole footprint is level (the floor, the landing), the body stands on it
    # within 1 cm; across the ramp's bends it bridges between its feet, within 2 cm of the ground under its centre.
    rim = np.array([[math.cos(a), math.sin(a)] for a in np.linspace(0.0, 2.0 * math.pi, 16, endpoint=False)])
    under = np.stack([terrain.heights(trajectory[:, 1:3] + radius * r) for r in rim], axis=1)
    ground = terrain.heights(trajectory[:, 1:3])
    level = np.all(np.abs(under - ground[:, None]) < 1e-9, axis=1)
    on_landing = level & (ground > ramp.rise / 2)
    assert on_landing.sum() >= 5 and (level & (ground == 0)).sum() >= 20
    assert np.abs(rise[level] - ground[level]).max() < 0.01
    assert np.abs(rise - ground).max() < 0.02
    assert rise[0] == pytest.approx(0.0, abs=0.01) and rise[-1] == pytest.approx(0.0, abs=0.01)


def test_the_drive_reaches_the_goal_over_the_ramp_and_passes(world, tmp_path):
    pytest.importorskip("rosbags")
    outcome = drive(world, tmp_path, sim="mujoco")
    assert outcome.ended == "goal" and outcome.passed, outcome.verdict
    assert outcome.contacts == [] and outcome.run["reached_goal"]


def test_a_kerb_higher_than_the_chassis_clears_stops_the_robot(tmp_path):
    pytest.importorskip("rosbags")
    world = worldgen.generate("terrain", seed=KERB_SEED, **KERB_PARAMS)
    (kerb,) = world.scene.terrain.elements
    assert kerb.height >= 2 * world.robot.ground_clearance
    outcome = drive(world, tmp_path, sim="mujoco", straight=True)
    assert outcome.ended == "stuck"
    assert outcome.contacts and {name for _, name in outcome.contacts} == {"terrain_0"}
