"""A training-style loop: a fresh, checked world per episode, built in memory and loaded into MuJoCo.

    .venv/bin/python examples/training_loop.py [OUT_DIR]

The pattern of DRL navigation training (random boxes, a random spawn/goal
pair per episode): each episode generates a new cluttered world with its own
seed, loads its MJCF with ``mujoco.MjModel.from_xml_string`` and steps it.
Nothing is written to disk (OUT_DIR is accepted for a uniform command line and
left untouched); the world's ground truth (spawn, goal, reference path length)
is what a reward function would read. Prints episodes per second.
"""

from __future__ import annotations

import sys
import time

import mujoco
import numpy as np

import worldgen

EPISODES = 30
STEPS = 200  # physics steps per episode: a stand-in for the agent's rollout


def main() -> int:
    start = time.perf_counter()
    lengths = []
    for episode in range(EPISODES):
        world = worldgen.generate("cluttered", seed=1000 + episode, size=[8, 8], n_obstacles=12)
        model = mujoco.MjModel.from_xml_string(world.to_mjcf())
        data = mujoco.MjData(model)
        for _ in range(STEPS):
            mujoco.mj_step(model, data)
        task = world.tasks[0]
        path = world.feasibility.paths[0]
        lengths.append(path.length)
        assert np.isfinite(data.qpos).all()
        if episode < 3:
            print(f"episode {episode}: {world.world_id}, spawn ({task.spawn.x:.2f}, {task.spawn.y:.2f}) -> "
                  f"goal ({task.goal.x:.2f}, {task.goal.y:.2f}), reference path {path.length:.2f} m")
    elapsed = time.perf_counter() - start
    print(f"{EPISODES} episodes in {elapsed:.2f} s: {EPISODES / elapsed:.1f} episodes per second "
          f"(generate + check + MJCF + load + {STEPS} steps); mean reference path {np.mean(lengths):.2f} m")
    return 0


if __name__ == "__main__":
    sys.exit(main())
