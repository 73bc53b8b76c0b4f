"""The ``--ros`` bundle's world (ros2/world.sdf, the Gazebo systems a run needs) in a real Gazebo (the Harmonic
bundle's in Harmonic too) with a robot carrying a gpu_lidar at the first task's spawn: it loads for both
releases' plugin names, the robot
stands where it was put, and the scan agrees with world.json's ground-truth lidar."""

from __future__ import annotations

import json
import math

import numpy as np
import pytest
from support.gazebo import lidar_robot_sdf, scan_ranges

import worldgen
from worldgen.sim.gazebo import GazeboServer

pytestmark = pytest.mark.gazebo



@pytest.mark.parametrize(("release", "server"), [("fortress", "fortress"), ("harmonic", "fortress"),
                                                 ("harmonic", "harmonic")])
def test_the_ros_bundle_world_runs_a_lidar_robot_that_sees_what_world_json_says(release, server, installs, tmp_path):
    # Fortress 6.18 maps Harmonic's gz-sim-* plugin names to its own, so both bundles load in it; the Harmonic
    # bundle's world runs in gz-sim 8 too.
    install = installs(server)
    folder = worldgen.generate("cluttered", seed=0).write(tmp_path, preview=False,
                                                          ros=True if release == "harmonic" else release)
    meta = json.loads((folder / "world.json").read_text())
    lidar = meta["sensors"]["lidar"]
    x, y, _, _, _, yaw = meta["tasks"][0]["spawn"]
    with GazeboServer(folder / "ros2" / "world.sdf", install=install, headless_rendering=True) as gz:
        assert gz.problems() == []
        gz.spawn(lidar_robot_sdf(lidar), "robot", (x, y, 0.0, yaw))
        scan = gz.echo("/scan", 1, step=25)[0]
        robot = gz.poses()["robot"]
    got, want = scan_ranges(scan, lidar["range_max"]), np.array(lidar["ranges"])
    error = np.abs(got - want)
    # gpu_lidar against the exact ranges: millimetres, except the few rays that graze an obstacle's edge
    assert len(got) == lidar["samples"]
    assert np.median(error) < 0.005 and np.percentile(error, 90) < 0.03, (np.median(error), np.percentile(error, 90))
    assert math.hypot(robot[0] - x, robot[1] - y) < 1e-3
    assert abs(math.remainder(2 * math.atan2(robot[5], robot[6]) - yaw, 2 * math.pi)) < 1e-3
    assert gz.problems() == []
