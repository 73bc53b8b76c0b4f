"""Door worlds in the navigation environment: a leaf is pushed open, not collided with; a pull door opens itself.

world.json plans every reference path through doorways with the leaves at their
open limit; the environment lets the robot push a leaf (a hinged MuJoCo body)
and reports those contacts as ``door_contacts`` (one per push: DOOR_DEBOUNCE),
apart from ``collisions``; a door the robot comes to from the side its leaf
swings into is an automatic door (``doors="auto"``, worldgen.envs.doors); the
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


# A 1 m/s robot (the environment's robot is the world's): these episodes are about doors, and at the default
# 0.5 m/s they would take twice the steps.
PARAMS = {"n_doors": 2, "size": [12, 4], "hinge_side": "random", "swing": "push", "robot_speed": 1.0}


@pytest.mark.parametrize("state", ["closed", "ajar", "open"])
def test_the_path_follower_pushes_through_door_worlds_in_every_door_state(state):
    env = gymnasium.make(ENV_ID, generator="door", params=dict(PARAMS, state=state), doors="push").unwrapped
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


SEEDS = 12  # per (swing, state): 3 x 3 x 12 = 108 episodes


@pytest.mark.parametrize("swing", ["push", "pull", "random"])
def test_the_path_follower_passes_push_and_pull_doors_closed_ajar_and_open(swing):
    """By default (doors="auto") a pull door opens by itself as the robot comes near, a push door is pushed."""
    for state in ("closed", "ajar", "open"):
        env = gymnasium.make(ENV_ID, generator="door", params=dict(PARAMS, swing=swing, state=state)).unwrapped
        for seed in range(SEEDS):
            info, _ = follow(env, seed)
            assert info["success"] and info["collisions"] == [] and info["spl"] > 0.9, (swing, state, seed)
            if swing == "pull":  # the robot always comes from the swing side: both doors open themselves
                assert [d["entity"] for d in info["doors_opened"]] == ["door_0", "door_1"], (state, seed)
            if swing == "push":  # always from the push side: nothing opens itself
                assert info["doors_opened"] == []
                assert (info["door_contacts"] == []) == (state == "open"), (state, seed)


def test_a_pull_door_stays_shut_when_doors_are_only_pushed():
    """doors="push": a base without an arm cannot pull a leaf towards itself: the follower stalls."""
    env = gymnasium.make(ENV_ID, generator="door", params=dict(PARAMS, swing="pull", state="closed"),
                         doors="push").unwrapped
    info, traj = follow(env, 0)
    assert not info["success"] and info["collisions"] == [] and info["doors_opened"] == []
    assert traj[-1, 1] < -2.0  # stopped before the first dividing wall (x = -2)


def test_every_door_opens_itself_in_automatic_mode():
    env = gymnasium.make(ENV_ID, generator="door", params=dict(PARAMS, swing="push", state="closed"),
                         doors="automatic").unwrapped
    info, _ = follow(env, 0)
    assert info["success"] and [d["entity"] for d in info["doors_opened"]] == ["door_0", "door_1"]


# One closed push door across a straight drive: spawn (-2, 0) facing +x, the leaf's near face at x = 0.01.
STRAIGHT = {"size": [8, 4], "door_x": 0.0, "door_y": 0.0, "hinge_side": "left", "swing": "push", "state": "closed",
            "spawn": [-2.0, 0.0, 0.0], "goal": [3.0, 0.0]}


def drive(env, plan):
    """Run ``plan`` ((v, steps), ...) straight ahead; (end info, reset info, per-step door_contact flags)."""
    _, first = env.reset(seed=0)
    flags = []
    for v, n in plan:
        for _ in range(n):
            _, _, terminated, truncated, info = env.step([v, 0.0])
            flags.append(info["door_contact"])
            if terminated or truncated:
                return info, first, flags
    raise AssertionError("the plan ended before the episode")


def test_one_push_through_a_door_is_one_door_contact_however_often_mujoco_makes_and_breaks_it(monkeypatch):
    from worldgen.envs import episode

    begins = []  # every contact with the leaf MuJoCo begins (the flicker DOOR_DEBOUNCE merges)
    touch = episode.Episode.touch
    monkeypatch.setattr(episode.Episode, "touch", lambda self, t, now: begins.extend(now - self.touching) or
                        touch(self, t, now))
    env = gymnasium.make(ENV_ID, generator="door", params=STRAIGHT).unwrapped
    info, _, flags = drive(env, [(0.5, 200)])
    assert info["success"] and info["collisions"] == []
    assert len(info["door_contacts"]) == 1 and info["door_contacts"][0]["entity"] == "door_0"
    # It begins where the 0.2 m disc, at 0.5 m/s behind its 0.01 s servo lag, meets the leaf's face at x = 0.01.
    radius = env.world.robot.radius
    assert info["door_contacts"][0]["time"] == pytest.approx((0.01 - radius + 2.0) / 0.5 + 0.01, abs=0.01)
    assert begins.count("door_0") > 10  # what the count was before (34 on this drive)
    touched = [k for k, f in enumerate(flags) if f]
    assert touched and touched == list(range(touched[0], touched[-1] + 1))  # one run of steps touching it


def test_a_second_push_after_the_debounce_is_a_second_door_contact_in_the_env_and_the_oracles():
    from worldgen.testing import oracles

    env = gymnasium.make(ENV_ID, generator="door", params=STRAIGHT, linear_velocity=[-1.0, 1.0]).unwrapped
    # Push the leaf, back off 0.5 m, wait 1 s, drive on: the leaf swung away, the robot's flank meets it
    # again 4.2 s after the first push ended (3.90 s to 8.10 s; > DOOR_DEBOUNCE).
    info, first, _ = drive(env, [(0.5, 39), (-0.5, 10), (0.0, 10), (0.5, 200)])
    assert info["success"] and info["collisions"] == []
    assert [c["entity"] for c in info["door_contacts"]] == ["door_0", "door_0"]
    gap = info["door_contacts"][1]["time"] - info["door_contacts"][0]["time"]
    assert gap > oracles.DOOR_DEBOUNCE
    # The oracles, holding the leaf closed, see the robot leave it (x < -0.19) and come back 2.6 s later.
    world = worldgen.generate("door", first["world_seed"], **STRAIGHT)
    assert [c.entity for c in oracles.door_contacts(env.episode.trajectory, world)] == ["door_0", "door_0"]


def test_pull_doors_open_themselves_in_a_pack_world_from_its_world_json(tmp_path):
    """A pack's world is read from world.json and world.mjcf.xml: doors[] (joint, limits, passage) is enough."""
    from worldgen.envs.policies import PathFollower
    from worldgen.pack import build_pack, parse_recipe

    recipe = parse_recipe("name: pull\nseeds: 2\nworlds:\n  - generator: door\n    params: {n_doors: 2, size: [12, 4], "
                          "swing: pull, hinge_side: random}\n")
    build_pack(recipe, tmp_path / "pull")
    env = gymnasium.make(ENV_ID, pack=str(tmp_path / "pull")).unwrapped
    for index in range(2):
        _, first = env.reset(options={"world_index": index})
        f = PathFollower.for_env(env)
        while True:
            _, _, terminated, truncated, info = env.step(f.action(*env.robot_pose))
            if terminated or truncated:
                break
        assert info["success"] and [d["entity"] for d in info["doors_opened"]] == ["door_0", "door_1"], index
