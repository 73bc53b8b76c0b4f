"""`worldgen judge` throughput and memory (issue 18's targets).

    .venv/bin/python benchmarks/bench_judge.py [--batches 10,100,1000] [--repeats 15]

The bag: a 60 s run at 20 Hz in a default cluttered world, as a Gazebo + nav2 run records it: /clock,
/odom, /tf (odom -> base_footprint every sample, map -> odom on /tf_static), /cmd_vel and /scan (360
exact lidar ranges from the world's ground truth, worldgen.groundtruth.lidar), mcap storage, Jazzy
definitions. The robot drives the reference path at 0.5 m/s and stands at the goal until 60 s.

- time: one bag judged end to end in this process, pinned to one core: read (streamed), figures,
  evaluate, and the report folder (json, csv, md, the picture); median of --repeats after one warm-up;
  the first bag of a fresh process (imports and rosbags' generated deserialisers included) beside it.
- memory: for each batch size N, a fresh process judges N bags (the bag under N names) into one report
  folder and reports its peak RSS (ru_maxrss); the slope between the smallest and largest batch is
  the memory one more bag costs.

Prints a table with each target met or missed; writes benchmarks/results/judge.json.
"""

from __future__ import annotations

import argparse
import json
import math
import os
import resource
import shutil
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT))

TIME_TARGET = 0.2   # s per 60 s, 20 Hz bag, end to end, one core
CRITERIA = {"navigation": {"success_rate": 0.95, "path_efficiency": 1.3}, "safety": {"collision_tolerance": 0}}


def make_bag(root: Path) -> tuple[Path, Path]:
    import worldgen
    from worldgen.groundtruth import lidar
    from worldgen.ros import write_run

    world = worldgen.generate("cluttered", seed=0)
    folder = Path(world.write(root / "worlds"))
    task = world.metadata["tasks"][0]
    wp = np.asarray(task["path"]["waypoints"], dtype=float)[:, :2]
    s = np.concatenate([[0.0], np.cumsum(np.hypot(*np.diff(wp, axis=0).T))])
    t = np.arange(0.0, 60.0, 0.05)
    along = np.minimum(t * 0.5, s[-1])
    x, y = np.interp(along, s, wp[:, 0]), np.interp(along, s, wp[:, 1])
    seg = np.searchsorted(s, along, side="right").clip(1, len(wp) - 1) - 1
    d = np.diff(wp, axis=0)
    yaw = np.unwrap(np.arctan2(d[:, 1], d[:, 0]))[seg]
    traj = np.column_stack([t, x, y, yaw])
    angles = np.linspace(-math.pi, math.pi, 360, endpoint=False)

    def scan(px, py, pyaw):
        dirs = np.column_stack([np.cos(angles + pyaw), np.sin(angles + pyaw), np.zeros_like(angles)])
        r = lidar.cast(world.scene, np.array([px, py, 0.2]), dirs, 0.05)
        return np.minimum(r, 12.0)

    spawn = task["spawn"]
    bag = write_run(root / "bag", traj, spawn=(spawn[0], spawn[1], spawn[5]), topics=("clock", "odom", "tf", "cmd_vel", "scan"),
                    scan=scan, world_id=world.world_id, task=task["id"])
    return bag, folder


def time_one(bag: Path, world: Path, repeats: int) -> dict:
    from worldgen.judge import judge, write_report

    out = bag.parent / "timing" / "report"

    def once() -> tuple[float, float]:
        t0 = time.perf_counter()
        result = judge([bag], CRITERIA, world=world)
        t1 = time.perf_counter()
        write_report(result, out)
        return t1 - t0, time.perf_counter() - t0

    once()  # warm: imports, rosbags' generated deserialisers (the cold start is measured in a fresh process)
    runs = [once() for _ in range(repeats)]
    return {"judge_s": statistics.median(r[0] for r in runs),
            "end_to_end_s": statistics.median(r[1] for r in runs), "repeats": repeats}


def _rss_now_kib() -> int:
    """The resident set now (VmRSS, KiB): what the process holds, where ru_maxrss is the highest it ever held."""
    for line in Path("/proc/self/status").read_text().splitlines():
        if line.startswith("VmRSS:"):
            return int(line.split()[1])
    return 0


def batch_child(bag: str, world: str, n: int, out: str) -> None:
    """In a fresh process: judge the bag under n names; print peak RSS (KiB), seconds, and the first bag's
    seconds counted from before worldgen.ros is imported (the cold start), as JSON."""
    names = Path(out) / "bags"
    names.mkdir(parents=True)
    for i in range(n):
        os.symlink(bag, names / f"run{i:05d}")
    t0 = time.perf_counter()
    from worldgen.judge import judge, write_report

    first: list[float] = []
    first_rss: list[int] = []

    def tick(k: int) -> None:
        if k == 1:
            first.append(time.perf_counter() - t0)
            first_rss.append(_rss_now_kib())

    result = judge(sorted(names.iterdir()), CRITERIA, world=world, progress=tick)
    write_report(result, Path(out) / "report")
    print(json.dumps({"n": n, "peak_rss_kib": resource.getrusage(resource.RUSAGE_SELF).ru_maxrss,
                      "rss_end_kib": _rss_now_kib(), "rss_after_first_kib": first_rss[0],
                      "seconds": time.perf_counter() - t0, "first_bag_cold_s": first[0], "passed": result.passed}))


def main() -> int:
    ap = argparse.ArgumentParser()
    ap.add_argument("--batches", default="10,100,1000")
    ap.add_argument("--repeats", type=int, default=15)
    ap.add_argument("--child", nargs=4, help=argparse.SUPPRESS)
    args = ap.parse_args()
    if hasattr(os, "sched_setaffinity"):
        os.sched_setaffinity(0, {sorted(os.sched_getaffinity(0))[0]})
    if args.child:
        batch_child(args.child[0], args.child[1], int(args.child[2]), args.child[3])
        return 0
    root = Path(tempfile.mkdtemp(prefix="bench-judge-"))
    try:
        return run(root, args)
    finally:
        shutil.rmtree(root, ignore_errors=True)


def run(root: Path, args) -> int:
    bag, world = make_bag(root)
    size = sum(p.stat().st_size for p in bag.iterdir())
    timing = time_one(bag, world, args.repeats)
    batches = []
    for n in (int(v) for v in args.batches.split(",")):
        child = subprocess.run([sys.executable, __file__, "--child", str(bag), str(world), str(n), str(root / f"batch{n}")],
                               capture_output=True, text=True, check=True, env=os.environ | {"PYTHONPATH": str(ROOT)})
        batches.append(json.loads(child.stdout.strip().splitlines()[-1]))
    first, last = batches[0], batches[-1]
    slope = (last["peak_rss_kib"] - first["peak_rss_kib"]) / max(last["n"] - first["n"], 1)
    held = (last["rss_end_kib"] - first["rss_end_kib"]) / max(last["n"] - first["n"], 1)
    print(f"bag: 60 s at 20 Hz, /clock /odom /tf /tf_static /cmd_vel /scan (360 rays), mcap, {size / 1e6:.2f} MB")
    print(f"{'measure':<44} {'value':>10}")
    print(f"{'judge (read + figures + evaluate), median s':<44} {timing['judge_s']:>10.4f}")
    print(f"{'end to end with the report folder, median s':<44} {timing['end_to_end_s']:>10.4f}")
    print(f"{'first bag in a fresh process (imports), s':<44} {first['first_bag_cold_s']:>10.4f}")
    for b in batches:
        label = f"batch of {b['n']}: peak / end RSS MiB, seconds"
        print(f"{label:<44} {b['peak_rss_kib'] / 1024:>10.1f} / {b['rss_end_kib'] / 1024:.1f}, {b['seconds']:.1f}")
    print(f"{'peak RSS per extra bag, KiB':<44} {slope:>10.2f}")
    print(f"{'RSS held at the end per extra bag, KiB':<44} {held:>10.2f}")
    met = timing["end_to_end_s"] <= TIME_TARGET
    print(f"target: end to end <= {TIME_TARGET} s: {'met' if met else 'missed'} ({timing['end_to_end_s']:.3f} s)")
    print(f"target: memory does not grow with the batch: peak RSS {first['peak_rss_kib'] / 1024:.1f} MiB at {first['n']} bags, "
          f"{last['peak_rss_kib'] / 1024:.1f} MiB at {last['n']} ({slope:.2f} KiB peak, {held:.2f} KiB held per bag: "
          "the report's rows and the allocator's retention)")
    results = ROOT / "benchmarks" / "results"
    results.mkdir(parents=True, exist_ok=True)
    (results / "judge.json").write_text(json.dumps({"bag_bytes": size, "timing": timing, "batches": batches,
                                                    "rss_kib_per_bag": slope, "rss_held_kib_per_bag": held,
                                                    "time_target_s": TIME_TARGET,
                                                    "time_target_met": met}, indent=2, sort_keys=True) + "\n")
    return 0


if __name__ == "__main__":
    sys.exit(main())
