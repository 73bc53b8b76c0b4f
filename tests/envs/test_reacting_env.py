"""Reacting people in the environment: the robot's pose feeds them every step, the timed path's follower
(at the environment's defaults) touches none of them whatever they do and reaches the goal in every
preset with people, each stays inside its tube, and the same seed gives the same run."""

from __future__ import annotations

import numpy as np
import pytest
from support.envs import ENV_ID, gymnasium

from worldgen.envs.policies import drive_timed
from worldgen.people.behaviours import BEHAVIOURS, tube_distance

#: Every preset whose world has people.
PEOPLE_PRESETS = ["person_head_on", "person_crossing", "person_in_doorway", "person_overtaking", "group_in_corridor",
                  "crowd_reacting"]


def _env(**params):
    """The environment at its defaults (turn rate, speeds, time limit) in a cluttered world of ``params``."""
    return gymnasium.make(ENV_ID, generator="cluttered", params=params)


def _outside(info: dict, env) -> float:
    """The largest amount (m) by which a reacting person's recorded step lies outside its tube."""
    worst = -np.inf
    people = {p["name"]: p for p in env.unwrapped.world.movers if p.get("behaviour")}
    for name, rows in env.unwrapped.episode.walkers.reacted.items():
        p = people[name]
        dist = tube_distance(rows[:, 1:], rows[:, 0], np.asarray(p["trajectory"], dtype=float), p["tube"]["tau"])
        worst = max(worst, float((dist - p["tube"]["d"]).max()))
    return worst


@pytest.mark.parametrize("behaviour", ["regular", "surprised", "scared", "curious", ",".join(BEHAVIOURS)])
def test_the_timed_follower_touches_no_reacting_person(behaviour):
    env = _env(size=[8.0, 8.0], n_obstacles=4, n_people=5, people_duration=12.0, people_behaviour=behaviour)
    clips = 0
    for seed in range(5):
        info = drive_timed(env, seed=seed)
        assert info["collisions"] == [] and info["success"], (seed, info["collisions"])
        assert _outside(info, env) <= 1e-9
        assert set(info["people_clips"]) == {m["name"] for m in env.unwrapped.world.movers if m.get("behaviour")}
        clips += sum(info["people_clips"].values())
        split = info["social"]["by_behaviour"]
        assert split["all"]["robot_on_person"] == split["all"]["person_on_robot"] == 0
        assert all(v["min_tube_gap"] is None or v["min_tube_gap"] > 0 for v in split.values())
    assert clips >= 0


def test_people_react_to_the_robot_in_a_preset():
    """person_crossing made regular: the person crossing the robot's line reacts to it, and is not touched."""
    env = gymnasium.make(ENV_ID, preset="person_crossing", params={"people_behaviour": "regular"})
    info = drive_timed(env, seed=0)
    assert info["success"] and info["collisions"] == []
    walked = env.unwrapped.episode.walkers.reacted["person_0"]
    recorded = np.asarray(env.unwrapped.world.movers[0]["trajectory"], dtype=float)
    here = np.c_[np.interp(walked[:, 0], recorded[:, 0], recorded[:, 1]), np.interp(walked[:, 0], recorded[:, 0], recorded[:, 2])]
    assert np.hypot(*(walked[:, 1:] - here).T).max() > 0.05  # it reacted, not replayed its recording


@pytest.mark.parametrize("preset", PEOPLE_PRESETS)
def test_the_timed_follower_at_the_envs_defaults_reaches_the_goal_in_every_people_preset(preset):
    """The time limit covers the certified arrival, and the follower keeps within the tracking margin."""
    from worldgen.envs.policies import TimedFollower
    from worldgen.people.timed import TRACKING

    env = gymnasium.make(ENV_ID, preset=preset)
    _, start = env.reset(seed=0)
    # The default limit: twice the longer of L / v_max and the certified arrival (both at the world's robot's
    # 0.5 m/s), plus a half turn at its 1 rad/s: never shorter than the schedule.
    arrival = env.unwrapped.task["arrival_time"]
    assert start["time_limit"] == pytest.approx(2.0 * max(start["reference_path_length"] / 0.5, arrival) + np.pi / 1.0)
    info = drive_timed(env, seed=0)
    assert info["success"] and info["collisions"] == [], (info["time_to_goal"], info["collisions"])
    u = env.unwrapped
    follower, rows = TimedFollower.for_env(env), np.asarray(u.episode.rows)
    lag = max(float(np.hypot(*(follower.at(t) - rows[k, 1:3]))) for k, t in enumerate(rows[:, 0]))
    assert lag <= TRACKING, lag


def test_the_same_seed_gives_the_same_reactions_and_vector_envs_react_too():
    params = dict(size=[8.0, 8.0], n_obstacles=4, n_people=4, people_duration=10.0, people_behaviour="regular,curious")
    runs = []
    for _ in range(2):
        env = _env(**params)
        drive_timed(env, seed=3)
        runs.append({k: v.tolist() for k, v in env.unwrapped.episode.walkers.reacted.items()})
    assert runs[0] == runs[1]
    envs = gymnasium.vector.SyncVectorEnv([lambda: _env(**params) for _ in range(2)])
    envs.reset(seed=[3, 4])
    for _ in range(20):
        envs.step(np.tile(np.array([0.3, 0.0], dtype=np.float32), (2, 1)))
    walked = envs.get_attr("episode")
    assert all(len(next(iter(e.walkers.reacted.values()))) > 1 for e in walked)


def test_the_timed_follower_passes_movers_on_their_certificate():
    """Movers are agents of the certificate (docs/people.md): among three looping movers, with people too,
    the follower at the environment's defaults reaches the goal without contact, within the tracking margin."""
    from worldgen.envs.policies import TimedFollower
    from worldgen.people.timed import TRACKING

    for params in ({"n_movers": 3}, {"n_movers": 2, "n_people": 3, "people_duration": 10.0}):
        env = _env(size=[8.0, 8.0], n_obstacles=4, **params)
        for seed in range(2):
            info = drive_timed(env, seed=seed)
            assert info["success"] and info["collisions"] == [], (params, seed, info["collisions"])
            u = env.unwrapped
            assert u.task["timed_path"] is not None
            follower, rows = TimedFollower.for_env(env), np.asarray(u.episode.rows)
            lag = max(float(np.hypot(*(follower.at(t) - rows[k, 1:3]))) for k, t in enumerate(rows[:, 0]))
            assert lag <= TRACKING, (params, seed, lag)
