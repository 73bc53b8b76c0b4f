"""People who react to the robot (issue 31, docs/people.md): the certificate's promise over many episodes,
what reactions cost an environment step, and what the tube costs the certificate.

    .venv/bin/python benchmarks/bench_reacting.py [--episodes N] [--steps N] [--worlds N] [--all-cores]

- ``episodes``: N episodes (default 1,000) of the timed path's follower (worldgen.envs.policies.drive_timed,
  at the environment's defaults: the timed path turns within robot.max_turn_rate) among reacting people:
  four presets made reacting (person_crossing, person_overtaking, group_in_corridor, person_in_doorway)
  and random crowds (cluttered 8 x 8 m, 4 obstacles, 5 people, 12 s),
  the behaviour cycling through regular, surprised, scared, curious and a mix of all five; a new world seed
  each episode. Counted: contacts with people (the target: 0), steps at which a reacting person was
  outside its tube (by the exact distance to its recorded positions within tau; the target: 0), the
  tube's clips, goals reached.
- ``step``: one env.step (drl_arena with 10 people walking 60 s, random actions, resets not timed) without
  people, with 10 impassive and with 10 reacting (regular) people, in interleaved rounds; medians.
  Target: reacting people cost at most 1.3x a step without people.
- ``certificate``: on the 20 x 20 m, 50-obstacle, 20-people world of bench_people, the timed path found
  against the recorded lines and against every person's regular tube (the same walk), beside the whole
  generation of that world. Target: the tube adds at most 20 % to the world's generation.

Pinned to one core (--all-cores to not pin). The table goes to stdout, the figures to
benchmarks/results/reacting.json.
"""

from __future__ import annotations

import argparse
import json
import os
import platform
import statistics
import time
from pathlib import Path

import numpy as np

RESULTS = Path(__file__).resolve().parent / "results" / "reacting.json"
KINDS = ("regular", "surprised", "scared", "curious", "impassive,regular,surprised,scared,curious")
PRESETS = ("person_crossing", "person_overtaking", "group_in_corridor", "person_in_doorway")
CROWD = {"size": [8.0, 8.0], "n_obstacles": 4, "n_people": 5, "people_duration": 12.0}


def episodes(n: int) -> dict:
    import gymnasium

    import worldgen.envs  # noqa: F401  (registers the environment)
    from worldgen.envs.policies import drive_timed
    from worldgen.people.behaviours import tube_distance

    envs = {}
    out = {"episodes": 0, "contacts": 0, "reached": 0, "outside_steps": 0, "steps_checked": 0, "clips": 0,
           "worst_outside_m": -1.0, "failed": []}
    t0 = time.perf_counter()
    for k in range(n):
        kind, where = KINDS[k % len(KINDS)], (PRESETS + ("crowd",))[(k // len(KINDS)) % (len(PRESETS) + 1)]
        key = (kind, where)
        if key not in envs:
            settings: dict = {}  # the environment's defaults: the timed path is drivable within them
            if where == "crowd":
                envs[key] = gymnasium.make("worldgen/Navigation-v0", generator="cluttered",
                                           params=dict(CROWD, people_behaviour=kind), **settings)
            else:
                envs[key] = gymnasium.make("worldgen/Navigation-v0", preset=where, params={"people_behaviour": kind},
                                           **settings)
        env = envs[key]
        info = drive_timed(env, seed=k)
        out["episodes"] += 1
        people = [c for c in info["collisions"] if c["entity"].startswith("person_")]
        out["contacts"] += len(people)
        out["reached"] += int(info["reached_goal"])
        out["clips"] += sum(info.get("people_clips", {}).values())
        movers = {m["name"]: m for m in env.unwrapped.world.movers if m.get("behaviour")}
        for name, rows in env.unwrapped.episode.walkers.reacted.items():
            p = movers[name]
            dist = tube_distance(rows[:, 1:], rows[:, 0], np.asarray(p["trajectory"], dtype=float), p["tube"]["tau"])
            outside = dist - p["tube"]["d"]
            out["outside_steps"] += int((outside > 1e-9).sum())
            out["steps_checked"] += len(rows)
            out["worst_outside_m"] = max(out["worst_outside_m"], float(outside.max()))
        if people or not info["reached_goal"]:
            out["failed"].append({"episode": k, "behaviour": kind, "world": where, "contacts": people,
                                  "reached": info["reached_goal"]})
    out["seconds"] = round(time.perf_counter() - t0, 1)
    return out


def step_cost(steps: int, rounds: int = 5) -> dict:
    import gymnasium

    import worldgen.envs  # noqa: F401

    variants = {"none": None, "impassive": {"n_people": 10, "people_duration": 60.0},
                "reacting": {"n_people": 10, "people_duration": 60.0, "people_behaviour": "regular"}}
    envs = {}
    for name, params in variants.items():
        env = gymnasium.make("worldgen/Navigation-v0", preset="drl_arena", params=params, time_limit_factor=None)
        for seed in range(50):  # the first seed whose world has a certificate among the reacting people
            try:
                env.reset(seed=seed)
                break
            except Exception:  # noqa: BLE001  (InfeasibleError: try the next world)
                continue
        envs[name] = (env, seed)
    times: dict = {name: [] for name in variants}
    rng = np.random.default_rng(0)
    for _ in range(rounds):
        for name, (env, seed) in envs.items():
            actions = rng.uniform(env.action_space.low, env.action_space.high, size=(steps, 2)).astype(np.float32)
            for a in actions:
                t = time.perf_counter()
                _, _, terminated, truncated, _ = env.step(a)
                times[name].append(time.perf_counter() - t)
                if terminated or truncated:
                    env.reset(seed=seed)
    med = {name: statistics.median(v) * 1e6 for name, v in times.items()}
    return {"median_us": {k: round(v, 1) for k, v in med.items()},
            "reacting_over_none": round(med["reacting"] / med["none"], 3),
            "reacting_over_impassive": round(med["reacting"] / med["impassive"], 3),
            "steps_each": len(times["none"])}


def certificate(worlds: int) -> dict:
    import worldgen
    from worldgen.people.behaviours import TUBES
    from worldgen.people.timed import timed_path

    rows = []
    for seed in range(worlds):
        t = time.perf_counter()
        world = worldgen.generate("cluttered", seed, size=[20.0, 20.0], n_obstacles=50, n_people=20,
                                  people_duration=60.0, people_behaviour="regular")
        whole = time.perf_counter() - t
        people = [m for m in world.scene.movers if m.person]
        tracks = [np.asarray(m.trajectory, dtype=float) for m in people]
        radii = [m.radius for m in people]
        path = world.feasibility.paths[0].waypoints
        cost = {}
        for name, tubes in (("line", None), ("tube", [TUBES["regular"]] * len(people))):
            t = time.perf_counter()
            timed_path(path, tracks, radii, world.robot.inflation, world.params["robot_speed"], tubes)
            cost[name] = time.perf_counter() - t
        rows.append((whole, cost["line"], cost["tube"], world.attempts))
    whole, line, tube, attempts = (statistics.median(c) for c in zip(*rows))
    return {"generate_ms": round(whole * 1e3, 1), "certificate_line_ms": round(line * 1e3, 1),
            "certificate_tube_ms": round(tube * 1e3, 1),
            "tube_adds_share_of_generation": round((tube - line) / whole, 3), "worlds": worlds,
            "median_attempts": attempts}


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--episodes", type=int, default=1000)
    ap.add_argument("--steps", type=int, default=400)
    ap.add_argument("--worlds", type=int, default=9)
    ap.add_argument("--all-cores", action="store_true")
    ap.add_argument("--only", choices=("episodes", "step", "certificate"))
    args = ap.parse_args()
    if not args.all_cores and hasattr(os, "sched_setaffinity"):
        os.sched_setaffinity(0, {min(os.sched_getaffinity(0))})
    out: dict = {"machine": platform.machine(), "python": platform.python_version(), "loadavg": os.getloadavg()}
    if args.only in (None, "step"):
        out["step"] = step_cost(args.steps)
        print("step", json.dumps(out["step"]))
    if args.only in (None, "certificate"):
        out["certificate"] = certificate(args.worlds)
        print("certificate", json.dumps(out["certificate"]))
    if args.only in (None, "episodes"):
        out["episodes"] = episodes(args.episodes)
        print("episodes", json.dumps({k: v for k, v in out["episodes"].items() if k != "failed"}),
              f"failed: {out['episodes']['failed'][:5]}")
    RESULTS.parent.mkdir(parents=True, exist_ok=True)
    name = RESULTS if args.only is None else RESULTS.with_name(f"reacting_{args.only}.json")
    name.write_text(json.dumps(out, indent=2) + "\n")


if __name__ == "__main__":
    main()
