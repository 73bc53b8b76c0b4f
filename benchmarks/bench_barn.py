"""worldgen's exact metrics against BARN's own, and the speed of the BARN-compatible function.

    make bench                      # or: .venv/bin/python benchmarks/bench_barn.py [--worlds N] [--runs N]

Part 1, the comparison: --worlds worlds (default 40) of each generator, seeds 0..N-1: cluttered and
door with their defaults; corridor with its shape, width (0.8 to 2 m), obstacles and side openings
varied by the index (its defaults, one straight empty corridor, are one world whatever the seed);
minimal with its target kind, distance, bearing and walls varied by the index (its seed draws
nothing); barn cycling through BARN's own 12 settings (fill 0.15 to 0.30, 2 to 4 smoothing passes)
by the index. For each world, the milliseconds worldgen.generate took (generate_ms: generator,
refused draws and the exact check, no files), and the ratio BARN / worldgen of every metric, BARN's computed by
worldgen.groundtruth.barn_metrics (equal to BARN's own code, tests/groundtruth/test_barn.py) in
metres (cells x map_resolution), on two kinds of input:

  user   what a user comparing with BARN would feed it: the uninflated map (map.pgm), the reference
         path as an 8-connected chain of map cells, dispersion radius 4 inflation radii in cells (20)
  barn   world.json's metrics.barn: BARN's own inputs, the square-kernel C-space and radius 3

plus, for the closest distance on the user inputs, the difference BARN - worldgen in metres, and for
the barn inputs the share of path cells inside BARN's C-space walls. Medians, minima and maxima per
generator.

Part 2, the target (issue 23): barn_metrics on a 30 x 30 m map at 0.05 m (600 x 600 cells: a walled
cluttered room of 29.8 x 29.8 m inside 0.1 m walls, 120 obstacles) along a 300-cell path (the first
300 cells of its reference path's chain), C-space inputs and radius 3, median of --runs calls, pinned
to one core (--all-cores to not pin): target <= 50 ms.

The table goes to stdout, the figures to benchmarks/results/barn.json.
"""

from __future__ import annotations

import argparse
import json
import os
import platform
import statistics
import sys
import time
from pathlib import Path

RESULTS = Path(__file__).resolve().parent / "results" / "barn.json"
GENERATORS = ("cluttered", "corridor", "door", "minimal", "barn")
#: worldgen's name of each BARN metric, and whether it is a length (cells -> m).
PAIRS = {"closest_wall": ("closest_obstacle_distance_mean", True),
         "average_visibility": ("average_visibility", True),
         "dispersion": ("dispersion", False),
         "characteristic_dimension": ("characteristic_dimension", True),
         "tortuosity": ("tortuosity", False)}
TARGET_MS = 50.0


def minimal_params(i: int) -> dict:
    """A different minimal world per index (its seed draws nothing)."""
    return {"target": ("wall", "box", "cylinder")[i % 3], "target_distance": 1.0 + 0.4 * (i % 8),
            "target_bearing": round(((i * 37) % 61 - 30) / 10.0, 4), "walls": bool(i % 2)}


def corridor_params(i: int) -> dict:
    """Every corridor shape, widths from 0.8 m, some obstacles and side openings (defaults: none)."""
    return {"shape": ("straight", "L", "U", "zigzag")[i % 4], "width": (0.8, 1.2, 1.5, 2.0)[(i // 4) % 4],
            "n_obstacles": (0, 2, 4)[i % 3], "side_openings": i % 2}


def barn_params(i: int) -> dict:
    """BARN's 12 settings in turn: fill fraction 0.15 to 0.30 by 0.05, 2 to 4 smoothing passes."""
    return {"fill_fraction": (0.15, 0.2, 0.25, 0.3)[i % 4], "smoothing_passes": (2, 3, 4)[(i // 4) % 3]}


def compare(generator: str, seed: int) -> dict:
    import worldgen
    from worldgen.groundtruth import barn, truth

    params = {"minimal": minimal_params, "corridor": corridor_params, "barn": barn_params}.get(
        generator, lambda i: {})(seed)
    t0 = time.perf_counter()
    world = worldgen.generate(generator, seed=seed, **params)
    generate_ms = (time.perf_counter() - t0) * 1e3
    meta = world.metadata
    ours = meta["metrics"]
    grid = truth.occupancy_map(world)
    res = grid.resolution
    waypoints = world.feasibility.paths[0].waypoints
    radius = round(4 * world.robot.inflation / res)
    user = barn.barn_metrics(*barn.world_inputs(grid.occupied, grid.origin, res, world.robot.radius, waypoints,
                                                kernel=1), radius)
    cs, cells = barn.world_inputs(grid.occupied, grid.origin, res, world.robot.radius, waypoints)
    inside = float(cs[cells[:, 0], cells[:, 1]].mean())
    out: dict = {"generator": generator, "seed": seed, "params": params, "cells_in_cspace_walls": inside,
                 "closest_difference_m": float(user["closest_wall"] or 0.0) * res - ours["closest_obstacle_distance_mean"],
                 "generate_ms": generate_ms}
    for kind, values in (("user", user), ("barn", meta["metrics"]["barn"])):
        for name, (mine, length) in PAIRS.items():
            got = values[name]
            assert got is not None, (generator, seed, name)  # every world here has a path
            value = got * (res if length else 1.0)
            out[f"{kind}:{name}"] = value / ours[mine] if ours[mine] else None
    return out


def summarise(rows: list[dict]) -> dict:
    out = {}
    for generator in GENERATORS:
        mine = [r for r in rows if r["generator"] == generator]
        stats = {}
        for key in [k for k in mine[0] if ":" in k] + ["closest_difference_m", "cells_in_cspace_walls", "generate_ms"]:
            vals = [r[key] for r in mine if r[key] is not None]
            stats[key] = {"median": statistics.median(vals), "min": min(vals), "max": max(vals), "n": len(vals)}
        out[generator] = stats
    return out


def bench_speed(runs: int) -> dict:
    import worldgen
    from worldgen.groundtruth import barn, truth

    world = worldgen.generate("cluttered", seed=0, size=[29.8, 29.8], n_obstacles=120, min_spawn_goal_distance=20.0)
    grid = truth.occupancy_map(world)
    cs, cells = barn.world_inputs(grid.occupied, grid.origin, grid.resolution, world.robot.radius,
                                  world.feasibility.paths[0].waypoints)
    cells = cells[:300]
    times = []
    for _ in range(runs):
        t0 = time.perf_counter()
        barn.barn_metrics(cs, cells, barn.DISP_RADIUS)
        times.append(time.perf_counter() - t0)
    t_inputs = []
    for _ in range(max(3, runs // 5)):
        t0 = time.perf_counter()
        barn.world_inputs(grid.occupied, grid.origin, grid.resolution, world.robot.radius,
                          world.feasibility.paths[0].waypoints)
        t_inputs.append(time.perf_counter() - t0)
    return {"map_cells": list(grid.occupied.shape), "cspace_cells": list(cs.shape), "path_cells": len(cells),
            "runs": runs, "median_ms": round(statistics.median(times) * 1e3, 3),
            "min_ms": round(min(times) * 1e3, 3), "inputs_median_ms": round(statistics.median(t_inputs) * 1e3, 3),
            "target_ms": TARGET_MS, "met": statistics.median(times) * 1e3 <= TARGET_MS}


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--worlds", type=int, default=40, help="worlds per generator (default 40)")
    ap.add_argument("--runs", type=int, default=50, help="timed calls of barn_metrics (default 50)")
    ap.add_argument("--all-cores", action="store_true", help="do not pin the process to one core")
    args = ap.parse_args(argv)
    if not args.all_cores and hasattr(os, "sched_setaffinity"):
        os.sched_setaffinity(0, {sorted(os.sched_getaffinity(0))[0]})  # the target is per core
    import worldgen

    rows = [compare(g, s) for g in GENERATORS for s in range(args.worlds)]
    summary = summarise(rows)
    speed = bench_speed(args.runs)
    print(f"BARN / worldgen, {args.worlds} worlds per generator: median [min, max]")
    print("user = uninflated map, chain, radius 4 inflation radii; barn = world.json metrics.barn (C-space, radius 3)")
    keys = [k for k in rows[0] if ":" in k]
    print(f"{'metric':<34}" + "".join(f"{g:>26}" for g in GENERATORS))
    for key in keys + ["closest_difference_m", "cells_in_cspace_walls", "generate_ms"]:
        cells = [summary[g][key] for g in GENERATORS]
        print(f"{key:<34}" + "".join(f"{c['median']:>9.3f} [{c['min']:6.3f},{c['max']:6.3f}]" for c in cells))
    print(f"\nbarn_metrics, {speed['cspace_cells'][0]} x {speed['cspace_cells'][1]} C-space of a "
          f"{speed['map_cells'][0]} x {speed['map_cells'][1]} map, {speed['path_cells']}-cell path: median "
          f"{speed['median_ms']} ms (min {speed['min_ms']}) over {speed['runs']} calls, "
          f"{'one core' if not args.all_cores else 'all cores'}; target <= {TARGET_MS:g} ms: "
          f"{'met' if speed['met'] else 'missed'}; inputs (C-space + chain) {speed['inputs_median_ms']} ms")
    results = {"worldgen_version": worldgen.__version__, "python": platform.python_version(),
               "machine": platform.machine(), "cpus": os.cpu_count(), "pinned_to_one_core": not args.all_cores,
               "worlds_per_generator": args.worlds, "summary": summary, "speed": speed, "worlds": rows}
    RESULTS.parent.mkdir(parents=True, exist_ok=True)
    tmp = RESULTS.with_suffix(".json.tmp")
    tmp.write_text(json.dumps(results, indent=2, sort_keys=True) + "\n")
    tmp.replace(RESULTS)
    print(f"\nfigures written to {RESULTS}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
