"""Campaigns (issue 36): how fast each strategy finds distinct failures, and what a campaign costs per run.

    .venv/bin/python benchmarks/bench_campaign.py [--seeds 10] [--cap 600] [--runs 200] [--episodes 5] [--ribs]

Part 1, the search: a planted weakness that fails only in one corner of a five-dimension space (cluttered
8 x 8 m rooms, n_obstacles 0-30, n_people 0-2, robot_radius 0.15-0.3 m, obstacle_shapes box, cylinder or
mixed; it fails when n_obstacles >= 24, a person is there and the robot radius is >= 0.26 m: about 4 % of
the space). The failure is decided from the point itself (no world is built: what is compared is how many
runs each strategy spends), and two failures are distinct when their cells differ: obstacle band of 2,
people count, radius band of 0.01 m. For each strategy, runs until the 10th distinct failure (--cap when it
never gets there), over --seeds seeds; median. Target: adaptive or coverage at most a third of random's.
With --ribs (pip install ribs), the quality-diversity alternative the coverage strategy was chosen against:
pyribs' MAP-Elites (a GridArchive over the cells, two GaussianEmitters of 8 in [0, 1]^4, sigma 0.3, the best
of 0.1 / 0.2 / 0.3 measured) asked and told the same way, the objective 1 for a failure, 0 for a pass.

Part 2, the campaign's own cost per run: a sequential campaign's loop without the world and the system
(Strategy.ask and tell, the point's two records written atomically, the progress log), per run over --runs
runs of the adaptive strategy, against the median wall time of --episodes MuJoCo episodes of the shipped
GapHeuristic on a level-5 cluttered world run as a campaign runs it (worldgen.campaign.systems, policy
GapHeuristic.for_env, the bag recorded and judged). Target: at most 5 %.

The table goes to stdout, the figures to benchmarks/results/campaign.json. Not part of the test suite.
"""

from __future__ import annotations

import argparse
import json
import logging
import os
import platform
import statistics
import sys
import tempfile
import time
from pathlib import Path

from worldgen.campaign.output import save_asked, save_record
from worldgen.campaign.recipe import parse_campaign
from worldgen.campaign.strategies import Strategy

SPACE = """\
space:
  - generator: cluttered
    params:
      size: [8, 8]
      n_obstacles: {min: 0, max: 30}
      n_people: {min: 0, max: 2}
      robot_radius: {min: 0.15, max: 0.3}
      obstacle_shapes: [box, cylinder, mixed]
budget: {runs: 1}
"""
DISTINCT = 10
TARGET_RATIO, TARGET_COST = 1 / 3, 0.05


def _fails(params: dict) -> bool:
    return params["n_obstacles"] >= 24 and params.get("n_people", 0) >= 1 and params["robot_radius"] >= 0.26


def _cell(params: dict) -> tuple:
    return params["n_obstacles"] // 2, params.get("n_people", 0), int(params["robot_radius"] * 100)


def runs_to_distinct(name: str, seed: int, cap: int, entries) -> int:
    """Runs ``name`` spends until DISTINCT distinct failures (``cap`` when it never gets there)."""
    strategy = Strategy(name, seed, entries)
    found: set = set()
    for k in range(cap):
        point, search = strategy.ask()
        params = point.param_dict
        failed = _fails(params)
        if failed:
            found.add(_cell(params))
        strategy.tell(point.index, search, "failed" if failed else "passed", _cell(params))
        if len(found) >= DISTINCT:
            return k + 1
    return cap


def ribs_runs_to_distinct(seed: int, cap: int, sigma: float = 0.3) -> int:
    """Runs pyribs' MAP-Elites spends until DISTINCT distinct failures on the same corner."""
    import numpy as np
    from ribs.archives import GridArchive
    from ribs.emitters import GaussianEmitter
    from ribs.schedulers import Scheduler

    archive = GridArchive(solution_dim=4, dims=[16, 3, 16], ranges=[(0, 31), (0, 3), (15, 31)], seed=seed)
    emitters = [GaussianEmitter(archive, sigma=sigma, x0=np.full(4, 0.5), batch_size=8, seed=seed + 1000 * k,
                                bounds=[(0, 1)] * 4) for k in range(2)]
    scheduler = Scheduler(archive, emitters)
    found: set = set()
    spent = 0
    while spent < cap:
        objectives, measures = [], []
        for x in scheduler.ask():
            x = np.clip(x, 0, 1)
            params = {"n_obstacles": int(round(x[0] * 30)), "n_people": int(round(x[1] * 2)),
                      "robot_radius": 0.15 + 0.15 * float(x[2])}
            spent += 1
            failed = _fails(params)
            if failed:
                found.add(_cell(params))
            if len(found) >= DISTINCT:
                return spent
            objectives.append(1.0 if failed else 0.0)
            measures.append([params["n_obstacles"], params["n_people"], 100 * params["robot_radius"]])
        scheduler.tell(np.array(objectives), np.array(measures))
    return cap


def loop_cost(runs: int, entries) -> float:
    """Seconds per run of the campaign's own loop (no world, no system)."""
    log = logging.getLogger("worldgen.progress")
    with tempfile.TemporaryDirectory(prefix="bench-campaign-") as tmp:
        out = Path(tmp)
        (out / ".campaign").mkdir()
        strategy = Strategy("adaptive", 0, entries)
        start = time.perf_counter()
        for _ in range(runs):
            point, search = strategy.ask()
            save_asked(out, point.as_dict(), search)
            failed = _fails(point.param_dict)
            rec = {"point": point.as_dict(), "search": search, "world_id": "w", "folder": "worlds/w", "reason": "",
                   "descriptors": {}, "cell": list(_cell(point.param_dict)), "verdict": "failed" if failed else "passed",
                   "runs": [{"task": "task_0", "run": "p0", "verdict": "passed", "reason": "", "row": {}, "seconds": 0.0}],
                   "seconds": 0.0}
            save_record(out, rec)
            strategy.tell(point.index, search, rec["verdict"], tuple(rec["cell"]))
            log.info("campaign bench: %d runs", point.index + 1)
        return (time.perf_counter() - start) / runs


def episode_seconds(episodes: int) -> float:
    """Median wall time of a GapHeuristic MuJoCo episode as a campaign runs it."""
    import worldgen
    from worldgen.campaign.systems import system_from_spec

    system = system_from_spec({"policy": "worldgen.envs.policies:GapHeuristic.for_env"})
    with tempfile.TemporaryDirectory(prefix="bench-campaign-") as tmp:
        folder = worldgen.generate("cluttered", seed=0, difficulty="5/10").write(Path(tmp) / "worlds", preview=False)
        system.run(folder, "task_0", "warm", Path(tmp) / "warm")  # the first run pays for its imports
        times = []
        for k in range(episodes):
            start = time.perf_counter()
            system.run(folder, "task_0", f"r{k}", Path(tmp) / f"r{k}")
            times.append(time.perf_counter() - start)
    return statistics.median(times)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--seeds", type=int, default=10)
    ap.add_argument("--cap", type=int, default=600)
    ap.add_argument("--runs", type=int, default=200)
    ap.add_argument("--episodes", type=int, default=5)
    ap.add_argument("--ribs", action="store_true", help="also measure pyribs' MAP-Elites on the same corner")
    args = ap.parse_args()
    entries = parse_campaign(SPACE).entries
    search = {}
    for name in ("random", "adaptive", "coverage"):
        spent = [runs_to_distinct(name, seed, args.cap, entries) for seed in range(args.seeds)]
        search[name] = {"runs": spent, "median": statistics.median(spent)}
        print(f"{name:9s} runs to {DISTINCT} distinct failures: median {statistics.median(spent):g} "
              f"(seeds 0-{args.seeds - 1}: {spent}; cap {args.cap})", flush=True)
    if args.ribs:
        spent = [ribs_runs_to_distinct(seed, args.cap) for seed in range(args.seeds)]
        search["ribs_map_elites"] = {"runs": spent, "median": statistics.median(spent)}
        print(f"ribs MAP-Elites runs to {DISTINCT} distinct failures: median {statistics.median(spent):g} ({spent})")
    best = min(search["adaptive"]["median"], search["coverage"]["median"])
    ratio = best / search["random"]["median"]
    cost = loop_cost(args.runs, entries)
    episode = episode_seconds(args.episodes)
    share = cost / episode
    targets = [
        {"target": "adaptive or coverage runs to 10 distinct failures / random's", "limit": TARGET_RATIO,
         "measured": round(ratio, 3), "met": ratio <= TARGET_RATIO},
        {"target": "campaign's own cost per run / a GapHeuristic MuJoCo episode", "limit": TARGET_COST,
         "measured": round(share, 4), "met": share <= TARGET_COST},
    ]
    print(f"best adaptive/coverage median / random median: {ratio:.2f} (target <= {TARGET_RATIO:.2f}): "
          f"{'met' if targets[0]['met'] else 'MISSED'}")
    print(f"campaign loop {1000 * cost:.1f} ms a run (adaptive, {args.runs} runs); GapHeuristic episode "
          f"{episode:.3f} s (median of {args.episodes}); share {100 * share:.1f} % (target <= 5 %): "
          f"{'met' if targets[1]['met'] else 'MISSED'}")
    result = {"cpus": os.cpu_count(), "python": platform.python_version(), "load_average": os.getloadavg(),
              "search": search, "loop_seconds_per_run": cost, "episode_seconds": episode, "targets": targets}
    target = Path(__file__).parent / "results" / "campaign.json"
    target.parent.mkdir(exist_ok=True)
    target.write_text(json.dumps(result, indent=2, sort_keys=True) + "\n")
    if not all(t["met"] for t in targets):
        sys.exit("a target was missed")


if __name__ == "__main__":
    main()
