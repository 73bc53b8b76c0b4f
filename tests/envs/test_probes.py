"""The reference probes (worldgen.envs.probes): deterministic, and they tell easy worlds from hard ones."""

from __future__ import annotations

import math

import numpy as np
import pytest
from support.envs import make

from worldgen.errors import ParameterError


def actions(env, probe, seed):
    from worldgen.envs.probes import make_probe

    obs, _ = env.reset(seed=seed)
    act = make_probe(probe, env)
    out = []
    while True:
        a = act(env, obs)
        out.append(np.asarray(a).tobytes())
        obs, _, terminated, truncated, info = env.step(a)
        if terminated or truncated:
            return out, info


@pytest.mark.parametrize("probe", ["reactive", "tracker"])
def test_a_probe_gives_the_same_actions_twice(probe):
    first, a = actions(make(generator="cluttered"), probe, 1)
    second, b = actions(make(generator="cluttered"), probe, 1)  # a fresh env: nothing carried over
    assert len(first) > 20 and first == second
    assert (a["success"], a["path_length"]) == (b["success"], b["path_length"])


def outcomes(env, probe, seeds):
    from worldgen.envs.probes import run_episode

    return [run_episode(env, probe, seed=s) for s in seeds]


@pytest.mark.parametrize("probe", ["reactive", "tracker"])
def test_a_probe_reaches_the_goal_in_an_empty_room(probe):
    runs = outcomes(make(generator="cluttered", params={"size": [8, 8], "n_obstacles": 0}), probe, range(4))
    assert all(r["success"] and r["collisions"] == [] for r in runs)
    # Nothing in the way: a near-straight drive, no longer than 1.1 x the optimal path.
    assert all(r["path_length"] <= 1.1 * r["reference_path_length"] for r in runs)


def test_the_probes_fail_sometimes_in_clutter_each_in_its_own_way():
    """Measured on these seeds (default cluttered room, 20 obstacles): the reactive probe is trapped (time out)
    in 2 of 6, the corner cutter hits an obstacle in 4 of 6; each succeeds in the others."""
    env = make(generator="cluttered")
    reactive = outcomes(env, "reactive", range(6))
    tracker = outcomes(env, "tracker", range(6))
    assert 0 < sum(r["success"] for r in reactive) < 6
    assert 0 < sum(r["success"] for r in tracker) < 6
    # The reactive probe keeps its margin: it fails by not arriving, never by a collision here.
    assert all(r["collisions"] == [] for r in reactive)
    assert all(r["collisions"] for r in tracker if not r["success"])


def test_the_reactive_probe_reads_only_the_observation_and_sees_a_wall_ahead():
    from worldgen.envs.probes import HEADINGS, ReactiveProbe

    angles = np.linspace(-math.pi, math.pi, 360, endpoint=False)
    probe = ReactiveProbe(angles, radius=0.2, range_max=10.0, v_max=1.0, w_max=1.0)
    # A wall 1 m ahead (x = 1): every beam pointing forward ends on it.
    with np.errstate(divide="ignore"):
        scan = np.where(np.cos(angles) > 1e-9, 1.0 / np.cos(angles), 10.0)
    scan = np.minimum(scan, 10.0)
    free = probe.free(scan)
    assert free[HEADINGS // 2] == pytest.approx(1.0 - 0.2 - 0.06, abs=0.02)  # the disc's edge plus the margin
    assert free[0] == 10.0  # straight back: nothing
    # Goal 3 m straight ahead, behind the wall: it does not drive into the wall but turns away.
    v, w = probe.action(np.r_[scan, 3.0, 0.0, 0.0, 0.0])
    assert v == 0.0 and abs(w) > 0.5
    # With the wall gone it drives straight at the goal.
    v, w = probe.action(np.r_[np.full(360, 10.0), 3.0, 0.0, 0.0, 0.0])
    assert v == pytest.approx(1.0) and w == 0.0


def test_an_unknown_probe_is_one_line():
    from worldgen.envs.probes import make_probe

    env = make(generator="cluttered", params={"n_obstacles": 0})
    env.reset(seed=0)
    with pytest.raises(ParameterError, match="parameter 'probe' must be one of reactive, tracker, got 'dwa'"):
        make_probe("dwa", env)
