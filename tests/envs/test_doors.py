"""Door worlds in the navigation environment: a leaf is pushed open, not collided with.

world.json plans every reference path through doorways with the leaves at their
open limit; the environment lets the robot push a leaf (a hinged MuJoCo body)
and reports those contacts as ``door_contacts``, apart from ``collisions``; the
oracles judge the recorded run the same way.
"""

from __future__ import annotations

import pytest
from support.envs import ENV_ID, gymnasium

import worldgen


def follow(env, seed):
    from worldgen.envs.policies import PathFollower

    _, first = env.reset(seed=seed)
    f = PathFollower.for_env(env)
    while True:
        _, _, terminated, truncated, info = env.step(f.action(*env.robot_pose))
        if terminated or truncated:
            return first | info, env.episode.trajectory


PARAMS = {"n_doors": 2, "size": [12, 4], "hinge_side": "random", "swing": "push"}


@pytest.mark.parametrize("state", ["closed", "ajar", "open"])
def test_the_path_follower_passes_door_worlds_in_every_door_state(state):
    env = gymnasium.make(ENV_ID, generator="door", params=dict(PARAMS, state=state)).unwrapped
    for seed in range(4):
        info, _ = follow(env, seed)
        assert info["success"] and info["collisions"] == [], (state, seed, info["collisions"])
        assert info["spl"] > 0.9
        if state == "open":
            assert info["door_contacts"] == []
        else:
            assert info["door_contacts"], (state, seed)  # it did push a leaf: the contacts are reported
            assert {c["entity"] for c in info["door_contacts"]} <= {"door_0", "door_1"}


def test_the_oracles_judge_a_pushed_leaf_as_a_door_contact_not_a_collision():
    from worldgen.testing import oracles

    env = gymnasium.make(ENV_ID, generator="door", params=dict(PARAMS, state="closed")).unwrapped
    info, traj = follow(env, 1)
    world = worldgen.generate("door", info["world_seed"], **dict(PARAMS, state="closed"))
    run = oracles.run(traj, world)
    assert run.reached_goal and run.collisions == ()
    # The oracles hold each leaf where it starts (closed), so they see the robot pass through both leaves.
    assert {c.entity for c in run.door_contacts} == {"door_0", "door_1"}
    assert oracles.collisions(traj, world) == [] and list(run.door_contacts) == oracles.door_contacts(traj, world)
    assert run.as_dict()["door_contacts"][0] == {"time": run.door_contacts[0].time, "entity": run.door_contacts[0].entity}
    # A wall is still a collision: the run shifted 1.5 m sideways runs along the outer wall.
    shifted = traj.copy()
    shifted[:, 2] += 1.6
    assert any(c.entity.startswith("wall") for c in oracles.collisions(shifted, world))


def test_a_wall_of_a_door_world_still_ends_the_episode():
    env = gymnasium.make(ENV_ID, generator="door", params=dict(PARAMS, state="closed")).unwrapped
    env.reset(seed=0)
    for _ in range(400):  # turn to face -x (the outer wall behind the spawn), then drive into it
        x, y, yaw = env.robot_pose
        _, reward, terminated, truncated, info = env.step([0.0 if abs(yaw) < 3.0 else 1.0, 1.0 if abs(yaw) < 3.0 else 0.0])
        if terminated or truncated:
            break
    assert terminated and not info["success"] and reward < -99  # the collision's -100, plus that step's shaping
    assert info["collisions"][0]["entity"].startswith("wall") and info["door_contacts"] == []
