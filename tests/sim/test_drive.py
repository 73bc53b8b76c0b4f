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
from worldgen.envs.policies import PathFollower
from worldgen.ros import read_run
from worldgen.sim.drive import LOOKAHEAD, TURN_RATE, drive

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
    meta = json.loads((worlds[generator] / "world.json").read_text())
    task = meta["tasks"][0]
    # The run is named <world_id>__<task>__<run> by the judge and by its folder, the world named once.
    assert outcome.bag.name == outcome.run["run"] == f"{meta['world_id']}__{task['id']}__mujoco"
    assert run.metadata["worldgen.run"] == "mujoco" and outcome.run["run"].count(meta["world_id"]) == 1
    end = run.trajectory[-1]
    assert math.hypot(end[1] - task["goal"][0], end[2] - task["goal"][1]) < task["goal_tolerance"]


def test_a_straight_drive_collides_with_the_obstacle_in_the_way(blocked, tmp_path):
    outcome = drive(blocked, tmp_path, sim="mujoco", straight=True)
    assert not outcome.passed and outcome.run["collisions"], outcome.verdict
    assert outcome.run["collisions"][0]["entity"] == first_in_the_way(blocked)
    world_id = json.loads((blocked / "world.json").read_text())["world_id"]
    assert outcome.bag.name == outcome.run["run"] == f"{world_id}__task_0__mujoco-straight"


def test_the_drive_controller_follows_a_corner_and_turns_on_the_spot_when_facing_away():
    p = PathFollower([[0, 0], [1, 0], [1, 1]], v_max=0.5, w_max=TURN_RATE, lookahead=LOOKAHEAD)
    v, w = p.action(0.0, 0.0, 0.0)
    assert v == pytest.approx(0.5) and w == pytest.approx(0.0)
    v, w = p.action(0.0, 0.0, math.pi)           # facing away: turn, do not drive
    assert v == 0.0 and abs(w) == pytest.approx(2.0)
    v, w = p.action(0.95, 0.0, 0.0)              # near the corner the target lies up the second leg: turn left
    assert w > 0


def _digest(bag: Path) -> str:
    return hashlib.sha256(b"".join(p.read_bytes() for p in sorted(bag.rglob("*")) if p.is_file())).hexdigest()


def test_the_cli_drives_end_to_end_and_repeats_its_bytes(tmp_path, blocked):
    assert run_cli("generate", "minimal", "--seed", "2", "--out", tmp_path / "w").returncode == 0
    folder = next((tmp_path / "w").iterdir())
    first = run_cli("drive", folder, "--sim", "mujoco", "--out", tmp_path / "a")
    assert first.returncode == 0 and "mujoco: PASS: reached the goal" in first.stdout, first.stdout + first.stderr
    # A second process: the same bag, byte for byte.
    assert run_cli("drive", folder, "--sim", "mujoco", "--out", tmp_path / "b").returncode == 0
    bag_a, bag_b = (next((tmp_path / d).iterdir()) for d in ("a", "b"))
    assert _digest(bag_a) == _digest(bag_b)
    straight = run_cli("drive", blocked, "--sim", "mujoco", "--out", tmp_path / "c", "--straight")
    assert straight.returncode == 1 and "FAIL: collision with" in straight.stdout, straight.stdout + straight.stderr


@pytest.mark.parametrize("args, needle", [
    (["--sim", "webots"], "--sim"),
    (["--speed", "0"], "--speed"),
    (["--task", "task_9"], "task_9"),
    (["--gz-release", "ionic", "--sim", "gazebo"], "--gz-release"),
    (["--gz-release", "harmonic"], "add --sim gazebo"),
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
    (tmp_path / "file").write_text("x")
    onto_a_file = run_cli("drive", worlds["minimal"], "--out", tmp_path / "file")
    assert onto_a_file.returncode == 2 and "is not a folder" in onto_a_file.stderr


def test_gazebo_missing_is_one_line_naming_how_to_install(worlds, tmp_path, monkeypatch):
    monkeypatch.setenv("WORLDGEN_GAZEBO_SETUP", str(tmp_path / "no-such-setup.sh"))
    result = run_cli("drive", worlds["minimal"], "--sim", "gazebo", "--out", tmp_path / "o")
    assert result.returncode == 2 and "Traceback" not in result.stderr, result.stderr
    assert len(result.stderr.strip().splitlines()) == 1 and "install Gazebo" in result.stderr
    assert not (tmp_path / "o").exists()


def test_an_unwritable_cache_is_one_line(tmp_path, monkeypatch):
    from worldgen.errors import OutputError
    from worldgen.sim import bridge

    if bridge.shutil.which("g++") is None or bridge.shutil.which("pkg-config") is None:
        pytest.skip("no compiler here: the build stops before the cache")
    blocker = tmp_path / "cache"
    blocker.write_text("a file where the cache folder would go")
    monkeypatch.setenv("XDG_CACHE_HOME", str(blocker))
    try:
        with pytest.raises(OutputError, match="XDG_CACHE_HOME"):
            bridge.build_bridge()
    except bridge.GazeboMissingError:
        pytest.skip("no ign-transport headers here")


def test_movers_follow_their_scripts_in_mujoco(tmp_path):
    from worldgen.envs.movers import MoverScript
    from worldgen.sim.mujoco import MujocoBackend

    folder = worldgen.generate("cluttered", seed=2, n_movers=3).write(tmp_path, preview=False)
    meta = json.loads((folder / "world.json").read_text())
    backend = MujocoBackend(folder / meta["files"]["mjcf"]["path"], meta)
    spawn = meta["tasks"][0]["spawn"]
    backend.start((spawn[0], spawn[1], spawn[2], spawn[5]))
    t, *_ = backend.step(0.0, 0.0, 500)
    script = MoverScript(meta["dynamic_obstacles"])
    # The last placement was for the last step's start, one step before t.
    expected = script.positions(np.array([t - backend.dt]))[0]
    placed = backend._sim.data.mocap_pos[backend._sim.mocap, :2]
    assert placed == pytest.approx(expected, abs=1e-9)
    assert not np.allclose(expected, script.positions(np.zeros(1))[0])  # they did move


def test_a_world_and_a_pack_world_drive_as_their_folder_does(worlds, tmp_path):
    """drive() reads its world through worldgen.groundtruth.folder: an unwritten World and a pack's world (in a
    folder or an archive) drive in MuJoCo to the same run as the written folder, and are judged the same."""
    from worldgen.pack import Pack, build_pack, parse_recipe
    from worldgen.pack.archive import write_archive

    build_pack(parse_recipe("name: one\nseeds: {start: 1, count: 1}\nworlds:\n  - generator: minimal\n"),
               tmp_path / "pack")
    pack, archived = Pack.open(tmp_path / "pack"), Pack.open(write_archive(tmp_path / "pack"))
    sources = {"folder": worlds["minimal"], "world": worldgen.generate("minimal", seed=1), "pack": pack[0],
               "archive": archived[0]}
    try:
        outcomes = {kind: drive(world, tmp_path / kind, sim="mujoco") for kind, world in sources.items()}
    finally:
        pack.close()
        archived.close()
    runs = {kind: read_run(o.bag, worlds["minimal"]).trajectory for kind, o in outcomes.items()}
    for kind, outcome in outcomes.items():
        assert outcome.passed and outcome.ended == "goal", (kind, outcome.verdict)
        assert outcome.bag.name == outcomes["folder"].bag.name
        assert np.array_equal(runs[kind], runs["folder"]), kind
        # A World's colliders are its scene's; a folder's are rebuilt from world.json's 6 decimals.
        drop = ("bag", "world_folder", "min_clearance")
        assert {k: v for k, v in outcome.run.items() if k not in drop} == \
            {k: v for k, v in outcomes["folder"].run.items() if k not in drop}, kind
        assert outcome.run["min_clearance"] == pytest.approx(outcomes["folder"].run["min_clearance"], abs=1e-6)
    with pytest.raises(worldgen.errors.ParameterError, match="has no folder on disk"):
        drive(worldgen.generate("minimal", seed=1), tmp_path / "gz", sim="gazebo")
