"""Timings of a 20 x 20 m terrain world with obstacles, on one core (issue 40's target: at most 100 ms).

    .venv/bin/python benchmarks/bench_terrain.py [--runs N] [--obstacles N]

Stages, each a median over seeds 0..N-1 (these machines are shared and noisy):
  generate   worldgen.generate("terrain", ...): the draw, the drivable set, the exact planner, FCL, the
             terrain check (the world as proven, before any file)
  mjcf       the MJCF with the terrain's pieces
  world      World.folder_blobs(): every file of the folder in memory (SDF, MJCF, URDF, world.json with
             its ground truth, the map, preview.png)
The target is read against ``generate`` (a proven world); ``world`` is what writing it all costs on top.
Pin one core with ``taskset -c 0`` to measure on one core. Figures go to stdout and
benchmarks/results/terrain.json.
"""

from __future__ import annotations

import argparse
import json
import os
import platform
import statistics
import time
from pathlib import Path

import worldgen
from worldgen.export.mjcf import to_mjcf

RESULTS = Path(__file__).resolve().parent / "results" / "terrain.json"
TARGET_MS = 100.0


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--runs", type=int, default=20)
    parser.add_argument("--obstacles", type=int, default=30)
    args = parser.parse_args()
    params = {"size": [20, 20], "n_obstacles": args.obstacles, "n_ramps": 3, "n_kerbs": 4, "n_rough": 2}
    worldgen.generate("terrain", 0, **params)  # imports and first-use caches out of the timing
    times: dict[str, list[float]] = {"generate": [], "mjcf": [], "world": []}
    for seed in range(args.runs):
        t0 = time.perf_counter()
        world = worldgen.generate("terrain", seed, **params)
        t1 = time.perf_counter()
        to_mjcf(world.scene)
        t2 = time.perf_counter()
        world.folder_blobs()
        t3 = time.perf_counter()
        times["generate"].append(t1 - t0)
        times["mjcf"].append(t2 - t1)
        times["world"].append(t3 - t2)
    medians = {k: round(1000 * statistics.median(v), 2) for k, v in times.items()}
    worst = {k: round(1000 * max(v), 2) for k, v in times.items()}
    print(f"terrain 20 x 20 m, {args.obstacles} obstacles, 3 ramps, 4 kerbs/potholes, 2 rough patches; "
          f"{args.runs} seeds; cpu affinity {sorted(os.sched_getaffinity(0))}")
    for k in times:
        print(f"  {k:10s} median {medians[k]:8.2f} ms   worst {worst[k]:8.2f} ms")
    verdict = "within" if medians["generate"] <= TARGET_MS else "over"
    print(f"  target: generate <= {TARGET_MS:g} ms: {verdict}")
    RESULTS.parent.mkdir(exist_ok=True)
    RESULTS.write_text(json.dumps({"params": params, "runs": args.runs, "median_ms": medians, "worst_ms": worst,
                                   "target_ms": TARGET_MS, "python": platform.python_version()}, indent=1) + "\n")


if __name__ == "__main__":
    main()
