"""Per-stage timings of the whole pipeline for cluttered worlds.

    make bench                      # or: .venv/bin/python benchmarks/bench_pipeline.py [--runs N]

Each stage is timed with time.perf_counter over many seeds and reported as a
median (these machines are noisy: compare ratios within one run, not absolute
times across runs). Stages:
  build        the generator's draw (obstacles, spawn/goal) for the draw that passed
  feasibility  feasibility.check on that draw (planner + FCL verification)
  sdf/mjcf/urdf each exporter, Scene -> text
  metadata     world.json from the rendered files
  pipeline     generate() + all three formats + metadata, in memory (what an RL loop pays)
  usd          the USD exporter alone, Scene -> world.usda text (where usd-core is installed)
  pipeline_usd the pipeline with world.usda written too (generate() + four formats + metadata): the
               usd format's cost when asked for; "usd_share" = pipeline_usd / pipeline - 1
  floor        the serialisation floor for the same world, no planning: its three XML documents
               rebuilt element by element as lxml trees and serialised, plus json.dumps of world.json
               (the cost of merely writing what the pipeline writes); "ratio" = pipeline / floor
  write        World.write to a temporary folder (files + fsync + rename)
  lidar/occupancy/metrics  the ground truth parts (360 rays; the map as PGM + YAML; BARN metrics),
               groundtruth their sum (all are also inside pipeline and metadata)
Series "default" uses the generator's default obstacle sizes and robot; series
"scaling" uses small obstacles and a small robot so that 1000 obstacles still
fit in 20 x 20 m, to show how cost grows with the obstacle count.
The table goes to stdout, the figures to benchmarks/results/pipeline.json.
"""

from __future__ import annotations

import argparse
import json
import os
import platform
import statistics
import sys
import tempfile
import time
from pathlib import Path
from typing import Optional

import worldgen
from worldgen import feasibility
from worldgen.export.formats import FORMATS
from worldgen.export.usd_prims import usd_available
from worldgen.generators import get, robot_from_params
from worldgen.seeding import attempt_rng

RESULTS = Path(__file__).resolve().parent / "results" / "pipeline.json"

SERIES = {
    "default": ({"size": [20, 20]}, (10, 50, 200)),
    "scaling": (
        {"size": [20, 20], "box_size": [0.1, 0.25], "cylinder_radius": [0.05, 0.12], "min_gap": 0.05,
         "robot_radius": 0.1, "clearance": 0.02, "max_attempts": 200},
        (10, 50, 200, 1000),
    ),
}
STAGES = ("build", "feasibility", "sdf", "mjcf", "urdf", "metadata", "pipeline", "floor", "write",
          "lidar", "occupancy", "metrics", "groundtruth")
#: Stages timed only where usd-core is installed (the usd extra).
USD_STAGES = ("usd", "pipeline_usd")
#: Issue 32's target: writing USD adds at most this share to the pipeline, at (series, obstacles).
USD_TARGET = ("default", 50, 0.30)
#: Issues 9 and 30's targets: (series, obstacles) -> largest median pipeline ms, and pipeline / floor ratio
#: (issue 30: 10 ms and 5x at 50 obstacles, 5x at 200; issue 9's for 200 and 1000 obstacles stand).
PIPELINE_TARGETS = {("default", 50): 10.0, ("default", 200): 40.0, ("scaling", 1000): 250.0}
RATIO_TARGETS = {("default", 50): 5.0, ("default", 200): 5.0}
FEASIBILITY_TARGET = ("default", 50, 4.0)
SLOPE_TARGET = 1.2


#: The clock every stage is timed with: wall time, or with --cpu the process's CPU time (on a shared,
#: loaded machine CPU time leaves out the waits for a core that wall time counts).
_now = time.perf_counter


def _ms(seconds: float) -> float:
    return round(seconds * 1e3, 3)


def time_world(params: dict, seed: int, out_dir: Path) -> dict[str, float]:
    t = {}
    t0 = _now()
    world = worldgen.generate("cluttered", seed=seed, **params)
    files = world.rendered_files()
    world.metadata_for(files)
    t["pipeline"] = _now() - t0

    spec = get("cluttered")
    resolved = spec.resolve(params)
    rng = attempt_rng(seed, world.attempts - 1)
    t0 = _now()
    draft = spec.build(resolved, rng)
    t["build"] = _now() - t0
    t0 = _now()
    feasibility.check(draft.scene, draft.tasks, robot_from_params(resolved))
    t["feasibility"] = _now() - t0
    for fmt in ("sdf", "mjcf", "urdf"):
        t0 = _now()
        world._render(fmt, "1.9")  # export_bytes() would return the bytes the pipeline already rendered
        t[fmt] = _now() - t0
    t["floor"] = serialisation_floor(world, files)
    from worldgen.groundtruth import lidar, metrics, occupancy, truth
    truth._DIFFICULTY.pop(world, None)  # world.json's first build computes them: time that, not the remembered ones
    t0 = _now()
    world.metadata_for(files)
    t["metadata"] = _now() - t0
    # Ground truth (worldgen.groundtruth), each part alone and all three as world.json adds them
    # (map made and encoded as PGM + YAML): what issue 4 budgets at 15 ms for 50 obstacles.
    t0 = _now()
    lidar.describe(world.scene, truth.lidar_spec(world))
    t["lidar"] = _now() - t0
    t0 = _now()
    grid = occupancy.build(world.scene, world.params["map_height"], world.params["map_resolution"])
    grid.pgm(), grid.yaml()
    t["occupancy"] = _now() - t0
    t0 = _now()
    metrics.difficulty(world.scene, world.robot, world.tasks, world.feasibility.paths)
    t["metrics"] = _now() - t0
    t["groundtruth"] = t["lidar"] + t["occupancy"] + t["metrics"]
    t0 = _now()
    world.write(out_dir)
    t["write"] = _now() - t0
    t["attempts"] = world.attempts
    if usd_available():
        t0 = _now()
        world._render("usd", "1.9")
        t["usd"] = _now() - t0
        t0 = _now()
        again = worldgen.generate("cluttered", seed=seed, **params)
        again.metadata_for(again.rendered_files(FORMATS + ("usd",)))
        t["pipeline_usd"] = _now() - t0
    return t


def _rebuild(source, parent=None):
    """An lxml tree built element by element with the same tags, attributes and text as ``source``."""
    from lxml import etree

    element = etree.Element(source.tag, source.attrib) if parent is None else \
        etree.SubElement(parent, source.tag, source.attrib)
    element.text = source.text
    for child in source:
        if isinstance(child.tag, str):  # elements only: the skeletons' comments are not the scene
            _rebuild(child, element)
    return element


def serialisation_floor(world, files) -> float:
    """Seconds to build and serialise the world's three XML trees with lxml and its world.json, no planning.

    The JSON goes through the standard library's ``json.dumps`` (sorted keys, indented), the cheapest
    faithful serialisation, not worldgen's own canonical writer.
    """
    from worldgen.export.xml import parse_bytes, to_bytes

    sources = [parse_bytes(files[fmt][1]).getroot() for fmt in ("sdf", "mjcf", "urdf")]
    meta = world.metadata_for(files)
    t0 = _now()
    for source in sources:
        to_bytes(_rebuild(source))
    json.dumps(meta, sort_keys=True, indent=2)
    return _now() - t0


def loglog_slope(rows: dict) -> float:
    """Least-squares slope of log(pipeline ms) against log(obstacles)."""
    import math

    xs = [math.log(int(n)) for n in rows]
    ys = [math.log(row["pipeline"]) for row in rows.values()]
    mx, my = sum(xs) / len(xs), sum(ys) / len(ys)
    return sum((x - mx) * (y - my) for x, y in zip(xs, ys)) / sum((x - mx) ** 2 for x in xs)


def targets(results: dict) -> list[dict]:
    """Each of issue 9's targets with its measured figure and whether it is met."""
    series = results["series"]
    out = []
    for (name, n), limit in PIPELINE_TARGETS.items():
        got = series[name][str(n)]["pipeline"]
        out.append({"target": f"pipeline, {n} obstacles ({name})", "limit": limit, "measured": got,
                    "unit": "ms", "met": got <= limit})
    for (name, n), limit in RATIO_TARGETS.items():
        got = series[name][str(n)]["ratio"]
        out.append({"target": f"pipeline / floor, {n} obstacles ({name})", "limit": limit, "measured": got,
                    "unit": "x", "met": got <= limit})
    name, n, limit = FEASIBILITY_TARGET
    got = series[name][str(n)]["feasibility"]
    out.append({"target": f"feasibility alone, {n} obstacles ({name})", "limit": limit, "measured": got,
                "unit": "ms", "met": got <= limit})
    name, n, limit = USD_TARGET
    got = series[name][str(n)].get("usd_share")
    if got is not None:
        out.append({"target": f"pipeline with usd / without - 1, {n} obstacles ({name})", "limit": limit,
                    "measured": got, "unit": "", "met": got <= limit})
    got = results["slope"]
    out.append({"target": "log-log slope of pipeline cost vs obstacles (scaling, 10-1000)", "limit": SLOPE_TARGET,
                "measured": got, "unit": "", "met": got <= SLOPE_TARGET})
    return out


def run(runs: int, only: Optional[tuple[str, int]] = None) -> dict:
    results = {"worldgen_version": worldgen.__version__, "python": platform.python_version(),
               "machine": platform.machine(), "cpus": os.cpu_count(), "runs": runs, "series": {},
               "clock": "process_time" if _now is time.process_time else "perf_counter"}
    for series, (base, counts) in SERIES.items():
        rows = {}
        for n in counts:
            if only is not None and (series, n) != only:
                continue
            params = dict(base, n_obstacles=n)
            seeds = range(runs if n < 1000 else max(5, runs // 3))
            samples = []
            with tempfile.TemporaryDirectory() as tmp:
                time_world(params, 10_000, Path(tmp))  # warm-up: imports, caches
                for seed in seeds:
                    samples.append(time_world(params, seed, Path(tmp)))
            stages = STAGES + (USD_STAGES if "usd" in samples[0] else ())
            rows[str(n)] = {
                **{stage: _ms(statistics.median(s[stage] for s in samples)) for stage in stages},
                "ratio": round(statistics.median(s["pipeline"] / s["floor"] for s in samples), 2),
                "attempts_mean": round(statistics.mean(s["attempts"] for s in samples), 2),
                "worlds": len(samples),
                **({"usd_share": round(statistics.median(s["pipeline_usd"] / s["pipeline"] - 1 for s in samples), 3)}
                   if "usd" in samples[0] else {}),
            }
        if rows:
            results["series"][series] = rows
    if only is None:
        results["slope"] = round(loglog_slope(results["series"]["scaling"]), 3)
        results["targets"] = targets(results)
    return results


def print_table(results: dict) -> None:
    for series, rows in results["series"].items():
        print(f"\nseries '{series}' (median ms over {results['runs']} seeds; 1000 obstacles: fewer)")
        stages = STAGES + tuple(s for s in USD_STAGES if s in next(iter(rows.values())))
        print(f"{'obstacles':>9} " + " ".join(f"{s:>11}" for s in stages) + f" {'ratio':>6} {'attempts':>8} {'x per obst.':>11}")
        first = None
        for n, row in rows.items():
            first = first or (row["pipeline"], int(n))
            growth = (row["pipeline"] / first[0]) / (int(n) / first[1])
            print(f"{n:>9} " + " ".join(f"{row[s]:>11.2f}" for s in stages)
                  + f" {row['ratio']:>6.2f} {row['attempts_mean']:>8.2f} {growth:>11.2f}"
                  + (f"   usd adds {row['usd_share']:.1%}" if "usd_share" in row else ""))
        print("  'x per obst.': pipeline time ratio to the first row divided by the obstacle-count ratio"
              " (1.0 = linear, below 1 = sub-linear); 'ratio': pipeline / floor, median of per-world ratios")
    if "slope" not in results:
        return
    print(f"\nlog-log slope of pipeline cost against obstacle count (scaling series): {results['slope']:.3f}")
    print("\ntargets (issues 9, 30 and 32):")
    for t in results["targets"]:
        print(f"  {'met   ' if t['met'] else 'MISSED'} {t['target']:<66} {t['measured']:>8.2f} {t['unit']:<2}"
              f" (limit {t['limit']:g} {t['unit']})")


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--runs", type=int, default=30, help="seeds per configuration (default 30)")
    ap.add_argument("--all-cores", action="store_true", help="do not pin the process to one core")
    ap.add_argument("--cpu", action="store_true", help="time with the process's CPU time instead of wall time")
    ap.add_argument("--only", metavar="SERIES:N", help="one row only (e.g. default:50); no targets, no slope")
    args = ap.parse_args(argv)
    if not args.all_cores and hasattr(os, "sched_setaffinity"):
        os.sched_setaffinity(0, {sorted(os.sched_getaffinity(0))[0]})  # the targets are per core
    global _now
    if args.cpu:
        _now = time.process_time
    only = None
    if args.only:
        name, _, count = args.only.partition(":")
        only = (name, int(count))
    results = run(args.runs, only)
    results["pinned_to_one_core"] = not args.all_cores
    print_table(results)
    out = RESULTS if only is None else RESULTS.with_name(f"pipeline-{only[0]}-{only[1]}.json")
    out.parent.mkdir(parents=True, exist_ok=True)
    out.write_text(json.dumps(results, indent=2, sort_keys=True) + "\n")
    print(f"\nfigures written to {out}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
