"""``corridor`` with ``terrain=true`` (docs/terrain.md, "Terrain in corridor"): ramps across the corridor, wall to
wall along their leg, clear of the obstacles and the spawn's and goal's room; the MuJoCo drive goes over them to
the goal; ramps too long for a leg and the option's parameters without it are one line, exit 2, and ramps
steeper than the robot climbs an infeasible corridor."""

from __future__ import annotations

import numpy as np
import pytest
from support.cli import run as run_cli

import worldgen
from worldgen.errors import InfeasibleError, ParameterError
from worldgen.groundtruth.folder import open_world
from worldgen.scene.terrain import Ramp

L_CORRIDOR = dict(shape="L", length=8.0, n_ramps=2, n_obstacles=2)


@pytest.fixture(scope="module")
def world():
    return worldgen.generate("corridor", 1, terrain=True, **L_CORRIDOR)


def test_ramps_span_the_corridor_along_their_leg_and_keep_off_the_ends(world):
    ramps = world.scene.terrain.elements
    assert len(ramps) == 2 and all(isinstance(r, Ramp) and r.width == 1.5 for r in ramps)
    assert all(abs(r.yaw) < 1e-9 or abs(r.yaw - np.pi / 2) < 1e-6 for r in ramps)  # the L's legs run +x, then +y
    task = world.tasks[0]
    ends = np.array([[task.spawn.x, task.spawn.y], [task.goal.x, task.goal.y]])
    assert np.all(world.scene.terrain.heights(ends) == 0.0)
    assert world.feasibility.feasible


def test_the_drive_goes_over_the_ramps_to_the_goal(world):
    from worldgen.sim.drive import run_loop
    from worldgen.sim.mujoco import MujocoBackend

    pytest.importorskip("mujoco")
    opened = open_world(world, "world")
    backend = MujocoBackend(opened.file_bytes("mjcf"), opened.metadata)
    trajectory, _, ended = run_loop(backend, opened.metadata["tasks"][0])
    assert ended == "goal" and backend.contacts == []
    ground = world.scene.terrain.heights(trajectory[:, 1:3])
    rises = {r.rise for r in world.scene.terrain.elements}
    assert {round(float(g), 6) for g in ground} >= {round(r, 6) for r in rises}  # on top of both landings
    assert max(h for _, h in backend.heights) == pytest.approx(max(rises), abs=0.01)


def test_without_the_option_a_corridor_is_what_it_was():
    plain = worldgen.generate("corridor", 3)
    assert plain.scene.terrain is None and "terrain" not in plain.params and "n_ramps" not in plain.params


def test_mistakes_are_one_line(tmp_path):
    result = run_cli("generate", "corridor", "--set", "terrain=true", "--set", "length=2", "--set", "ramp_rise=0.5,0.6",
                     "--set", "ramp_incline=5,6", "--out", tmp_path)
    assert result.returncode == 2 and "no leg holds" in result.stderr, result.stderr
    assert len(result.stderr.strip().splitlines()) == 1
    with pytest.raises(ParameterError, match="parameter 'n_ramps' belongs to the terrain option, which is off"):
        worldgen.generate("corridor", 0, n_ramps=2)
    # A ramp it cannot climb closes the corridor: infeasible, as a corridor too narrow for the robot is.
    with pytest.raises(InfeasibleError, match="steeper than the robot climbs"):
        worldgen.generate("corridor", 0, terrain=True, ramp_incline=[12, 14])
