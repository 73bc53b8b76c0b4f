"""One robot, described once (issue 37, item 3): the environment's MuJoCo robot, the robot ``worldgen drive``
builds in MuJoCo and robot.sdf / robot.urdf for Gazebo and ROS carry world.json's numbers (sizes, motion
limits, lidar) in a flat world, a world with people and a terrain world, and a world.json that states no
limits gets the documented defaults."""

from __future__ import annotations

import math

import numpy as np
import pytest
from lxml import etree
from support import missing_tool
from support.envs import gymnasium

import worldgen
from worldgen.errors import ParameterError
from worldgen.export.robot import robot_sdf, robot_urdf
from worldgen.groundtruth.folder import open_world, robot_description_of
from worldgen.params import COMMON_PARAMS
from worldgen.presets import generate_preset
from worldgen.scene.robot import ACCELERATION, MAX_SPEED, TURN_RATE

#: Each world with numbers of its own where the parameters allow: a faster robot and a sparser lidar in the
#: flat world, a quicker turn and acceleration among people.
WORLDS = {
    "flat": lambda: worldgen.generate("minimal", 2, robot_speed=0.8, lidar_samples=90, lidar_height=0.25),
    "people": lambda: generate_preset("person_crossing", seed=0, robot_turn_rate=2.0, robot_acceleration=1.5),
    "terrain": lambda: worldgen.generate("terrain", 0),
}


@pytest.fixture(scope="module", params=sorted(WORLDS))
def world(request):
    return WORLDS[request.param]()


def _stated(meta: dict) -> dict:
    """The numbers world.json states for the robot, read here without the reader under test."""
    robot, params, lidar = meta["robot"], meta["params"], meta["sensors"]["lidar"]
    defaults = {p.name: p.default for p in COMMON_PARAMS}
    limit = {k: robot.get(k, params.get(p, defaults[p])) for k, p in
             (("max_speed", "robot_speed"), ("max_turn_rate", "robot_turn_rate"),
              ("max_acceleration", "robot_acceleration"))}
    return dict(radius=robot["radius"], height=robot["height"], lidar_height=lidar["pose"][2], **limit,
                **{f"lidar_{k}": lidar[k] for k in ("samples", "angle_min", "angle_max", "range_min", "range_max")})


def _model_robot(model) -> dict:
    """The MuJoCo robot's radius, top, mass and servo ranges (forward, turn) in a compiled model."""
    from worldgen.envs.robot import ROBOT

    geom = model.geom(ROBOT)
    radius, half = float(geom.size[0]), float(geom.size[1])
    forward, turn = (model.actuator(f"{ROBOT}_{s}").ctrlrange.tolist() for s in ("forward", "turn"))
    # The body's centre stands half its height over its bottom (the floor gap, or a terrain base's clearance).
    return dict(radius=radius, top=float(model.body(ROBOT).pos[2]) + half, mass=float(model.body(ROBOT).mass[0]),
                forward=forward, turn=turn)


def test_the_description_is_world_jsons_whether_read_from_the_folder_or_the_world(world):
    meta = world.metadata
    stated, described = _stated(meta), open_world(world).robot_description
    assert described == robot_description_of(meta)  # a World and its world.json describe one robot
    assert (described.radius, described.height) == (stated["radius"], stated["height"])
    assert (described.max_speed, described.turn_rate, described.acceleration) == \
        (stated["max_speed"], stated["max_turn_rate"], stated["max_acceleration"])
    lidar = described.lidar
    assert (lidar.height, lidar.samples, lidar.angle_min, lidar.angle_max, lidar.range_min, lidar.range_max) == \
        tuple(stated[k] for k in ("lidar_height", "lidar_samples", "lidar_angle_min", "lidar_angle_max",
                                  "lidar_range_min", "lidar_range_max"))


def _tree_robot(root) -> dict:
    """The same figures read off the MJCF tree the robot was added to, before MuJoCo compiles it."""
    from worldgen.envs.robot import ROBOT

    geom = root.find(f".//geom[@name='{ROBOT}']")
    radius, half = (float(v) for v in geom.get("size").split())
    forward, turn = ([float(v) for v in root.find(f".//velocity[@name='{ROBOT}_{s}']").get("ctrlrange").split()]
                     for s in ("forward", "turn"))
    centre = float(root.find(f".//body[@name='{ROBOT}']").get("pos").split()[2])
    return dict(radius=radius, top=centre + half, mass=float(geom.get("mass")), forward=forward, turn=turn)


def _agrees(got: dict, stated: dict, reverse: float) -> None:
    assert (got["radius"], got["top"], got["mass"]) == pytest.approx((stated["radius"], stated["height"], 10.0))
    assert got["forward"] == pytest.approx([reverse, stated["max_speed"]])
    assert got["turn"] == pytest.approx([-stated["max_turn_rate"], stated["max_turn_rate"]])


def test_the_environments_robot_is_world_jsons(world):
    if gymnasium is None:
        missing_tool("gymnasium (pip install 'worldgen[rl]')")
    import worldgen.envs  # noqa: F401  (registers the id)
    from worldgen.envs.source import OneWorldSource

    stated = _stated(world.metadata)
    env = gymnasium.make("worldgen/Navigation-v0", lidar_beams=8).unwrapped
    env.source = OneWorldSource(world)
    env.reset(seed=0)
    assert env._lidar_height == stated["lidar_height"]
    _agrees(_model_robot(env._sim.model), stated, 0.0)  # forward only: the action box starts at standstill


def test_drives_mujoco_robot_is_world_jsons(world):
    from worldgen.sim.mujoco import MujocoBackend

    opened = open_world(world)
    meta, stated = opened.metadata, _stated(opened.metadata)
    backend = MujocoBackend(opened.file_bytes("mjcf"), meta, world.scene)
    # It may back away from an opening leaf at up to its top speed.
    _agrees(_tree_robot(backend._root), stated, -stated["max_speed"])
    spawn = meta["tasks"][0]["spawn"]
    backend.start((spawn[0], spawn[1], spawn[2], spawn[5]))
    _agrees(_model_robot(backend._sim.model), stated, -stated["max_speed"])


def _sdf_numbers(sdf: str) -> dict:
    model = etree.fromstring(sdf.encode()).find("model")
    drive = next(p for p in model.findall("plugin") if p.get("name").endswith("DiffDrive"))
    base, scan = model.find("link[@name='base_link']"), model.find("link[@name='base_scan']")
    chassis = base.find("collision[@name='chassis_collision']")
    length = float(chassis.find("geometry/cylinder/length").text)
    top = float(base.find("pose").text.split()[2]) + float(chassis.find("pose").text.split()[2]) + length / 2
    ray = scan.find("sensor/lidar")
    return dict(radius=float(chassis.find("geometry/cylinder/radius").text), height=top,
                mass=float(base.find("inertial/mass").text), lidar_height=float(scan.find("pose").text.split()[2]),
                **{k: float(drive.find(k).text) for k in ("max_linear_velocity", "min_linear_velocity",
                                                         "max_angular_velocity", "max_linear_acceleration")},
                lidar_samples=int(ray.find("scan/horizontal/samples").text),
                lidar_angle_min=float(ray.find("scan/horizontal/min_angle").text),
                lidar_angle_max=float(ray.find("scan/horizontal/max_angle").text),
                lidar_range_min=float(ray.find("range/min").text), lidar_range_max=float(ray.find("range/max").text))


def test_robot_sdf_and_urdf_are_world_jsons(world):
    stated = _stated(world.metadata)
    sdf = _sdf_numbers(robot_sdf(world.metadata))
    assert sdf == pytest.approx(dict(
        radius=stated["radius"], height=stated["height"], mass=10.0, lidar_height=stated["lidar_height"],
        max_linear_velocity=stated["max_speed"], min_linear_velocity=-stated["max_speed"],
        max_angular_velocity=stated["max_turn_rate"], max_linear_acceleration=stated["max_acceleration"],
        **{k: stated[k] for k in stated if k.startswith("lidar_") and k != "lidar_height"}), abs=1e-6)
    assert robot_sdf(world) == robot_sdf(world.metadata)  # a World and its world.json give the same bytes
    urdf = etree.fromstring(robot_urdf(world.metadata).encode())
    base = urdf.find("link[@name='base_link']")
    wheel_z = float(urdf.find("joint[@name='base_footprint_joint']/origin").get("xyz").split()[2])
    scan_z = float(urdf.find("joint[@name='base_scan_joint']/origin").get("xyz").split()[2])
    assert float(base.find("collision/geometry/cylinder").get("radius")) == pytest.approx(stated["radius"])
    assert float(base.find("inertial/mass").get("value")) == 10.0
    assert wheel_z + scan_z == pytest.approx(stated["lidar_height"], abs=1e-6)


def test_a_world_json_without_limits_gets_the_documented_defaults():
    meta = generate_preset("person_crossing", seed=0).metadata
    old = dict(meta, robot={k: meta["robot"][k] for k in ("radius", "height", "clearance")},
               params={k: v for k, v in meta["params"].items()
                       if k not in ("robot_speed", "robot_turn_rate", "robot_acceleration")})
    described = robot_description_of(old)
    defaults = {p.name: p.default for p in COMMON_PARAMS}
    assert (described.max_speed, described.turn_rate, described.acceleration) == \
        (MAX_SPEED, TURN_RATE, ACCELERATION) == \
        (defaults["robot_speed"], defaults["robot_turn_rate"], defaults["robot_acceleration"])
    from worldgen.people import timed
    assert (timed.TURN_RATE, timed.ACCELERATION) == (TURN_RATE, ACCELERATION)  # one home for each default
    sdf = _sdf_numbers(robot_sdf(old))
    assert (sdf["max_linear_velocity"], sdf["max_angular_velocity"], sdf["max_linear_acceleration"]) == \
        (MAX_SPEED, TURN_RATE, ACCELERATION)


def test_the_environments_settings_override_the_robots_speeds():
    if gymnasium is None:
        missing_tool("gymnasium (pip install 'worldgen[rl]')")
    import worldgen.envs  # noqa: F401
    from worldgen.envs.source import OneWorldSource

    world = WORLDS["flat"]()
    env = gymnasium.make("worldgen/Navigation-v0", lidar_beams=8, linear_velocity=[-0.2, 1.2]).unwrapped
    env.source = OneWorldSource(world)
    assert env.action_space.high.tolist() == pytest.approx([1.2, TURN_RATE])  # w: the robot's, unset here
    env.reset(seed=0)
    got = _model_robot(env._sim.model)
    assert got["forward"] == pytest.approx([-0.2, 1.2]) and got["turn"] == pytest.approx([-TURN_RATE, TURN_RATE])
    path = world.metadata["tasks"][0]["path"]["length"]
    assert env._time_limit == pytest.approx(2.0 * path / 1.2 + math.pi / TURN_RATE)
    # Unset, the box is the source's robots' limits and each episode's robot its world's.
    default = gymnasium.make("worldgen/Navigation-v0", generator="minimal", params={"robot_speed": 0.8},
                             lidar_beams=8).unwrapped
    assert default.action_space.high.tolist() == pytest.approx([0.8, TURN_RATE])


def test_drive_refuses_a_speed_beyond_the_robots_in_one_line(tmp_path):
    from worldgen.sim.drive import drive

    world = WORLDS["flat"]()
    with pytest.raises(ParameterError, match=r"option '--speed' must be in \(0, 0.8\] m/s"):
        drive(world, tmp_path, sim="mujoco", speed=0.9)
    assert np.isclose(open_world(world).robot_description.max_speed, 0.8)
