"""worldgen.envs: the Gymnasium navigation environment (worldgen/Navigation-v0).

Gymnasium is an optional extra (``rl``, also in ``test``): these tests skip where it is
missing, except under CI, where they fail (tests/envs/conftest.py).
"""

from __future__ import annotations

import math
import subprocess
import sys
import textwrap

import numpy as np
import pytest
from support.envs import ENV_ID, gymnasium, make


def run_python(code: str, timeout: int = 120) -> subprocess.CompletedProcess:
    return subprocess.run([sys.executable, "-c", textwrap.dedent(code)], capture_output=True, text=True, timeout=timeout)


def drive(env, policy, limit: int = 5000):
    """Step ``policy(env)`` until the episode ends; (last reward, terminated, truncated, info, rewards)."""
    rewards = []
    for _ in range(limit):
        obs, reward, terminated, truncated, info = env.step(policy(env))
        assert env.observation_space.contains(obs)
        rewards.append(reward)
        if terminated or truncated:
            return reward, terminated, truncated, info, rewards
    raise AssertionError("the episode did not end")


def follower(env):
    from worldgen.envs.policies import PathFollower

    f = PathFollower.for_env(env)
    return lambda e: f.action(*e.robot_pose)


# -- Gymnasium's contract ----------------------------------------------------------------------------------

def test_passes_gymnasiums_env_checker():
    from gymnasium.utils.env_checker import check_env

    check_env(gymnasium.make(ENV_ID, preset="drl_arena").unwrapped, skip_render_check=True)
    check_env(gymnasium.make(ENV_ID, preset="drl_arena", render_mode="rgb_array", lidar_sectors=20,
                             lidar_noise=0.02).unwrapped)


def test_spaces_are_as_documented():
    env = make(lidar_beams=180, lidar_sectors=20, linear_velocity=[-0.2, 0.8], angular_velocity=1.5)
    assert env.action_space.shape == (2,) and env.action_space.dtype == np.float32
    assert env.action_space.low.tolist() == pytest.approx([-0.2, -1.5]) and env.action_space.high.tolist() == pytest.approx([0.8, 1.5])
    assert env.observation_space.shape == (24,) and env.observation_space.dtype == np.float32
    obs, info = env.reset(seed=1)
    x, y, yaw = env.robot_pose
    gx, gy = env.task["goal"][:2]
    assert obs[-4] == pytest.approx(math.hypot(gx - x, gy - y), abs=1e-5)
    bearing = (math.atan2(gy - y, gx - x) - yaw + math.pi) % (2 * math.pi) - math.pi
    assert obs[-3] == pytest.approx(bearing, abs=1e-5)
    assert obs[-2:].tolist() == [0.0, 0.0]
    obs, *_ = env.step([0.5, -3.0])  # w clipped into the box
    assert obs[-2:].tolist() == pytest.approx([0.5, -1.5])


def test_registered_through_gymnasium_make_without_importing_worldgen_envs():
    """Gymnasium 1.x has no plugin system: the id loads through make's "module:id" form, in a fresh process."""
    run = run_python("""
        import sys, gymnasium
        assert "worldgen.envs" not in sys.modules
        env = gymnasium.make("worldgen.envs:worldgen/Navigation-v0", generator="cluttered",
                             params={"size": [6, 6], "n_obstacles": 3})
        obs, info = env.reset(seed=0)
        print(type(env.unwrapped).__name__, info["world_id"].split("-")[0], obs.shape)
    """)
    assert run.returncode == 0, run.stderr
    assert run.stdout.split() == ["NavigationEnv", "cluttered", "(364,)"]


def test_worldgen_and_its_pytest_plugin_do_not_import_gymnasium():
    run = run_python("""
        import sys
        import worldgen, worldgen.testing.plugin
        worldgen.generate("cluttered", 0, size=[6, 6], n_obstacles=2)
        print("gymnasium" in sys.modules, "worldgen.envs" in sys.modules)
    """)
    assert run.returncode == 0, run.stderr
    assert run.stdout.split() == ["False", "False"]


def test_without_gymnasium_the_env_says_what_to_install_in_one_line():
    run = run_python("""
        import sys
        sys.modules["gymnasium"] = None          # as if it were not installed
        import worldgen.envs                     # importing the package still works
        try:
            worldgen.envs.NavigationEnv
        except worldgen.envs.MissingDependencyError as exc:
            print(str(exc))
        try:
            worldgen.envs.register_envs()
        except ImportError as exc:
            print(str(exc))
    """)
    assert run.returncode == 0, run.stderr
    lines = run.stdout.splitlines()
    assert len(lines) == 2 and lines[0] == lines[1]
    assert lines[0] == "worldgen.envs needs Gymnasium, which is not installed: pip install 'worldgen[rl]'"


# -- worlds, seeds, determinism ----------------------------------------------------------------------------

DETERMINISM = """
    import hashlib, numpy as np, gymnasium, worldgen.envs
    env = gymnasium.make("worldgen/Navigation-v0", preset="drl_arena", lidar_noise=0.03, lidar_sectors=40)
    rng = np.random.default_rng(7)
    h = hashlib.sha256()
    obs, info = env.reset(seed=11)
    h.update(obs.tobytes()); ids = [info["world_id"]]
    for _ in range(150):
        obs, reward, terminated, truncated, info = env.step(rng.uniform(env.action_space.low, env.action_space.high).astype(np.float32))
        h.update(obs.tobytes()); h.update(np.float64(reward).tobytes())
        if terminated or truncated:
            obs, info = env.reset()
            h.update(obs.tobytes()); ids.append(info["world_id"])
    print(h.hexdigest(), len(ids), *ids)
"""


def test_same_seeds_and_actions_give_the_same_observations_in_two_processes():
    first, second = run_python(DETERMINISM), run_python(DETERMINISM)
    assert first.returncode == 0 and second.returncode == 0, first.stderr + second.stderr
    assert first.stdout == second.stdout
    assert int(first.stdout.split()[1]) >= 2  # the run crossed a reset into a second world
    other = run_python(DETERMINISM.replace("seed=11", "seed=12"))
    assert other.stdout.split()[0] != first.stdout.split()[0]


def test_every_reset_draws_a_fresh_checked_world_in_memory(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    env = make(preset="drl_arena")
    seen = []
    for k in range(5):
        obs, info = env.reset(seed=3) if k == 0 else env.reset()
        seen.append(info["world_id"])
        assert info["reference_path_length"] == pytest.approx(env.world.task["path"]["length"])
        assert info["reference_path_length"] >= math.dist(env.task["spawn"][:2], env.task["goal"][:2]) - 1e-9
    assert len(set(seen)) == 5
    assert list(tmp_path.iterdir()) == []  # nothing written
    env.reset(seed=3)
    again = [env.reset()[1]["world_id"] for _ in range(4)]
    assert again == seen[1:]  # the same seed replays the same worlds
    import worldgen
    world = worldgen.generate_preset("drl_arena", seed=env.reset(options={"world_seed": 42})[1]["world_seed"])
    assert env.world.world_id == world.world_id
    assert env.world.reference_path_length == pytest.approx(world.feasibility.paths[0].length)


def test_the_first_scan_is_world_json_ground_truth():
    """With the world's lidar settings, the scan at the spawn is sensors.lidar (MuJoCo rays vs the analytic caster)."""
    import worldgen

    world = worldgen.generate_preset("drl_arena", seed=5)
    truth = world.metadata["sensors"]["lidar"]
    env = make(preset="drl_arena", lidar_range_min=truth["range_min"], lidar_range_max=truth["range_max"],
               lidar_beams=truth["samples"])
    obs, info = env.reset(options={"world_seed": 5})
    assert info["world_id"] == world.world_id
    assert env.lidar.angles[0] == pytest.approx(truth["angle_min"], abs=1e-6)
    assert np.abs(obs[:-4] - np.array(truth["ranges"])).max() < 1e-3


def test_sectors_are_the_minimum_of_their_beams_and_noise_comes_from_the_seed():
    plain = make(preset="drl_arena")
    binned = make(preset="drl_arena", lidar_sectors=20)
    noisy = make(preset="drl_arena", lidar_noise=0.05)
    a, b, c = (e.reset(seed=2)[0] for e in (plain, binned, noisy))
    assert np.array_equal(b[:-4], a[:-4].reshape(20, 18).min(axis=1))
    diff = c[:-4] - a[:-4]
    assert 0.02 < np.std(diff) < 0.08
    assert np.array_equal(c, noisy.reset(seed=2)[0]) and not np.array_equal(c, noisy.reset(seed=3)[0])


# -- driving -----------------------------------------------------------------------------------------------

def test_driving_straight_into_an_obstacle_is_a_collision_with_reward_minus_100():
    """A wall 2.0 m straight ahead (the minimal generator): full speed ahead touches it after ~1.8 m."""
    env = make(generator="minimal", params={"target_distance": 2.0}, reward="walkthrough")
    env.reset(seed=0)
    v_max = float(env.action_space.high[0])  # the world's robot's max_speed (0.5 m/s, its default)
    assert v_max == 0.5
    reward, terminated, truncated, info, rewards = drive(env, lambda e: [v_max, 0.0])
    assert terminated and not truncated and reward == -100.0
    assert [c["entity"] for c in info["collisions"]] == ["target"]
    assert info["success"] is False and info["spl"] == 0.0 and info["reached_goal"] is False
    assert 1.75 < info["path_length"] < 1.85  # 2.0 m to the wall's face less the 0.2 m radius
    assert info["min_clearance"] <= 1e-3
    # Until then the walkthrough's reward: v/2 - |w|/2, less (1 - r)/2 once the wall is nearer than 1 m.
    assert rewards[0] == pytest.approx(v_max / 2, abs=1e-6) and min(rewards[:-1]) < v_max / 2
    with pytest.raises(RuntimeError, match="reset"):
        env.step([0.0, 0.0])


def test_the_reference_path_follower_reaches_the_goal_with_spl_near_1():
    env = make(preset="drl_arena")
    for seed in range(6):
        _, info = env.reset(seed=seed)
        reward, terminated, truncated, info, _ = drive(env, follower(env))
        # +100, plus the last step's shaping (about k * v * dt), less the time penalty
        assert terminated and 100.0 < reward < 102.0, info
        assert info["success"] is True and info["collisions"] == [] and info["reached_goal"] is True
        assert info["spl"] > 0.9
        assert info["path_length"] < info["reference_path_length"] * 1.1
        assert info["min_clearance"] > 0.0 and info["duration"] <= env._time_limit
        from support.reftools_mujoco import assert_no_warnings
        assert_no_warnings(env._sim.model, env._sim.data, info["world_id"])


def test_standing_still_is_truncated_at_the_tasks_time_limit():
    env = make(preset="drl_arena", control_period=0.5)
    _, first = env.reset(seed=4)
    reward, terminated, truncated, info, rewards = drive(env, lambda e: [0.0, 0.0])
    assert truncated and not terminated
    assert info["time"] == pytest.approx(math.ceil(first["time_limit"] / 0.5) * 0.5, abs=1e-6)
    assert info["success"] is False and info["spl"] == 0.0 and info["path_length"] == pytest.approx(0.0, abs=1e-6)
    assert len(rewards) == math.ceil(first["time_limit"] / 0.5)


def test_a_custom_reward_function_replaces_the_default():
    seen = []

    def progress(o):
        seen.append(o)
        return o.previous_goal_distance - o.goal_distance

    env = make(preset="drl_arena", reward_fn=progress)
    env.reset(seed=1)
    _, reward, *_ = env.step([0.5, 0.0])
    assert reward == pytest.approx(seen[0].previous_goal_distance - seen[0].goal_distance)
    assert seen[0].v == 0.5 and seen[0].w == 0.0 and seen[0].time == pytest.approx(0.1)
    weighted = make(preset="drl_arena", reward="walkthrough", reward_speed=2.0, reward_turn=0.0)
    weighted.reset(seed=1)
    reward = weighted.step([0.5, 0.7])[1]
    assert reward == pytest.approx(2.0 * 0.5 - 0.5 * max(0.0, 1.0 - weighted._ranges.min()))


def test_movers_are_driven_along_their_scripts_every_physics_step():
    from worldgen.scene.motion import mover_positions

    env = make(generator="cluttered", params={"size": [8, 8], "n_obstacles": 3, "n_movers": 2})
    env.reset(seed=0)
    assert len(env.world.movers) == 2
    for _ in range(7):
        env.step([0.0, 0.3])
    data = env._sim.data
    expected = mover_positions(env.world.movers, data.time - env._sim.model.opt.timestep)  # set before the last step
    assert np.allclose(data.mocap_pos[env._sim.mocap, :2], expected, atol=1e-9)


def test_a_pack_is_a_fixed_benchmark_set_in_order(tmp_path):
    from worldgen.pack import Pack, build_pack, parse_recipe

    recipe = parse_recipe("name: arena\nseeds: 3\nworlds:\n  - preset: drl_arena\n")
    build_pack(recipe, tmp_path / "arena")
    pack = Pack.open(tmp_path / "arena")
    env = make(pack=str(tmp_path / "arena"))
    ids = [env.reset(seed=0)[1]["world_id"]] + [env.reset()[1]["world_id"] for _ in range(3)]
    assert ids == pack.ids() + pack.ids()[:1]
    _, info = env.reset(options={"world_index": 2})
    assert info["world_index"] == 2 and info["world_id"] == pack[2].world_id
    assert info["reference_path_length"] == pack[2].metadata["tasks"][0]["path"]["length"]
    reward, terminated, _, end, _ = drive(env, follower(env))
    assert terminated and end["success"] and end["world_id"] == pack[2].world_id
    assert env.reset()[1]["world_index"] == 0


@pytest.mark.parametrize("kwargs, message", [
    ({"lidar_beams": 0}, "parameter 'lidar_beams' must be in [1, 4096], got 0"),
    ({"control_period": 0.0}, "parameter 'control_period' must be in [0.001, 10], got 0.0"),
    ({"linear_velocity": [1.0, 0.5]}, "parameter 'linear_velocity' must be [min, max] with min <= max, got [1.0, 0.5]"),
    ({"angular_velocity": -1}, "parameter 'angular_velocity' must be in [0.001, 20], got -1"),
    ({"lidar_sectors": 7}, "parameter 'lidar_sectors' must divide lidar_beams = 360 (a whole number of beams per sector), got 7"),
    ({"lidar_noise": -0.1}, "parameter 'lidar_noise' must be in [0, 10], got -0.1"),
    ({"lidar_range_min": 5.0, "lidar_range_max": 2.0}, "parameter 'lidar_range_min' must be below lidar_range_max = 2.0, got 5.0"),
    ({"reward_fn": 3}, "parameter 'reward_fn' must be a callable (StepOutcome -> float) or None, got 3"),
    ({"lidar_beam": 10}, "unknown parameter 'lidar_beam' (did you mean 'lidar_beams'?); known parameters:"),
    ({"generator": "cluttered", "params": {"n_obstacles": -1}}, "parameter 'n_obstacles' must be in [0, 5000], got -1"),
    ({"generator": "cluttered", "preset": "drl_arena"}, "parameters 'generator' and 'preset' exclude each other"),
    ({"preset": "no_such_preset"}, "unknown preset 'no_such_preset'; available:"),
    ({"pack": 5}, "parameter 'pack' must be a worldgen.Pack or a pack folder or archive, got 5"),
    ({"lidar_fov": 7.0}, "parameter 'lidar_fov' must be in [0.001, 6.283185"),
])
def test_bad_parameters_are_one_clear_line(kwargs, message):
    from worldgen.errors import ParameterError

    with pytest.raises(ParameterError) as err:
        gymnasium.make(ENV_ID, **kwargs)
    assert str(err.value).startswith(message) and "\n" not in str(err.value)


def test_render_modes_other_than_rgb_array_are_refused():
    from worldgen.envs import NavigationEnv
    from worldgen.errors import ParameterError

    with pytest.raises(ParameterError, match=r"^parameter 'render_mode' must be one of None, rgb_array, got 'ansi'$"):
        NavigationEnv(render_mode="ansi")


def test_a_control_period_that_is_not_whole_physics_steps_is_refused_at_reset():
    from worldgen.errors import ParameterError

    env = make(preset="drl_arena", control_period=0.0035)
    with pytest.raises(ParameterError, match=r"parameter 'control_period' must be a whole multiple of the world's "
                                             r"physics step_size = 0.002 s, got 0.0035"):
        env.reset(seed=0)
    with pytest.raises(ParameterError, match=r"unknown reset option 'world_index' for worlds from a generator"):
        make(preset="drl_arena").reset(options={"world_index": 0})
    with pytest.raises(ParameterError, match=r"option 'world_seed' must be an integer in \[0, "):
        make(preset="drl_arena").reset(options={"world_seed": -1})


# -- vector envs, rendering --------------------------------------------------------------------------------

@pytest.mark.parametrize("kind", ["sync", "async"])
def test_runs_under_gymnasiums_vector_envs(kind):
    fns = [lambda: gymnasium.make(ENV_ID, preset="drl_arena", lidar_sectors=20)] * 2
    vec = gymnasium.vector.SyncVectorEnv(fns) if kind == "sync" else gymnasium.vector.AsyncVectorEnv(fns)
    try:
        obs, info = vec.reset(seed=[10, 11])
        assert obs.shape == (2, 24) and len(set(info["world_id"])) == 2
        ended = 0
        for _ in range(60):
            obs, reward, terminated, truncated, info = vec.step(np.tile(np.array([[1.0, 0.4]], np.float32), (2, 1)))
            assert obs.shape == (2, 24) and reward.shape == (2,)
            ended += int(np.sum(terminated | truncated))
        assert ended >= 1  # driving in circles at full speed ends somewhere
    finally:
        vec.close()


def test_renders_a_top_down_frame_with_the_robot_its_beams_and_its_track():
    from worldgen.envs.render import ROBOT_COLOUR, TopDown

    env = make(preset="drl_arena", render_mode="rgb_array")
    env.reset(seed=0)
    first = env.render()
    for _ in range(10):
        env.step([0.6, 0.3])
    frame = env.render()
    assert frame.dtype == np.uint8 and frame.ndim == 3 and frame.shape[2] == 3 and frame.shape == first.shape
    lay = TopDown(env.world.metadata()).layout

    def beside(x, y, yaw):  # half a radius to the robot's left: on its body, off its heading line
        r = env.world.robot.radius / 2
        return tuple(int(round(c)) for c in lay.px(x - r * math.sin(yaw), y + r * math.cos(yaw)))

    u, v = beside(*env.robot_pose)
    assert tuple(frame[v, u]) == ROBOT_COLOUR
    spawn = env.task["spawn"]
    u0, v0 = beside(spawn[0], spawn[1], spawn[5])
    assert tuple(first[v0, u0]) == ROBOT_COLOUR and tuple(frame[v0, u0]) != ROBOT_COLOUR
    plain = make(preset="drl_arena")
    plain.reset(seed=0)
    with pytest.warns(UserWarning, match="render_mode"):
        assert plain.render() is None
