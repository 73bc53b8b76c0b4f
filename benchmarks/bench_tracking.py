"""How far the shipped TimedFollower is off its schedule at the environment's defaults (docs/people.md, the
tracking margin): since issue 37 the environment's robot is the world's (speeds up to robot.max_speed,
turns up to robot.max_turn_rate), before it could go 1 m/s whatever the world's robot.

    .venv/bin/python benchmarks/bench_tracking.py [--crowds N] [--old-speeds]

Episodes: the six presets with people (seeds 0 and 1) and ``--crowds`` random crowds (default 30: cluttered
8 x 8 m, 4 obstacles, 5 people walking 12 s, the behaviour cycling through impassive, regular, surprised,
scared, curious and a mix of all five; world seed k for crowd k), each driven by
worldgen.envs.policies.drive_timed. The lag of an episode is the largest distance between the robot and
where the schedule has it, sampled at every control period (as tests/envs/test_reacting_env.py measures
it). ``--old-speeds`` drives with the environment's old defaults (linear_velocity [0, 1], angular_velocity
1) instead. Prints the worst lag and the episodes that reached the goal without contact; the figures go
to benchmarks/results/tracking.json.
"""

from __future__ import annotations

import argparse
import json
import platform
from pathlib import Path

import numpy as np

RESULTS = Path(__file__).resolve().parent / "results" / "tracking.json"
PRESETS = ("person_head_on", "person_crossing", "person_in_doorway", "person_overtaking", "group_in_corridor",
           "crowd_reacting")
KINDS = ("impassive", "regular", "surprised", "scared", "curious", "impassive,regular,surprised,scared,curious")
CROWD = {"size": [8.0, 8.0], "n_obstacles": 4, "n_people": 5, "people_duration": 12.0}


def lag_of(env, seed: int) -> tuple[float, bool]:
    """(largest lag behind the schedule in m, reached the goal without contact) of one episode."""
    from worldgen.envs.policies import TimedFollower, drive_timed

    info = drive_timed(env, seed=seed)
    follower, rows = TimedFollower.for_env(env), np.asarray(env.unwrapped.episode.rows)
    lag = max(float(np.hypot(*(follower.at(t) - rows[k, 1:3]))) for k, t in enumerate(rows[:, 0]))
    return lag, bool(info["success"] and not info["collisions"])


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--crowds", type=int, default=30)
    parser.add_argument("--old-speeds", action="store_true")
    args = parser.parse_args()
    import gymnasium

    import worldgen.envs  # noqa: F401  (registers the id)

    settings = {"linear_velocity": [0.0, 1.0], "angular_velocity": 1.0} if args.old_speeds else {}
    episodes = []
    for preset in PRESETS:
        env = gymnasium.make("worldgen/Navigation-v0", preset=preset, **settings)
        episodes += [(preset, seed, *lag_of(env, seed)) for seed in range(2)]
    for k in range(args.crowds):
        kind = KINDS[k % len(KINDS)]
        env = gymnasium.make("worldgen/Navigation-v0", generator="cluttered",
                             params=dict(CROWD, people_behaviour=kind), **settings)
        episodes.append((f"crowd:{kind}", k, *lag_of(env, k)))
    worst = max(e[2] for e in episodes)
    clean = sum(e[3] for e in episodes)
    print(f"{'old speeds' if args.old_speeds else 'defaults'}: {len(episodes)} episodes, {clean} reached the goal "
          f"without contact, worst lag {worst:.4f} m")
    RESULTS.parent.mkdir(exist_ok=True)
    RESULTS.write_text(json.dumps({"settings": settings, "machine": platform.machine(), "episodes": len(episodes),
                                   "clean": clean, "worst_lag": worst,
                                   "per_episode": [list(e) for e in episodes]}, indent=1) + "\n")


if __name__ == "__main__":
    main()
