"""Two policies evaluated in the Gymnasium navigation environment over a fixed world pack.

    .venv/bin/python examples/rl_navigation.py [OUT_DIR]      # needs: pip install 'worldgen[rl]'

Builds a small pack (10 worlds: the DRL arena and a denser 8 x 8 m room) in
OUT_DIR/pack, then drives every world once with each policy in
``worldgen/Navigation-v0`` (the pack's worlds in order: a fixed benchmark set):

- ``follower``: pure pursuit along the task's reference path (worldgen.envs.policies.PathFollower),
  an upper bound that reads the robot's true pose;
- ``random``: uniform random actions (the floor).

Each run's recorded trajectory is judged by ``worldgen.oracles.evaluate`` against
the criteria below and each world's scenario.yaml (success rate, collisions,
path efficiency, clearance: the same report as for a run from any simulator);
SPL, which evaluate does not know, comes from the environment's episode info.
The reports go to OUT_DIR/report-<policy>.json. The exit status is 1 when the
follower fails a criterion (the random policy is expected to).
"""

from __future__ import annotations

import statistics
import sys
import tempfile
import time
from pathlib import Path

import gymnasium

import worldgen.envs  # noqa: F401  (registers worldgen/Navigation-v0)
from worldgen import oracles
from worldgen.envs.policies import PathFollower, RandomPolicy
from worldgen.pack import Pack, build_pack, parse_recipe

RECIPE = """
name: rl_smoke
formats: [mjcf]          # the environment needs only the MJCF (plus world.json, always written)
seeds: 5
worlds:
  - preset: drl_arena
  - generator: cluttered
    params: {size: [8, 8], n_obstacles: 10, obstacle_shapes: box}
"""

CRITERIA = """
navigation:
  success_rate: 0.9       # at least 9 of 10 worlds: goal reached in time, no contact
  path_efficiency: 1.1    # on average at most 10 % longer than the optimal path
safety:
  collision_tolerance: 0
"""


def episode(env, policy_name: str, seed: int):
    """Drive one episode; return (trajectory, end-of-episode info)."""
    policy = (PathFollower.for_env(env) if policy_name == "follower"
              else RandomPolicy(env.action_space, seed=seed))
    while True:
        _, _, terminated, truncated, info = env.step(policy.action(*env.robot_pose))
        if terminated or truncated:
            return env.episode.trajectory, info


def main(out_dir: str) -> int:
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    start = time.perf_counter()
    build_pack(parse_recipe(RECIPE), out / "pack")
    pack = Pack.open(out / "pack")
    print(f"pack of {len(pack)} worlds built in {time.perf_counter() - start:.1f} s at {out / 'pack'}")
    env = gymnasium.make("worldgen/Navigation-v0", pack=pack).unwrapped
    status = 0
    for name in ("follower", "random"):
        start = time.perf_counter()
        runs, infos = [], []
        env.reset(seed=0, options={"world_index": 0})
        for i in range(len(pack)):
            if i:
                env.reset()
            trajectory, info = episode(env, name, seed=i)
            runs.append((trajectory, pack[i]))
            infos.append(info)
        report = oracles.evaluate(runs, CRITERIA)
        report.write_json(out / f"report-{name}.json")
        spl = statistics.mean(i["spl"] for i in infos)
        agree = sum(i["success"] == r["success"] for i, r in zip(infos, report.runs))
        steps = sum(len(t) - 1 for t, _ in runs)
        print(f"\n== {name}: {len(runs)} episodes, {steps} steps in {time.perf_counter() - start:.1f} s")
        print(report)
        print(f"success rate {report.summary['success_rate']:.2f}, mean SPL {spl:.3f}, "
              f"collisions {report.summary['collision_count']} (MuJoCo: {sum(len(i['collisions']) for i in infos)}); "
              f"env and evaluate agree on success in {agree} of {len(runs)} runs")
        if name == "follower" and not report.passed:
            status = 1
            for line in report.failures:
                print("FAILED", line)
    env.close()
    return status


if __name__ == "__main__":
    sys.exit(main(sys.argv[1] if len(sys.argv) > 1 else tempfile.mkdtemp(prefix="worldgen-rl-")))
