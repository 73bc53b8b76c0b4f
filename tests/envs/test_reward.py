"""worldgen.envs' rewards and observation bounds: potential-based shaping by the geodesic distance (the default),
the walkthrough's reward kept byte for byte, finite bounds every standard wrapper accepts, the time limit.

The geodesic field's reference is the feasibility proof's exact shortest path (world.json ``path.length``)
and the configuration space's own exact segment test.
"""

from __future__ import annotations

import hashlib
import math

import numpy as np
import pytest
from support.envs import ENV_ID, gymnasium, make

#: A sweep of worlds: the default arena, an L and a U corridor (the goal out of sight), a denser room.
SWEEP = [("drl_arena", None, None, s) for s in range(4)] + [
    (None, "corridor", {"shape": "L", "n_obstacles": 3}, 0), (None, "corridor", {"shape": "U", "n_obstacles": 2}, 1),
    (None, "cluttered", {"n_obstacles": 25}, 3)]


def sweep_env(preset, generator, params, **kwargs):
    if preset is not None:
        return make(preset=preset, **kwargs)
    return make(generator=generator, params=params, **kwargs)


def run(env, policy, steps: int) -> tuple[float, list[float]]:
    """Sum of rewards over at most ``steps`` steps (fewer if the episode ends) and the rewards."""
    rewards = []
    for _ in range(steps):
        _, r, terminated, truncated, _ = env.step(policy(env))
        rewards.append(r)
        if terminated or truncated:
            break
    return float(sum(rewards)), rewards


def away(env):
    """Head for the neighbouring point the geodesic field puts farthest from the goal, turning on the spot first."""
    x, y, yaw = env.robot_pose
    angles = np.linspace(-math.pi, math.pi, 32, endpoint=False)
    g = [env.geodesic.distance(x + 0.3 * math.cos(a), y + 0.3 * math.sin(a)) for a in angles]
    err = (angles[int(np.argmax(g))] - yaw + math.pi) % (2 * math.pi) - math.pi
    return [0.0 if abs(err) > 0.3 else 1.0, float(np.clip(3 * err, -1.0, 1.0))]


# -- the default reward -----------------------------------------------------------------------------------

@pytest.mark.parametrize("preset, generator, params, seed", SWEEP)
def test_driving_away_earns_less_than_standing_still_and_both_less_than_the_reference_path(preset, generator, params, seed):
    from worldgen.envs.policies import PathFollower

    for gamma in (1.0, 0.99):  # the default, and the learner's discount
        sums = {}
        for name in ("along", "still", "away"):
            env = sweep_env(preset, generator, params, lidar_beams=36, reward_discount=gamma)
            env.reset(seed=seed)
            f = PathFollower.for_env(env)
            policy = {"along": lambda e: f.action(*e.robot_pose), "still": lambda e: [0.0, 0.0], "away": away}[name]
            sums[name], rewards = run(env, policy, 60)
            if name == "still":
                # Standing still: (1 - gamma) k G - c every step, G the geodesic distance where it stands.
                G = env.geodesic.distance(*env.robot_pose[:2])
                assert rewards == pytest.approx([(1 - gamma) * 10.0 * G - 0.05] * len(rewards), abs=1e-6)
        assert sums["away"] < sums["still"] < sums["along"], (gamma, sums)


def test_the_shaping_telescopes_over_an_episode():
    """sum_t gamma^t (gamma phi(s_t+1) - phi(s_t)) = gamma^T phi(s_T) - phi(s_0), phi = -k G from the field."""
    from worldgen.envs.reward import geodesic_reward, shaping, terminal_reward

    for seed, steps in ((0, 400), (5, 400)):
        outcomes = []
        env = make(preset="drl_arena", lidar_beams=36, reward_fn=lambda o: outcomes.append(o) or 0.0,
                   reward_discount=0.97, reward_progress=7.0)
        env.reset(seed=seed)
        start = env.geodesic.distance(*env.robot_pose[:2])
        rng = np.random.default_rng(seed)
        for _ in range(steps):  # a wandering run: mostly ahead, turning at random, until it ends
            _, _, terminated, truncated, _ = env.step([rng.uniform(0.2, 1.0), rng.uniform(-1.0, 1.0)])
            if terminated or truncated:
                break
        end = env.geodesic.distance(*env.robot_pose[:2])
        cfg = env.config
        T = len(outcomes)
        total = sum(0.97 ** t * shaping(o, cfg) for t, o in enumerate(outcomes))
        assert total == pytest.approx(0.97 ** T * (-7.0 * end) - (-7.0 * start), abs=1e-9)
        for o in outcomes:  # the reward is the terminal reward + the shaping - the time penalty
            assert geodesic_reward(o, cfg) == pytest.approx(terminal_reward(o, cfg) + shaping(o, cfg) - 0.05, abs=1e-12)


def test_euclidean_progress_pays_for_the_decrease_of_the_straight_line_distance():
    env = make(preset="drl_arena", lidar_beams=36, reward="euclidean_progress")
    env.reset(seed=2)
    gx, gy = env.task["goal"][:2]
    before = math.hypot(gx - env.robot_pose[0], gy - env.robot_pose[1])
    _, r, *_ = env.step([0.8, 0.3])
    after = math.hypot(gx - env.robot_pose[0], gy - env.robot_pose[1])
    assert r == pytest.approx(10.0 * (before - after) - 0.05, abs=1e-9)


#: 400 rewards of random actions (seed 7) from reset(seed=3), five collisions among them, recorded with the
#: walkthrough reward when it was the default (before issue 22): sha256 of their float64 bytes.
WALKTHROUGH_PIN = "e37391b4f7247b1a0a4131eef21ef1dd0b176efeae44f267511ad6b3a1f9c2ce"


def test_the_walkthrough_reward_is_unchanged_byte_for_byte():
    # The speeds pinned as they were when the rewards were recorded (the robot's own are 0.5 m/s and 1 rad/s).
    env = gymnasium.make(ENV_ID, preset="drl_arena", lidar_beams=40, lidar_sectors=20, reward="walkthrough",
                         time_limit_factor=None, linear_velocity=[0.0, 1.0], angular_velocity=1.0)
    rng = np.random.default_rng(7)
    rewards, ends = [], 0
    env.reset(seed=3)
    for _ in range(400):
        _, r, terminated, truncated, _ = env.step(rng.uniform(env.action_space.low, env.action_space.high).astype(np.float32))
        rewards.append(r)
        if terminated or truncated:
            ends += 1
            env.reset()
    assert ends == 5 and rewards[:2] == [-0.08466604351997375, 0.11305001378059387]
    assert hashlib.sha256(np.array(rewards, dtype=np.float64).tobytes()).hexdigest() == WALKTHROUGH_PIN


# -- the geodesic distance ------------------------------------------------------------------------------------

@pytest.mark.parametrize("preset, generator, params, seed", SWEEP + [(None, "door", {}, 0), (None, "door", {}, 1)]
                         + [("drl_arena", None, None, s) for s in range(4, 12)])
def test_the_geodesic_distance_agrees_with_the_exact_path_length_at_the_spawn(preset, generator, params, seed):
    """Within the field's stated bound: never below L (beyond a chord's cut), at most 2.75 % + 2 spacings above."""
    env = sweep_env(preset, generator, params, lidar_beams=36)
    _, info = env.reset(seed=seed)
    L, G, h = info["reference_path_length"], info["geodesic_distance"], env.geodesic.h
    assert L - 0.01 <= G <= 1.0275 * L + 2 * h, (L, G)
    if env.geodesic.straight_free(*env.task["spawn"][:2]):
        assert G == pytest.approx(L, rel=1e-9)


def test_the_geodesic_distance_is_the_straight_line_wherever_the_segment_to_the_goal_is_free():
    """Random points where the disc fits, in three worlds; the segment tested by the configuration space's exact test."""
    for preset, generator, params, seed in (SWEEP[0], SWEEP[4], SWEEP[6]):
        env = sweep_env(preset, generator, params, lidar_beams=36)
        env.reset(seed=seed)
        field = env.geodesic
        (x0, y0, x1, y1) = field.cs.box
        pts = np.random.default_rng(seed).uniform([x0, y0], [x1, y1], size=(3000, 2))
        pts = pts[field.cs.points_clearance(pts) >= 0]
        free = field.cs.segments_clear(pts, np.broadcast_to(field.goal, pts.shape))
        assert free.sum() > 50 and (~free).sum() > 10  # both kinds are sampled
        gx, gy = field.goal
        for (x, y), ok in zip(pts, free):
            d = field.distance(x, y)
            if ok:
                assert d == pytest.approx(math.hypot(x - gx, y - gy), rel=1e-12)
            else:  # out of sight the way round is longer than the straight line
                assert d >= math.hypot(x - gx, y - gy) - 0.01


# -- observation bounds and the time limit ----------------------------------------------------------------------

def test_every_observation_lies_inside_the_finite_space_over_long_random_runs():
    env = make(preset="drl_arena", lidar_beams=36, lidar_noise=0.05)
    space = env.observation_space
    assert np.all(np.isfinite(space.low)) and np.all(np.isfinite(space.high))
    assert space.high[-4] == pytest.approx(math.hypot(10.0, 10.0), rel=1e-6)  # the preset's 10 x 10 m room
    assert space.high[:-4].tolist() == [10.0] * 36
    rng = np.random.default_rng(0)
    obs, _ = env.reset(seed=0)
    for _ in range(3000):
        assert space.contains(obs), obs
        obs, _, terminated, truncated, _ = env.step(rng.uniform(env.action_space.low, env.action_space.high))
        if terminated or truncated:
            obs, _ = env.reset()
    clipped = make(preset="drl_arena", lidar_beams=36, goal_distance_max=1.5)
    obs, _ = clipped.reset(seed=0)
    assert clipped.observation_space.contains(obs) and obs[-4] == pytest.approx(1.5, abs=1e-6)


def test_standard_wrappers_accept_the_space():
    from gymnasium.wrappers import NormalizeObservation, RescaleObservation

    n = 36 + 4
    for wrap in (lambda e: RescaleObservation(e, np.full(n, -1.0, np.float32), np.full(n, 1.0, np.float32)),
                 NormalizeObservation):
        env = wrap(gymnasium.make(ENV_ID, preset="drl_arena", lidar_beams=36))
        obs, _ = env.reset(seed=0)
        for _ in range(5):
            obs, *_ = env.step(env.action_space.sample())
        assert np.all(np.isfinite(obs)) and env.observation_space.contains(obs.astype(np.float32))


def test_the_goal_distance_bound_comes_from_the_source():
    assert make(generator="cluttered", params={"size": [6, 8]}).observation_space.high[-4] == pytest.approx(10.0)
    corridor = make(generator="corridor", params={"shape": "L"})  # no size: the seed-0 world's diagonal
    (x0, y0), (x1, y1) = corridor.source.world(0).bounds
    assert corridor.observation_space.high[-4] == pytest.approx(math.hypot(x1 - x0, y1 - y0), rel=1e-6)


def test_the_time_limit_is_a_multiple_of_the_optimal_time():
    env = make(preset="drl_arena", lidar_beams=36, linear_velocity=[0.0, 0.5], angular_velocity=2.0)
    _, info = env.reset(seed=1)
    assert info["time_limit"] == pytest.approx(2.0 * info["reference_path_length"] / 0.5 + math.pi / 2.0)
    own = make(preset="drl_arena", lidar_beams=36, time_limit_factor=None)
    _, info = own.reset(seed=1)
    assert info["time_limit"] == own.task["time_limit"]


def test_a_bad_reward_name_is_one_clear_line():
    from worldgen.errors import ParameterError

    with pytest.raises(ParameterError) as err:
        gymnasium.make(ENV_ID, reward="distance")
    assert str(err.value) == ("parameter 'reward' must be one of geodesic, walkthrough, euclidean_progress, "
                              "got 'distance'")
