"""People in the environment: driven along their world.json tracks, seen by the lidar, and a contact
with one is a collision that ends the episode (the person_head_on preset: one person walking straight
at the robot along its path)."""

from __future__ import annotations

import math

import numpy as np
from support.envs import ENV_ID, gymnasium

from worldgen.scene.motion import positions_at


def _head_on():
    env = gymnasium.make(ENV_ID, preset="person_head_on").unwrapped
    obs, _ = env.reset(seed=0)
    return env, obs


def test_the_lidar_sees_a_person_where_world_json_has_them():
    env, obs = _head_on()
    (person,) = env.world.movers
    assert person["name"] == "person_0"
    x, y, yaw = env.robot_pose
    px, py = positions_at([np.asarray(person["trajectory"])], [False], np.array([0.0]))[0, 0]
    bearing = math.atan2(py - y, px - x) - yaw
    beam = int(np.argmin(np.abs(np.asarray(env.lidar.angles) - bearing)))
    ranges = obs[: env.lidar.size]  # the preset's lidar: 360 beams, no noise, no sectors
    assert abs(env.lidar.angles[beam] - bearing) < 1e-9  # the person stands straight down one beam
    assert ranges[beam] == np.float32(math.hypot(px - x, py - y) - person["radius"])


def test_driving_into_a_person_is_a_collision_with_them():
    env, _ = _head_on()
    v_max = env.action_space.high[0]
    for _ in range(2000):
        _, reward, terminated, truncated, info = env.step(np.array([v_max, 0.0], dtype=np.float32))
        if terminated or truncated:
            break
    assert terminated and not info["success"] and reward < -99
    assert [c["entity"] for c in info["collisions"]] == ["person_0"]
