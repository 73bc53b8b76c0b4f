"""The environment in a terrain world: the robot is the terrain base (worldgen.envs.terrain), an episode
driven along the reference path climbs the ramp and comes down to the goal without a contact, the lidar
riding with the body; a flat world's robot is the flat base, unchanged."""

from __future__ import annotations

import math

import numpy as np
import pytest
from lxml import etree
from support.envs import make
from support.terrain import RAMP_PARAMS, RAMP_SEED

from worldgen.envs.policies import PathFollower
from worldgen.envs.robot import add_robot
from worldgen.envs.terrain import add_base, centre_height, lidar_frame
from worldgen.scene import Robot


def test_an_episode_climbs_the_ramp_and_reaches_the_goal_with_the_lidar_riding():
    env = make(generator="terrain", params=RAMP_PARAMS)
    env.reset(seed=0, options={"world_seed": RAMP_SEED})
    assert env.world.terrain
    (ramp,) = env.world.scene().terrain.elements
    robot = env.world.robot
    follow = PathFollower(env.task["path"]["waypoints"], v_max=0.5, w_max=2.0, lookahead=0.3)
    lidar_z = []
    for _ in range(400):
        obs, _, terminated, truncated, info = env.step(follow.action(*env.robot_pose))
        assert env.observation_space.contains(obs)
        origin, rotation = lidar_frame(env._sim, env._lidar_height, centre_height(robot.height, robot.ground_clearance))
        lidar_z.append(origin[2])
        if terminated or truncated:
            break
    assert terminated and info["success"] and info["collisions"] == []
    # Up on the landing the lidar is its height above the landing, within 1 cm; back on the floor, above the floor.
    assert max(lidar_z) == pytest.approx(ramp.rise + env._lidar_height, abs=0.01)
    assert lidar_z[-1] == pytest.approx(env._lidar_height, abs=0.01)


def test_a_flat_world_gets_the_flat_base_unchanged():
    robot = Robot(0.2, 0.4, 0.05)
    flat, base = (etree.fromstring(b"<mujoco><worldbody/></mujoco>") for _ in range(2))
    add_robot(flat, robot.radius, robot.height, (-1.0, 1.0), 2.0)
    assert add_base(base, robot, (-1.0, 1.0), 2.0, False, {"floor"}) == ["floor"]
    assert etree.tostring(base) == etree.tostring(flat)
    terrain = etree.fromstring(b"<mujoco><worldbody><geom name='floor' type='plane' size='1 1 1'/></worldbody></mujoco>")
    assert add_base(terrain, robot, (-1.0, 1.0), 2.0, True, {"floor"}) == ["floor"]
    joints = [j.get("name").rsplit("_", 1)[1] for j in terrain.iter("joint")]
    assert joints == ["x", "y", "z", "yaw", "pitch", "roll"]
    assert terrain.find("worldbody/geom").get("conaffinity") == "3" and math.isclose(
        float(terrain.find("worldbody/body").get("pos").split()[2]), centre_height(0.4, robot.ground_clearance))
    assert np.isclose(centre_height(0.4, 0.03), 0.215)


def test_the_geodesic_reward_goes_round_ground_the_robot_cannot_drive():
    # A 6 cm kerb stands between spawn and goal: the proven path goes round it, and so does the field the
    # default reward shapes with (within the field's documented 2.75 % plus a spacing per corner).
    from support.terrain import KERB_PARAMS, KERB_SEED

    import worldgen
    from worldgen.envs.geodesic import GeodesicField

    world = worldgen.generate("terrain", seed=KERB_SEED, **KERB_PARAMS)
    path = world.feasibility.paths[0]
    (x, y), goal = path.waypoints[0], path.waypoints[-1]
    field = GeodesicField.for_scene(world.scene, world.robot, goal)
    straight = math.dist((x, y), goal)
    assert path.length > straight + 0.1
    assert path.length - 0.002 <= field.distance(x, y) <= 1.0275 * path.length + 2 * 0.05
    assert GeodesicField.for_scene(world.scene.with_terrain(None), world.robot, goal).distance(x, y) == \
        pytest.approx(straight, abs=1e-6)
