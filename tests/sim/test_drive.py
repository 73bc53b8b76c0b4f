"""``worldgen drive --sim mujoco``: the pursuit reaches the goal without contact in a world of every generator,
a straight drive collides with the obstacle world.json puts in the way, the bag reads back as the run, the
bytes repeat in a fresh process, and the command's exit status follows docs/cli.md."""

from __future__ import annotations

import hashlib
import json
import math
from pathlib import Path

import numpy as np
import pytest
from support.cli import run as run_cli

import worldgen
from worldgen import oracles
from worldgen.ros import read_run
from worldgen.sim.drive import Pursuit, drive

pytest.importorskip("rosbags")

GENERATORS = ("barn", "cluttered", "corridor", "door", "minimal")


@pytest.fixture(scope="module")
def worlds(tmp_path_factory) -> dict[str, Path]:
    out = tmp_path_factory.mktemp("worlds")
    return {g: worldgen.generate(g, seed=1).write(out, preview=False) for g in GENERATORS}


def first_in_the_way(folder: Path):
    """The first entity the footprint meets driven kinematically along spawn -> goal (no simulator), or None."""
    task = json.loads((folder / "world.json").read_text())["tasks"][0]
    s, g = np.array(task["spawn"][:2]), np.array(task["goal"][:2])
    u = np.linspace(0.0, 1.0, int(np.hypot(*(g - s)) / 0.005) + 2)
    yaw = math.atan2(g[1] - s[1], g[0] - s[0])
    contacts = oracles.collisions(np.c_[u * 10.0, s[0] + u * (g - s)[0], s[1] + u * (g - s)[1], np.full(len(u), yaw)],
                                  folder)
    return contacts[0].entity if contacts else None


@pytest.fixture(scope="module")
def blocked(tmp_path_factory) -> Path:
    """A cluttered world with an obstacle between spawn and goal."""
    out = tmp_path_factory.mktemp("blocked")
    for seed in range(20):
        folder = worldgen.generate("cluttered", seed=seed).write(out, preview=False)
        if (first_in_the_way(folder) or "").startswith("obstacle"):
            return folder
    raise AssertionError("no cluttered world of seeds 0-19 has an obstacle between spawn and goal")


@pytest.mark.parametrize("generator", GENERATORS)
def test_the_pursuit_reaches_the_goal_without_contact(worlds, tmp_path, generator):
    outcome = drive(worlds[generator], tmp_path, sim="mujoco")
    assert outcome.ended == "goal" and outcome.passed, outcome.verdict
    assert outcome.run["collisions"] == [] and outcome.run["reached_goal"]
    run = read_run(outcome.bag, worlds[generator])
    assert run.source == "ground_truth" and set(run.topics) >= {"/clock", "/odom", "/tf", "/cmd_vel", "/ground_truth"}
    # The bag's trajectory ends within the goal's tolerance (the loop stops inside half of it).
    task = json.loads((worlds[generator] / "world.json").read_text())["tasks"][0]
    end = run.trajectory[-1]
    assert math.hypot(end[1] - task["goal"][0], end[2] - task["goal"][1]) < task["goal_tolerance"]


def test_a_straight_drive_collides_with_the_obstacle_in_the_way(blocked, tmp_path):
    outcome = drive(blocked, tmp_path, sim="mujoco", straight=True)
    assert not outcome.passed and outcome.run["collisions"], outcome.verdict
    assert outcome.run["collisions"][0]["entity"] == first_in_the_way(blocked)


def test_pursuit_follows_a_corner_and_turns_on_the_spot_when_facing_away():
    p = Pursuit([[0, 0], [1, 0], [1, 1]], speed=0.5, lookahead=0.3)
    v, w = p.command(0.0, 0.0, 0.0)
    assert v == pytest.approx(0.5) and w == pytest.approx(0.0)
    v, w = p.command(0.0, 0.0, math.pi)          # facing away: turn, do not drive
    assert v == 0.0 and abs(w) == pytest.approx(2.0)
    v, w = p.command(0.95, 0.0, 0.0)             # near the corner the target lies up the second leg: turn left
    assert w > 0


def _digest(bag: Path) -> str:
    return hashlib.sha256(b"".join(p.read_bytes() for p in sorted(bag.rglob("*")) if p.is_file())).hexdigest()


def test_the_cli_drives_end_to_end_and_repeats_its_bytes(tmp_path):
    assert run_cli("generate", "minimal", "--seed", "2", "--out", tmp_path / "w").returncode == 0
    folder = next((tmp_path / "w").iterdir())
    first = run_cli("drive", folder, "--sim", "mujoco", "--out", tmp_path / "a")
    assert first.returncode == 0 and "mujoco: PASS: reached the goal" in first.stdout, first.stdout + first.stderr
    # A second process: the same bag, byte for byte.
    assert run_cli("drive", folder, "--sim", "mujoco", "--out", tmp_path / "b").returncode == 0
    bag_a, bag_b = (next((tmp_path / d).iterdir()) for d in ("a", "b"))
    assert _digest(bag_a) == _digest(bag_b)
    straight = run_cli("drive", folder, "--sim", "mujoco", "--out", tmp_path / "c", "--straight")
    assert straight.returncode == 1 and "FAIL: collision with" in straight.stdout, straight.stdout + straight.stderr


@pytest.mark.parametrize("args, needle", [
    (["--sim", "webots"], "--sim"),
    (["--speed", "0"], "--speed"),
    (["--task", "task_9"], "task_9"),
])
def test_mistakes_exit_2_with_one_line(worlds, tmp_path, args, needle):
    result = run_cli("drive", worlds["minimal"], "--out", tmp_path, *args)
    assert result.returncode == 2 and needle in result.stderr and "Traceback" not in result.stderr
    assert len(result.stderr.strip().splitlines()) == 1 and not any(tmp_path.iterdir())


def test_a_folder_without_world_json_and_an_existing_run_are_refused(worlds, tmp_path):
    result = run_cli("drive", tmp_path, "--out", tmp_path / "o")
    assert result.returncode == 2 and "world.json" in result.stderr
    assert run_cli("drive", worlds["minimal"], "--out", tmp_path / "o").returncode == 0
    again = run_cli("drive", worlds["minimal"], "--out", tmp_path / "o")
    assert again.returncode == 2 and "exists already" in again.stderr
