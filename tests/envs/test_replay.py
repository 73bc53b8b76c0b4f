"""The adaptive sampler (worldgen.envs.replay): PLR's replay distribution against hand-computed values,
the learnability score, the buffer's admission, every buffered level proven, and the sampler in the
environment: the learner's score, determinism under a seed, sync and async vector environments."""

from __future__ import annotations

import math
from fractions import Fraction

import numpy as np
import pytest
from support.checks import recheck
from support.envs import ENV_ID, gymnasium, make

import worldgen
from worldgen.envs.replay import LevelRecord, LevelReplay, learnability
from worldgen.errors import ParameterError
from worldgen.feasibility.report import CHECKER


def record(score, last_played):
    return LevelRecord(world=None, score=score, last_played=last_played)


def test_the_replay_distribution_is_plr_s_mix_of_rank_and_staleness():
    s = LevelReplay(temperature=0.5, staleness=0.25)
    s.buffer = [record(0.1, 2), record(0.3, 5), record(0.2, 9)]
    s.clock = 10
    # Ranks 3, 1, 2 -> (1/r)^(1/0.5) = 1/9, 1, 1/4, normalised by 49/36; staleness 8, 5, 1 of 14.
    p_score = [Fraction(4, 49), Fraction(36, 49), Fraction(9, 49)]
    p_stale = [Fraction(8, 14), Fraction(5, 14), Fraction(1, 14)]
    expect = [Fraction(3, 4) * a + Fraction(1, 4) * b for a, b in zip(p_score, p_stale)]
    assert np.allclose(s.probabilities(), [float(e) for e in expect], rtol=0, atol=1e-15)
    assert math.isclose(float(sum(expect)), 1.0)


def test_ties_rank_in_buffer_order_and_a_fresh_buffer_is_uniformly_stale():
    s = LevelReplay(temperature=1.0, staleness=0.5)
    s.buffer = [record(0.2, 0), record(0.2, 0)]
    s.clock = 0  # nothing played yet: every staleness 0, P_C uniform
    assert np.allclose(s.probabilities(), [0.5 * 2 / 3 + 0.25, 0.5 * 1 / 3 + 0.25])


def test_replay_draws_follow_the_distribution():
    """10,000 draws from the sampler's stream against the probabilities (chi-square, scipy)."""
    from scipy.stats import chisquare

    s = LevelReplay(replay_prob=1.0, temperature=0.5, staleness=0.25)
    s.buffer = [record(0.1, 2), record(0.3, 5), record(0.2, 9)]
    s.clock = 10
    s.reseed(1)
    p = s.probabilities()
    counts = np.bincount([s.buffer.index(s.choose(None, None)) for _ in range(10000)], minlength=3)
    assert chisquare(counts, 10000 * p).pvalue > 1e-3


def test_learnability_is_p_times_one_minus_p_with_one_success_and_one_failure_added():
    assert learnability(0, 0) == 0.25
    assert math.isclose(learnability(1, 1), (2 / 3) * (1 / 3))
    assert math.isclose(learnability(0, 4), (1 / 6) * (5 / 6))
    assert learnability(3, 4) == learnability(1, 4)  # symmetric: as hard to learn from as to fail


def test_a_full_buffer_takes_a_level_only_in_place_of_a_lower_scored_one():
    s = LevelReplay(buffer_size=2)
    a, b, c, d = record(0.2, 0), record(0.1, 0), record(0.05, 0), record(0.15, 0)
    assert s.admit(a) and s.admit(b)
    assert not s.admit(c) and s.buffer == [a, b]
    assert s.admit(d) and s.buffer == [a, d]
    assert s.admit(a) and s.buffer == [a, d]  # already there


@pytest.mark.parametrize("kwargs, message", [
    ({"replay_prob": 1.5}, "parameter 'replay_prob' must be a number in \\[0, 1\\]"),
    ({"temperature": 0}, "parameter 'temperature' must be a number in \\(0, 100\\]"),
    ({"edits": ("teleport",)}, "parameter 'edits' must name some of move, resize, add, remove, move_goal"),
    ({"buffer_size": 0}, "parameter 'buffer_size' must be an integer in"),
])
def test_bad_settings_are_one_line_errors(kwargs, message):
    with pytest.raises(ParameterError, match=message):
        LevelReplay(**kwargs)


def test_a_curriculum_needs_a_generator():
    from worldgen.envs.replay import check_generator_source

    with pytest.raises(ParameterError, match="needs worlds from a generator or preset, not a pack"):
        check_generator_source(object(), "replay")


def episodes(env, n, seed, score=None):
    """(reset info, end info) of ``n`` short episodes standing still, reporting ``score(k)`` after each."""
    out = []
    for k in range(n):
        _, first = env.reset(seed=seed) if k == 0 else env.reset()
        while True:
            _, _, terminated, truncated, info = env.step(np.zeros(2, dtype=np.float32))
            if terminated or truncated:
                break
        if score is not None:
            env.report_score(score(k))
        out.append((first, info))
    return out


SETTINGS = dict(generator="cluttered", lidar_beams=16, time_limit_factor=0.1, reward="walkthrough")


def test_the_sampler_replays_and_edits_and_every_buffered_level_is_proven():
    env = make(curriculum=LevelReplay(buffer_size=6, replay_prob=0.4, edit_prob=0.7), **SETTINGS)
    runs = episodes(env, 30, seed=2, score=lambda k: float(k % 7))
    kinds = [first["level_kind"] for first, _ in runs]
    assert {"new", "replay", "edit"} <= set(kinds)
    sampler = env.curriculum
    assert len(sampler.buffer) == 6 and any(r.edits for r in sampler.buffer)
    for r in sampler.buffer:
        assert r.certificate.feasible and r.certificate.checker == CHECKER and r.path is not None
        recheck(r.world)  # independent: the footprint kept clear along the whole reference path
        assert r.rebuild().content_hash == r.world.content_hash  # (generator, params, seed, edits) rebuild it
    # The learner's score replaced learnability: each buffered level holds the last score reported for it.
    last = {first["world_id"]: float(k % 7) for k, (first, _) in enumerate(runs)}
    assert all(r.reported and r.score == last[r.world.world_id] for r in sampler.buffer)
    stats = env.curriculum_stats()
    assert stats["episodes"] == 30 and sum(stats["kinds"].values()) == 30


def test_without_a_reported_score_levels_are_scored_by_learnability():
    env = make(curriculum="replay", **SETTINGS)
    (first, last), = episodes(env, 1, seed=0)
    assert first["level_kind"] == "new" and math.isnan(first["level_score"])
    assert not last["success"] and last["level_score"] == learnability(0, 1)
    _, again = env.reset()
    assert again["buffer_size"] == 1 and env.curriculum.buffer[0].score == learnability(0, 1)


def test_the_same_seed_gives_the_same_levels_in_two_environments():
    def levels():
        env = make(curriculum=LevelReplay(replay_prob=0.3, edit_prob=0.6), **SETTINGS)
        return [(f["world_id"], f["level_kind"], end["level_score"]) for f, end in episodes(env, 12, 9, lambda k: k % 3)]

    first, second = levels(), levels()
    assert first == second and len({w for w, _, _ in first}) > 3


def test_report_score_without_a_curriculum_is_a_one_line_error():
    env = make(**SETTINGS)
    with pytest.raises(ParameterError, match="report_score needs an environment made with curriculum='replay'"):
        env.report_score(1.0)
    with pytest.raises(ParameterError, match="parameter 'score' must be a finite number"):
        make(curriculum="replay", **SETTINGS).curriculum.report_score(math.nan)


@pytest.mark.parametrize("vector", ["sync", "async"])
def test_vector_environments_report_scores_per_environment(vector):
    def one():
        return gymnasium.make(ENV_ID, curriculum=LevelReplay(replay_prob=0.5, edit_prob=0.5), **SETTINGS)

    cls = gymnasium.vector.SyncVectorEnv if vector == "sync" else gymnasium.vector.AsyncVectorEnv
    envs = cls([one, one])
    try:
        envs.reset(seed=[1, 2])
        kinds = []
        for _ in range(150):
            _, _, terminated, truncated, info = envs.step(np.zeros((2, 2), dtype=np.float32))
            ended = terminated | truncated
            if ended.any():
                envs.set_attr("level_score", [3.0, 4.0])  # per environment
                kinds += [str(info["level_kind"][i]) for i in np.flatnonzero(ended)]
        stats = envs.call("curriculum_stats")
    finally:
        envs.close()
    assert kinds and [s["episodes"] for s in stats] and all(s["buffer_size"] >= 1 for s in stats)
    assert {3.0} <= set(stats[0]["scores"]) and {4.0} <= set(stats[1]["scores"])


def test_a_world_from_the_sampler_is_the_generator_s_world_when_new():
    env = make(curriculum="replay", **SETTINGS)
    _, info = env.reset(seed=3)
    assert info["level_kind"] == "new"
    assert info["world_id"] == worldgen.generate("cluttered", info["world_seed"]).world_id


def test_sync_and_async_vector_environments_play_the_same_levels():
    """The async workers are other processes: the same seeds and scores give the same levels there."""
    def one():
        return gymnasium.make(ENV_ID, curriculum=LevelReplay(replay_prob=0.4, edit_prob=0.6), **SETTINGS)

    def levels(cls):
        envs = cls([one, one])
        try:
            _, info = envs.reset(seed=[7, 8])
            seen = [(i, str(info["world_id"][i]), str(info["level_kind"][i])) for i in (0, 1)]
            for step in range(200):
                _, _, terminated, truncated, info = envs.step(np.zeros((2, 2), dtype=np.float32))
                if (terminated | truncated).any():
                    envs.set_attr("level_score", [float(step % 5), float(step % 3)])
                if "_world_id" in info:
                    seen += [(int(i), str(info["world_id"][i]), str(info["level_kind"][i]))
                             for i in np.flatnonzero(info["_world_id"])]
        finally:
            envs.close()
        return seen

    sync, asynchronous = levels(gymnasium.vector.SyncVectorEnv), levels(gymnasium.vector.AsyncVectorEnv)
    assert len(sync) > 6 and sync == asynchronous
    assert {kind for _, _, kind in sync} == {"new", "replay", "edit"}, sync
