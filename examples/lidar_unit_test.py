"""A lidar unit test: a wall 2.0 m ahead, MuJoCo ray casting as the sensor, world.json as the oracle.

    .venv/bin/python examples/lidar_unit_test.py [OUT_DIR]

The ``lidar_wall`` preset (the ``minimal`` generator) stands the robot at the
origin facing +x with a wall whose near face is the plane x = 2.0, and starts
its scan straight ahead (``lidar_angle_min`` 0, so ``ranges[0]`` is the forward
beam, as in a ROS LaserScan whose angle_min is 0). The "sensor"
is MuJoCo's own ray caster (``mujoco.mj_ray``) on the exported MJCF, one ray per
beam of world.json's ``sensors.lidar`` (pose, angles, range limits); every beam
must agree with the recorded ground truth, and the forward beam must read 2.0 m.
The world folder is written to OUT_DIR so the files can be inspected.
"""

from __future__ import annotations

import math
import sys
import tempfile

import mujoco
import numpy as np

from worldgen import generate_preset

TOLERANCE = 1e-4  # m: both sides are exact ray casts; only 6-decimal rounding separates them


def mujoco_scan(model, data, lidar: dict) -> np.ndarray:
    """Ranges as a noise-free planar lidar built on mj_ray would report them."""
    x, y, z, _, _, yaw = lidar["pose"]
    angles = np.linspace(lidar["angle_min"], lidar["angle_max"], lidar["samples"])
    ranges = np.empty(len(angles))
    geomid = np.zeros(1, dtype=np.int32)
    for i, a in enumerate(angles):
        d = np.array([math.cos(yaw + a), math.sin(yaw + a), 0.0])
        # Cast from range_min along the beam (as the ground truth does), then add range_min back.
        start = np.array([x, y, z]) + lidar["range_min"] * d
        hit = mujoco.mj_ray(model, data, start, d, None, 1, -1, geomid)
        r = hit + lidar["range_min"] if hit >= 0 else math.inf
        ranges[i] = r if r <= lidar["range_max"] else lidar["range_max"]
    return ranges


def main(out_dir: str) -> int:
    world = generate_preset("lidar_wall")
    folder = world.write(out_dir)
    lidar = world.metadata["sensors"]["lidar"]
    model = mujoco.MjModel.from_xml_path(str(folder / "world.mjcf.xml"))
    data = mujoco.MjData(model)
    mujoco.mj_forward(model, data)
    measured = mujoco_scan(model, data, lidar)
    truth = np.asarray(lidar["ranges"])
    forward = 0  # ranges[i] is the beam at angle_min + i * increment, and angle_min is 0 here
    assert lidar["angle_min"] == 0.0
    worst = float(np.max(np.abs(measured - truth)))
    print(f"{len(truth)} beams; forward beam {measured[forward]:.6f} m (ground truth {truth[forward]:.6f} m); "
          f"largest disagreement {worst:.2e} m")
    assert abs(measured[forward] - 2.0) < TOLERANCE, measured[forward]
    assert worst < TOLERANCE, worst
    print("lidar unit test passed")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1] if len(sys.argv) > 1 else tempfile.mkdtemp(prefix="worldgen-lidar-")))
