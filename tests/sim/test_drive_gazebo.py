"""The robot in a real Gazebo (Fortress and Harmonic, headless): its gpu_lidar agrees with world.json's lidar at
the spawn, ``worldgen drive --sim gazebo`` reaches the goal without contact in a world of every generator, and a
straight drive is judged a collision with the obstacle in the way. Fortress runs every case, Harmonic a sample
(every case with ``WORLDGEN_GAZEBO_ALL=1``). Group ``gazebo``: skips without Gazebo on a laptop, fails on CI
(``CI`` set), also when one of the releases is missing."""

from __future__ import annotations

import json
import math
import time
from pathlib import Path

import numpy as np
import pytest
from support.cli import run as run_cli
from support.gazebo import gazebo_install, release_cases, scan_stamp

import worldgen
from worldgen import oracles
from worldgen.export.contract import SIM_GZ_RELEASES

pytestmark = pytest.mark.gazebo
pytest.importorskip("rosbags")

GENERATORS = ("barn", "cluttered", "corridor", "door", "minimal")


@pytest.fixture(scope="module", autouse=True)
def gazebo():
    return gazebo_install()  # the gazebo group's one finder: skips on a laptop, fails on CI



@pytest.fixture(scope="module")
def worlds(tmp_path_factory) -> dict[str, Path]:
    out = tmp_path_factory.mktemp("worlds")
    return {g: worldgen.generate(g, seed=1).write(out, preview=False) for g in GENERATORS}


@pytest.mark.parametrize(("release", "generator"), release_cases(["cluttered", "minimal"], {"cluttered"},
                                                                  first={"cluttered"}))
def test_one_scan_agrees_with_world_json_and_misses_only_on_edges(worlds, release, generator, installs):
    from worldgen.sim.scan import edge_rays, read_scan

    installs(release)
    folder = worlds[generator]
    truth = np.array(json.loads((folder / "world.json").read_text())["sensors"]["lidar"]["ranges"])
    got, frame = read_scan(folder, gz_release=release)
    assert frame == "base_scan"  # the URDF's frame (gz_frame_id), not Gazebo's scoped sensor name
    assert got.shape == truth.shape
    error = np.abs(got - truth)
    assert np.median(error) < 0.01, f"median |error| {np.median(error):.4f} m"
    # Rays that graze an obstacle's edge land on either side of the jump; every other ray is within 5 cm.
    off = set(np.flatnonzero(error > 0.05).tolist())
    assert off <= set(edge_rays(truth).tolist()), sorted(off - set(edge_rays(truth).tolist()))
    assert len(off) <= 0.05 * len(truth)


def test_lidar_noise_is_the_gaussian_asked_for(worlds):
    from worldgen.sim.scan import edge_rays, gazebo_scan

    folder = worlds["barn"]
    truth = np.array(json.loads((folder / "world.json").read_text())["sensors"]["lidar"]["ranges"])
    error = gazebo_scan(folder, lidar_noise=0.05) - truth
    keep = np.setdiff1d(np.arange(len(truth)), edge_rays(truth))
    # 312 rays: the sample deviation of N(0, 0.05) lies within 15 % of it with odds above 99.5 %; the noise-free
    # renderer's own error (median 1.6 mm here) is small beside it.
    assert abs(np.std(error[keep]) - 0.05) < 0.0075 and abs(np.mean(error[keep])) < 0.01


def _drive(folder: Path, out: Path, *extra: str):
    result = run_cli("drive", folder, "--sim", "gazebo", "--out", out, *extra)
    assert "Traceback" not in result.stderr, result.stderr
    bag = next(out.iterdir())
    from worldgen.judge import judge

    return result, judge([bag], world=folder).report["runs"][0]


#: Fortress drives barn, corridor and door worlds, Harmonic door and cluttered ones (minimal's in MuJoCo; every
#: generator in both releases with WORLDGEN_GAZEBO_ALL=1).
@pytest.mark.parametrize(("release", "generator"), release_cases(list(GENERATORS), {"door", "cluttered"},
                                                                  first={"barn", "corridor", "door"}))
def test_gazebo_drive_reaches_the_goal_without_contact(worlds, tmp_path, release, generator, installs):
    installs(release)
    result, run = _drive(worlds[generator], tmp_path, "--gz-release", release)
    assert result.returncode == 0 and "gazebo: PASS: reached the goal" in result.stdout, result.stdout + result.stderr
    assert run["success"] and run["reached_goal"] and run["collisions"] == []
    assert run["source"] == "ground_truth"


def test_gazebo_straight_drive_is_a_collision_with_the_obstacle_in_the_way(tmp_path):
    out = tmp_path / "worlds"
    for seed in range(20):
        folder = worldgen.generate("cluttered", seed=seed).write(out, preview=False)
        task = json.loads((folder / "world.json").read_text())["tasks"][0]
        s, g = np.array(task["spawn"][:2]), np.array(task["goal"][:2])
        u = np.linspace(0.0, 1.0, int(np.hypot(*(g - s)) / 0.005) + 2)
        sweep = np.c_[u * 10.0, s[0] + u * (g - s)[0], s[1] + u * (g - s)[1],
                      np.full(len(u), math.atan2(g[1] - s[1], g[0] - s[0]))]
        contacts = oracles.collisions(sweep, folder)
        if contacts and contacts[0].entity.startswith("obstacle"):
            break
    else:
        raise AssertionError("no cluttered world of seeds 0-19 has an obstacle between spawn and goal")
    result, run = _drive(folder, tmp_path / "runs", "--straight")
    assert result.returncode == 1 and "FAIL: collision with" in result.stdout, result.stdout + result.stderr
    assert run["collisions"][0]["entity"] == contacts[0].entity


def test_gazebo_drive_keeps_the_timed_path_among_people(tmp_path):
    """Issue 37: driven along its static path, person_crossing meets person_0 at 8.70 s; on world.json's timed
    path Gazebo reaches the goal, judged against person_0 where world.json has it (Fortress's actors play the
    recorded walk and have no body). A schedule among movers is not tested here: the Gazebo robot tracks a
    schedule that turns badly (docs/drive.md)."""
    from worldgen.presets import generate_preset

    folder = generate_preset("person_crossing", seed=0).write(tmp_path / "worlds", preview=False)
    result, run = _drive(folder, tmp_path / "runs")
    assert result.returncode == 0 and "gazebo: PASS: reached the goal" in result.stdout, result.stdout + result.stderr
    assert "followed the timed path" in result.stdout
    assert run["collisions"] == [] and run["reached_goal"]


@pytest.mark.parametrize("release", SIM_GZ_RELEASES)
def test_the_body_goes_no_further_than_its_wheels_turned_and_turns_on_the_spot(release, installs, tmp_path):
    # Issue 39: in Harmonic the body went 0.22 m further than its wheels turned after a stop. Measured: the
    # same in Fortress. With no acceleration limit a twist sets the wheels' speed in one step, the tyres slip
    # on a start and the body slides on after a stop (0.31 m from 2 m/s, 0.02 m from 0.5 m/s). Here the
    # robot drives 2 s at 2 m/s in an empty room and stops; the ground truth and the DiffDrive's odometry
    # (integrated from the wheels' joints) must agree at the stop and 2 s later.
    from worldgen.export.robot import robot_sdf
    from worldgen.sim import textproto
    from worldgen.sim.bridge import GazeboBackend, world_step

    install = installs(release)
    folder = worldgen.generate("cluttered", seed=0, size=[20.0, 20.0], n_obstacles=0).write(tmp_path, preview=False)
    sdf, per = folder / "world.sdf", 25
    dt = world_step(sdf)
    # The world's robot (0.5 m/s, 1 m/s^2) made a 2 m/s robot braking at 2.5 m/s^2 (nav2's controllers' default
    # acc_lim_x), the figures this was measured with: from 2 m/s tyres without the limit slip by 0.31 m.
    from dataclasses import replace

    from worldgen.groundtruth.folder import robot_description_of

    described = replace(robot_description_of(json.loads((folder / "world.json").read_text())), max_speed=2.0,
                        acceleration=2.5)
    robot = robot_sdf(described, gz_release=release, sensors=False, odom_rate=1.0 / ((per - 0.5) * dt))
    backend = GazeboBackend(sdf, robot, dt=dt, first_steps=per, install=install)
    try:
        x0 = backend.start((-8.0, 0.0, 0.0, 0.0))[1]
        assert backend._server is not None
        with backend._server.subscribe("/odom") as odom:
            time.sleep(2.0)  # the subscriber connects in wall time; the world must not step behind the bridge
            marks = []
            for v in (2.0, 0.0):
                for _ in range(40):
                    t, truth = backend.step(v, 0.0, per)[:2]
                # the DiffDrive's message stamped when the ground truth was
                same = odom.wait(1, timeout=10, where=lambda m: abs(scan_stamp(m) - t) < dt / 2)[0]
                pose = textproto.first(same, "pose", {})
                marks.append((truth - x0, float(textproto.first(textproto.first(pose, "position", {}), "x", 0.0))))
        # Then on the spot: with the wheels' cylinders for collisions DART touched each at the same end of its
        # width, and the robot pivoted 2 cm to the right of its centre, which went round a circle 4 cm across
        # (barn seed 22: the timed follower turned round to go back; docs/drive.md).
        centre = backend.step(0.0, 0.0, per)[1:3]
        spun = [backend.step(0.0, 3.0, per) for _ in range(40)] + [backend.step(0.0, 0.0, per) for _ in range(10)]
    finally:
        backend.close()
    turned = abs(float(np.unwrap([pose[3] for pose in spun])[-1]) - spun[0][3])
    off = max(math.hypot(p[1] - centre[0], p[2] - centre[1]) for p in spun)
    assert turned > 1.5 and off < 0.002, (turned, off)  # measured 0.0 mm (before: up to 40 mm)
    (moving, wheels_moving), (stopped, wheels_stopped) = marks
    assert moving > 2.5 and stopped - moving > 0.1, marks  # it drove, and it braked over a distance
    assert abs(moving - wheels_moving) < 0.005 and abs(stopped - wheels_stopped) < 0.005, marks
