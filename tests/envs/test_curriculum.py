"""The level curriculum (worldgen.envs.curriculum): a scripted learner whose skill is a known function of
the level climbs and settles where the thresholds say, is demoted after forced failures, and is sent to
a random level when it passes the top; one short run in the real environment; vector environments."""

from __future__ import annotations

import math

import numpy as np
import pytest
from support.envs import ENV_ID, gymnasium, make

import worldgen
from worldgen.envs.curriculum import LevelCurriculum
from worldgen.envs.policies import PathFollower
from worldgen.errors import ParameterError
from worldgen.seeding import curriculum_rng


def drive(curriculum, succeeds, episodes):
    """Levels played, one per episode, by a learner whose k-th episode at level L succeeds when
    ``succeeds(L, k)`` (k counts that learner's episodes at L)."""
    played, count = [], {}
    for _ in range(episodes):
        level = curriculum.level
        k = count.get(level, 0)
        count[level] = k + 1
        info = curriculum.record(succeeds(level, k))
        assert info["curriculum_level"] == level and info["curriculum_next_level"] == curriculum.level
        assert info["curriculum_level_changed"] == (curriculum.level != level)
        played.append(level)
    return played


def skilled_up_to_five(level, k):
    """Always below 5, never above, every other episode at 5: a success rate of exactly 0.5 there."""
    return level < 5 or (level == 5 and k % 2 == 0)


def test_a_learner_climbs_one_level_a_window_and_settles_where_it_succeeds_half_the_time():
    c = LevelCurriculum(window=20, promote=0.8, demote=0.4)
    played = drive(c, skilled_up_to_five, 1000)
    # Levels 1-4: 20 successes each, promoted at the 20th; at 5 the rate 0.5 lies strictly between 0.4 and 0.8.
    assert played[:80] == [1] * 20 + [2] * 20 + [3] * 20 + [4] * 20
    assert set(played[80:]) == {5} and c.level == 5
    stats = c.stats()
    assert stats["episodes"][:5] == [20, 20, 20, 20, 920] and stats["successes"][4] == 460
    assert stats["success_rates"][:5] == [1.0, 1.0, 1.0, 1.0, 0.5] and all(math.isnan(r) for r in stats["success_rates"][5:])


def test_the_level_falls_one_step_per_window_of_forced_failures_and_stops_at_one():
    c = LevelCurriculum(window=20, promote=0.8, demote=0.4)
    drive(c, skilled_up_to_five, 200)
    assert c.level == 5
    played = drive(c, lambda level, k: False, 100)
    # At 5 the window slid over episodes 100-119 there (the even ones succeeded): 3 failures leave 104-118
    # with 8 successes in the 20 (0.4), demoted;
    # every later level starts a fresh window, so it falls one level per 20 failures, and stays at 1.
    assert played == [5] * 3 + [4] * 20 + [3] * 20 + [2] * 20 + [1] * 37 and c.level == 1


def test_a_sliding_window_demotes_as_soon_as_the_rate_falls_to_the_threshold():
    c = LevelCurriculum(window=10, promote=0.8, demote=0.4, start=3)
    # 5 successes then failures: the window of 10 holds 5/10 = 0.5 after 10, 4/10 after 11 (demoted then).
    played = drive(c, lambda level, k: k < 5, 11)
    assert played == [3] * 11 and c.level == 2


def test_passing_the_top_level_sends_the_environment_to_a_level_from_its_curriculum_stream():
    c = LevelCurriculum(window=5, start=10)
    c.reseed(7)
    expect = curriculum_rng(7)
    jumps, at_top = [], 0
    for _ in range(2000):  # always succeeding: climb, pass the top, land somewhere, climb again
        before = c.level
        c.record(True)
        if before == 10:
            at_top += 1
            if at_top == 5:  # the 5th success in a fresh window at the top: passed
                at_top = 0
                jumps.append(c.level)
                assert c.level == int(expect.integers(1, 11))
    assert len(jumps) > 20 and len(set(jumps)) >= 5


def test_a_learner_with_noisy_skill_settles_at_the_level_the_thresholds_predict():
    """Success probability 0.97 up to level 6, 0.6 at 7, 0.1 from 8: with window 50, promote 0.8 and demote
    0.4 the level settles at 7 (P[rate >= 0.8] and P[rate <= 0.4] at p = 0.6 are both about 0.002)."""
    rng = np.random.default_rng(3)
    p = {level: 0.97 if level <= 6 else 0.6 if level == 7 else 0.1 for level in range(1, 11)}
    c = LevelCurriculum(window=50)
    played = np.array(drive(c, lambda level, k: bool(rng.random() < p[level]), 3000))
    settled = played[400:]
    assert np.mean(settled == 7) >= 0.9 and set(settled) <= {6, 7, 8}


@pytest.mark.parametrize("kwargs, message", [
    ({"window": 0}, "parameter 'window' must be an integer in"),
    ({"promote": 0.4, "demote": 0.5}, "parameter 'demote' must be below promote = 0.4"),
    ({"start": 11}, "parameter 'start' must be an integer in \\[1, 10\\]"),
])
def test_bad_settings_are_one_line_errors(kwargs, message):
    with pytest.raises(ParameterError, match=message):
        LevelCurriculum(**kwargs)


@pytest.mark.parametrize("kwargs, message", [
    ({"generator": "cluttered", "curriculum": "ladder"}, "parameter 'curriculum' must be one of levels, replay"),
    ({"generator": "cluttered", "difficulty": "3/10", "curriculum": "levels"}, "leave out 'difficulty'"),
    ({"generator": "minimal", "curriculum": "levels"},
     "parameter 'curriculum' draws worlds at a level: parameter 'difficulty' is offered by the generators"),
    ({"generator": "door", "curriculum": LevelCurriculum(start=1)},
     "parameter 'curriculum' draws worlds at a level: parameter 'difficulty' 1/10 is out of reach of 'door'"),
    ({"preset": "drl_arena", "curriculum": "levels"}, "draws worlds at a level: .* leave out 'n_obstacles'"),
])
def test_a_bad_curriculum_fails_when_the_env_is_made(kwargs, message):
    with pytest.raises(ParameterError, match=message):
        gymnasium.make(ENV_ID, **kwargs)


def follow(env, **reset):
    obs, first = env.reset(**reset)
    policy = PathFollower.for_env(env)
    while True:
        obs, _, terminated, truncated, info = env.step(policy.action(*env.robot_pose))
        if terminated or truncated:
            return first, info


def test_in_the_environment_info_reports_the_level_and_the_follower_climbs():
    env = make(generator="cluttered", curriculum=LevelCurriculum(window=2, promote=1.0, demote=0.0), lidar_beams=16)
    levels = []
    for episode in range(5):
        first, last = follow(env, seed=11) if episode == 0 else follow(env)
        world = worldgen.generate("cluttered", first["world_seed"], difficulty=first["curriculum_level"])
        assert first["world_id"] == world.world_id  # the world is the generator's at that level
        assert world.metadata["metrics"]["difficulty_level"] == first["curriculum_level"]
        assert last["success"] and last["curriculum_level"] == first["curriculum_level"]
        levels.append((first["curriculum_level"], first["curriculum_level_changed"], last["curriculum_next_level"],
                       last["curriculum_level_changed"]))
    # Two successes per level: promoted after the 2nd and the 4th episode; the next reset says so once.
    assert levels == [(1, False, 1, False), (1, False, 2, True), (2, True, 2, False), (2, False, 3, True),
                      (3, True, 3, False)]
    assert env.curriculum_stats()["episodes"][:3] == [2, 2, 1]


def test_an_episode_the_caller_picked_does_not_count():
    env = make(generator="cluttered", curriculum="levels", lidar_beams=16)
    first, last = follow(env, seed=0, options={"world_seed": 5})
    assert "curriculum_level" not in first and "curriculum_level" not in last
    assert sum(env.curriculum_stats()["episodes"]) == 0


def idle(envs, steps):
    """Infos of the episodes that end while every robot stands still for ``steps`` steps."""
    ended = []
    for _ in range(steps):
        _, _, terminated, truncated, info = envs.step(np.zeros((envs.num_envs, 2), dtype=np.float32))
        for i in np.flatnonzero(terminated | truncated):
            ended.append((int(i), int(info["curriculum_level"][i]), bool(info["curriculum_level_changed"][i])))
    return ended


@pytest.mark.parametrize("vector", ["sync", "async"])
def test_vector_environments_keep_one_curriculum_each(vector):
    def one():
        return gymnasium.make(ENV_ID, generator="cluttered", curriculum=LevelCurriculum(window=1, promote=0.9, demote=0.5),
                              lidar_beams=16, time_limit_factor=0.1, reward="walkthrough")

    cls = gymnasium.vector.SyncVectorEnv if vector == "sync" else gymnasium.vector.AsyncVectorEnv
    runs = []
    for _ in range(2):
        envs = cls([one, one])
        try:
            _, info = envs.reset(seed=[4, 5])
            assert list(info["curriculum_level"]) == [1, 1]
            ended = idle(envs, 60)
            stats = envs.call("curriculum_stats")
        finally:
            envs.close()
        # Standing still never reaches the goal: each env fails its level-1 episode and stays at 1.
        assert ended and all(level == 1 and not changed for _, level, changed in ended)
        assert [sum(s["episodes"]) for s in stats] == [sum(e[0] == i for e in ended) for i in (0, 1)]
        runs.append(ended)
    assert runs[0] == runs[1]


@pytest.mark.parametrize("curriculum", ["levels", "replay"])
def test_an_environment_with_a_curriculum_passes_gymnasium_s_checker(curriculum):
    from gymnasium.utils.env_checker import check_env

    check_env(gymnasium.make(ENV_ID, curriculum=curriculum, generator="cluttered", lidar_beams=16).unwrapped, skip_render_check=True)


def test_a_generator_without_level_1_starts_at_its_lowest_and_is_never_sent_below_or_outside_it():
    """door reaches levels 2-10 (worldgen.leveling.reachable): the curriculum starts at 2, demotes no lower,
    and a pass of the top sends it among 2..10 only."""
    env = gymnasium.make(ENV_ID, generator="door", curriculum="levels")
    try:
        _, info = env.reset(seed=3)
        assert info["curriculum_level"] == 2
        curriculum = env.unwrapped.curriculum
        assert curriculum.ladder == tuple(range(2, 11))
    finally:
        env.close()
    for _ in range(3 * curriculum.window):
        curriculum.record(False)
    assert curriculum.level == 2
    curriculum.level, landed = 10, set()
    for _ in range(60):
        for _ in range(curriculum.window):
            curriculum.record(True)
        landed.add(curriculum.level)
        curriculum.level = 10
    assert 1 not in landed and len(landed) >= 5
