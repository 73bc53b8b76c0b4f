"""Cost of a curriculum's reset in worldgen/Navigation-v0 against a plain reset of the same worlds.

    make bench          # or: .venv/bin/python benchmarks/bench_curriculum.py [--resets N]

Two pairs of environments (cluttered worlds, default settings but a 36-beam lidar), each reset N times
(default 60) alternately, timed with time.perf_counter around ``env.reset``:

  levels   ``difficulty="k/10"`` (plain) against ``curriculum=LevelCurriculum(start=k)``, k = 3, 6, 9 in
           turn, both ``reset(seed=s)``: the same seed gives both the same world, so the difference is
           the curriculum's bookkeeping alone (no episode is finished, so the level stays k)
  replay   ``generator="cluttered"`` (plain) against ``curriculum="replay"`` (defaults: half the resets
           replay a buffered level, half the rest edit one and re-prove it); after every reset both run
           their episode to its end standing still (not timed; ``time_limit_factor=0.1``) so that levels
           are scored and buffered; the replay's medians by kind (new, replay, edit) are shown too

Target (issue 19): a curriculum reset no slower than a plain reset plus 20 % (ratio of medians <= 1.2).
The table goes to stdout, the figures to benchmarks/results/curriculum.json.
"""

from __future__ import annotations

import argparse
import json
import os
import statistics
import sys
import time
from pathlib import Path

import numpy as np

RESULTS = Path(__file__).resolve().parent / "results" / "curriculum.json"
SETTINGS = {"generator": "cluttered", "lidar_beams": 36, "time_limit_factor": 0.1}
TARGET = 1.2


def _timed_reset(env, **kw) -> tuple[float, dict]:
    t0 = time.perf_counter()
    _, info = env.reset(**kw)
    return time.perf_counter() - t0, info


def _run_out(env) -> None:
    while True:
        _, _, terminated, truncated, _ = env.step(np.zeros(2, dtype=np.float32))
        if terminated or truncated:
            return


def bench_levels(resets: int) -> dict:
    import gymnasium

    from worldgen.envs.curriculum import LevelCurriculum

    plain, curriculum = [], []
    for level in (3, 6, 9):
        a = gymnasium.make("worldgen/Navigation-v0", difficulty=f"{level}/10", **SETTINGS).unwrapped
        b = gymnasium.make("worldgen/Navigation-v0", curriculum=LevelCurriculum(start=level), **SETTINGS).unwrapped
        a.reset(seed=0), b.reset(seed=0)  # warm-up
        for i in range(resets // 3):
            pair = [(a, plain), (b, curriculum)]
            for env, times in pair if i % 2 == 0 else pair[::-1]:
                dt, info = _timed_reset(env, seed=1000 + i)
                times.append(dt)
            assert a.world.world_id == b.world.world_id  # the same world: only the bookkeeping differs
    return _summary(plain, curriculum)


def bench_replay(resets: int) -> dict:
    import gymnasium

    a = gymnasium.make("worldgen/Navigation-v0", **SETTINGS).unwrapped
    b = gymnasium.make("worldgen/Navigation-v0", curriculum="replay", **SETTINGS).unwrapped
    plain, curriculum, kinds = [], [], {"new": [], "replay": [], "edit": []}
    for i in range(resets):
        order = [a, b] if i % 2 == 0 else [b, a]
        for env in order:
            dt, info = _timed_reset(env, seed=2000 + i)
            if env is a:
                plain.append(dt)
            else:
                curriculum.append(dt)
                kinds[info["level_kind"]].append(dt)
            _run_out(env)
    out = _summary(plain, curriculum)
    out["by_kind"] = {k: {"resets": len(v), "median_ms": round(statistics.median(v) * 1e3, 2) if v else None}
                      for k, v in kinds.items()}
    return out


def _summary(plain: list, curriculum: list) -> dict:
    p, c = statistics.median(plain), statistics.median(curriculum)
    return {"resets": len(plain), "plain_median_ms": round(p * 1e3, 2), "curriculum_median_ms": round(c * 1e3, 2),
            "ratio": round(c / p, 3), "met": c <= TARGET * p}


def main(argv=None) -> int:
    import worldgen.envs  # noqa: F401  (registers the id)

    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--resets", type=int, default=60)
    args = ap.parse_args(argv)
    results = {"levels": bench_levels(args.resets), "replay": bench_replay(args.resets)}
    print(f"{'curriculum':10s} {'resets':>6s} {'plain ms':>9s} {'curriculum ms':>14s} {'ratio':>6s}  target <= {TARGET}")
    for name, r in results.items():
        print(f"{name:10s} {r['resets']:6d} {r['plain_median_ms']:9.2f} {r['curriculum_median_ms']:14.2f} "
              f"{r['ratio']:6.3f}  {'met' if r['met'] else 'MISSED'}")
    print("replay by kind: " + ", ".join(f"{k} {v['resets']} x {v['median_ms']} ms"
                                         for k, v in results["replay"]["by_kind"].items()))
    results["machine"] = {"cpus": os.cpu_count(), "load_1min": round(os.getloadavg()[0], 2)}
    RESULTS.parent.mkdir(exist_ok=True)
    tmp = RESULTS.with_suffix(".tmp")
    tmp.write_text(json.dumps(results, indent=1) + "\n")
    tmp.replace(RESULTS)
    return 0 if all(r["met"] for k, r in results.items() if k != "machine") else 1


if __name__ == "__main__":
    sys.exit(main())
