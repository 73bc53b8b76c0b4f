"""Lidar ground truth: exact ranges, checked ray by ray against MuJoCo's own mj_ray on the exported MJCF."""

from __future__ import annotations

import math

import mujoco
import numpy as np
import pytest
from support import draft
from support.scenes import showcase_scene

import worldgen
from worldgen.errors import ParameterError
from worldgen.export import mjcf
from worldgen.groundtruth import lidar
from worldgen.scene import Box, Node, Pose, Scene

#: mj_ray sees geom groups 0, 1, 3, 4, 5: worldgen's visual-only markers sit in group 2.
GROUPS = np.array([1, 1, 0, 1, 1, 1], dtype=np.uint8)


def mujoco_ranges(scene: Scene, spec: lidar.LidarSpec) -> np.ndarray:
    """Ranges by mj_ray from the lidar pose, static geoms included, no body excluded; inf = no hit."""
    model = mujoco.MjModel.from_xml_string(mjcf.to_mjcf(scene).decode())
    data = mujoco.MjData(model)
    mujoco.mj_forward(model, data)  # geom poses of the bodies (a door leaf, loose objects)
    origin = spec.pose.position
    geom = np.zeros(1, dtype=np.int32)
    out = []
    for d in lidar.directions(spec):
        r = mujoco.mj_ray(model, data, origin, d, GROUPS, 1, -1, geom)
        out.append(np.inf if r < 0 else r)
    return np.array(out)


def spec_at(x, y, z, yaw=0.0, samples=360, range_min=0.0, range_max=50.0):
    return lidar.spec_from_params({"lidar_fov": 2 * math.pi, "lidar_samples": samples, "lidar_height": z,
                                   "lidar_range_min": range_min, "lidar_range_max": range_max},
                                  Pose(x, y, 0.0, 0, 0, yaw))


def assert_agree(ours, theirs):
    hit = np.isfinite(theirs)
    np.testing.assert_array_equal(np.isfinite(ours), hit)  # hit and miss on the same rays
    assert np.abs(ours[hit] - theirs[hit]).max(initial=0.0) < 1e-3


@pytest.mark.parametrize("seed", range(24))
def test_cluttered_worlds_agree_with_mj_ray_on_every_ray(seed):
    scene, tasks = draft("cluttered", seed, size=[12, 12], n_obstacles=40, walls=seed % 3 != 0)
    spawn = tasks[0].spawn
    spec = spec_at(spawn.x, spawn.y, 0.3, spawn.yaw)
    ours = lidar.cast(scene, spec.pose.position, lidar.directions(spec))
    theirs = mujoco_ranges(scene, spec)
    assert_agree(ours, theirs)
    if seed % 3 != 0:  # a walled room: every ray ends on something
        assert np.isfinite(ours).all()


@pytest.mark.parametrize("z", [0.004, 0.15, 0.35, 0.6, 0.95, 1.4])
def test_every_shape_kind_tilted_meshes_and_a_door_agree_with_mj_ray(z):
    # Tilted boxes and cylinders, a sphere, meshes (turned, scaled), loose bodies, a door leaf on its
    # hinge and a marker (at z = 0.004 the marker is cut, and must be seen by neither).
    scene = showcase_scene()
    for x, y, yaw in [(0.0, 0.0, 0.3), (0.3, -0.5, -1.0), (-1.5, 0.5, 2.0), (1.2, 2.4, 0.0), (1.5, 0.0, 0.0)]:
        spec = spec_at(x, y, z, yaw, samples=720)
        ours = lidar.cast(scene, spec.pose.position, lidar.directions(spec))
        assert_agree(ours, mujoco_ranges(scene, spec))


def wall_ahead(distance=2.0, thickness=0.1):
    floor = Node("floor", "floor", Box((20, 20, 0.1)), Pose(0, 0, -0.05))
    wall = Node("wall", "wall", Box((thickness, 4.0, 1.0)), Pose(distance + thickness / 2, 0.0, 0.5))
    return Scene((floor, wall), bounds=((-9, -9), (9, 9)))


def test_a_wall_two_metres_ahead_reads_two_metres_and_nothing_else_reads_range_max():
    scene = wall_ahead()
    spec = spec_at(0.0, 0.0, 0.3, samples=360, range_min=0.05, range_max=30.0)
    ranges = lidar.scan(scene, spec)
    a = lidar.angles(spec)
    assert a[0] == -math.pi and len(a) == 360
    assert a[-1] == pytest.approx(math.pi - 2 * math.pi / 360)  # a full circle casts no ray twice
    ahead = int(np.argmin(np.abs(a)))
    assert abs(a[ahead]) < 1e-12 and ranges[ahead] == pytest.approx(2.0, abs=1e-9)
    # Exactly 2 / cos(angle) while the ray meets the 4 m wide wall, range_max elsewhere.
    meets = np.abs(2.0 * np.tan(a)) <= 2.0
    meets &= np.cos(a) > 0
    np.testing.assert_allclose(ranges[meets], 2.0 / np.cos(a[meets]), atol=1e-9)
    assert np.all(ranges[~meets] == 30.0)
    # The floor slab under a horizontal ray is never hit; a turned sensor turns its rays.
    turned = lidar.scan(scene, spec_at(0.0, 0.0, 0.3, yaw=math.pi / 2, samples=360, range_max=30.0))
    assert turned[int(np.argmin(np.abs(a + math.pi / 2)))] == pytest.approx(2.0, abs=1e-9)


def test_rays_start_at_range_min_and_stop_at_range_max():
    floor = Node("floor", "floor", Box((20, 20, 0.1)), Pose(0, 0, -0.05))
    near = Node("near", "obstacle", Box((0.01, 0.5, 1.0)), Pose(0.03, 0.0, 0.5))  # 0.025 .. 0.035 m ahead
    far = Node("far", "wall", Box((0.1, 4.0, 1.0)), Pose(3.05, 0.0, 0.5))
    scene = Scene((floor, near, far), bounds=((-9, -9), (9, 9)))
    one = {"lidar_fov": 1.0, "lidar_samples": 1, "lidar_height": 0.3, "lidar_range_max": 30.0}
    assert lidar.scan(scene, lidar.spec_from_params({**one, "lidar_range_min": 0.0}, Pose()))[0] == pytest.approx(0.025)
    assert lidar.scan(scene, lidar.spec_from_params({**one, "lidar_range_min": 0.05}, Pose()))[0] == pytest.approx(3.0)
    assert lidar.scan(scene, lidar.spec_from_params({**one, "lidar_range_min": 0.05, "lidar_range_max": 2.5},
                                                    Pose()))[0] == 2.5
    # A partial field of view spans angle_min .. angle_max inclusive, centred ahead.
    part = lidar.spec_from_params({**one, "lidar_fov": math.pi, "lidar_samples": 181, "lidar_range_min": 0.0}, Pose())
    assert (part.angle_min, part.angle_max) == (-math.pi / 2, math.pi / 2)
    assert abs(lidar.angles(part)[90]) < 1e-12


def test_world_json_carries_the_scan_at_the_first_spawn():
    world = worldgen.generate("cluttered", seed=4, size=[8, 8], n_obstacles=12, lidar_height=0.25,
                              lidar_samples=90, lidar_range_max=12.0)
    block = world.metadata["sensors"]["lidar"]
    spawn = world.tasks[0].spawn
    assert block["pose"] == [spawn.x, spawn.y, 0.25, 0.0, 0.0, spawn.yaw]
    assert block["samples"] == 90 == len(block["ranges"])
    assert (block["range_min"], block["range_max"]) == (0.05, 12.0)
    spec = lidar.spec_from_params(world.params, spawn)
    np.testing.assert_allclose(block["ranges"], mujoco_ranges(world.scene, spec).clip(max=12.0), atol=1e-3)
    assert min(block["ranges"]) >= world.robot.inflation  # the spawn is free, so is the lidar's circle


def test_lidar_range_limits_are_checked():
    with pytest.raises(ParameterError, match=r"parameter 'lidar_range_min' must be below lidar_range_max = 5.0, got 6.0"):
        worldgen.generate("cluttered", seed=0, lidar_range_min=6.0, lidar_range_max=5.0)
    with pytest.raises(ParameterError, match=r"parameter 'lidar_samples' must be in \[1, 100000\], got 0"):
        worldgen.generate("cluttered", seed=0, lidar_samples=0)


@pytest.mark.parametrize("angle_min,fov,samples", [(0.0, 2 * math.pi, 360), (-1.0, 2 * math.pi, 7),
                                                   (0.3, 1.2, 5), (-math.pi, math.pi, 181)])
def test_lidar_angle_min_sets_ranges_0_as_a_ros_laserscan(angle_min, fov, samples):
    """ranges[i] is the beam at angle_min + i * increment, counter-clockwise from the heading."""
    room = Scene((Node("floor", "floor", Box((20, 20, 0.1)), Pose(0, 0, -0.05)),
                  *[Node(f"w{k}", "wall", Box((0.1, 20, 1)), Pose(x, 0, 0.5)) for k, x in enumerate((-3.05, 5.05))],
                  *[Node(f"v{k}", "wall", Box((20, 0.1, 1)), Pose(0, y, 0.5)) for k, y in enumerate((-2.05, 4.05))]),
                 bounds=((-3, -2), (5, 4)))
    yaw = 0.4
    spec = lidar.spec_from_params({"lidar_fov": fov, "lidar_samples": samples, "lidar_angle_min": angle_min,
                                   "lidar_height": 0.3, "lidar_range_min": 0.0, "lidar_range_max": 50.0},
                                  Pose(0, 0, 0, 0, 0, yaw))
    increment = (fov / samples) if fov >= 2 * math.pi - 1e-9 else fov / (samples - 1)
    assert spec.angle_min == angle_min
    assert spec.angle_max == pytest.approx(angle_min + (samples - 1) * increment, abs=1e-12)
    ranges = lidar.scan(room, spec)
    for i in range(samples):
        beam = yaw + angle_min + i * increment  # world bearing of beam i
        c, s = math.cos(beam), math.sin(beam)
        # Exact distance to the room's inner faces x in [-3, 5], y in [-2, 4] from the origin.
        t = min(v for v in ((5 / c) if c > 1e-12 else math.inf, (-3 / c) if c < -1e-12 else math.inf,
                            (4 / s) if s > 1e-12 else math.inf, (-2 / s) if s < -1e-12 else math.inf))
        assert ranges[i] == pytest.approx(t, abs=1e-9)


def test_the_seed_lidar_unit_test_reads_ranges_0():
    """The seed's test, as it is written: scan.ranges[0] is the wall 2.0 m ahead, within 5 cm."""
    scan = worldgen.generate_preset("lidar_wall").metadata["sensors"]["lidar"]
    assert abs(scan["ranges"][0] - 2.0) < 0.05
    assert scan["angle_min"] == 0.0 and scan["ranges"][0] == pytest.approx(2.0, abs=1e-6)
    # Without lidar_angle_min, a full circle starts behind the robot: ranges[0] would not be the wall.
    centred = worldgen.generate_preset("lidar_wall", lidar_angle_min=None).metadata["sensors"]["lidar"]
    assert centred["angle_min"] == pytest.approx(-math.pi, abs=1e-6) and abs(centred["ranges"][0] - 2.0) > 0.05
