"""The long fuzz sweep: every generator over its whole parameter ranges, each request in a child process.

    make fuzz                      # or: .venv/bin/python benchmarks/fuzz_sweep.py [--per-generator N] [--seed S]

tests/test_fuzz.py runs a derandomised few hundred requests with the slow ends
of a few ranges capped (sizes, counts, ray counts) to stay inside the CI
budget; this sweep draws the same way over the full ranges, with a longer time
limit per request, and prints per generator how requests ended (a world that
passed the re-check, one WorldgenError line, or a defect: bug, crash, timeout)
and how long they took. Defects are listed with their requests, so each is a
reproducer. Figures also go to benchmarks/results/fuzz.json.
"""

from __future__ import annotations

import argparse
import collections
import json
import statistics
import sys
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "tests"))

import numpy as np  # noqa: E402
from support.fuzzing import draw_request, run_requests  # noqa: E402

from worldgen.generators import names  # noqa: E402

RESULTS = Path(__file__).resolve().parent / "results" / "fuzz.json"


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--per-generator", type=int, default=250)
    ap.add_argument("--seed", type=int, default=1)
    ap.add_argument("--jobs", type=int, default=2)
    ap.add_argument("--timeout", type=float, default=300.0, help="seconds one request may take")
    args = ap.parse_args()
    rng = np.random.default_rng(args.seed)
    requests = [draw_request(rng, g, caps={}, floors={}) for g in names() for _ in range(args.per_generator)]
    start = time.perf_counter()
    outcomes = run_requests(requests, jobs=args.jobs, timeout=args.timeout)
    took = time.perf_counter() - start
    rows = []
    print(f"{'generator':<10} {'requests':>8} {'world':>6} {'error':>6} {'bug':>4} {'crash':>5} {'timeout':>7} "
          f"{'median s':>8} {'max s':>7}")
    for g in names():
        mine = [o for o in outcomes if o.request["generator"] == g]
        kinds = collections.Counter(o.kind for o in mine)
        secs = [o.seconds for o in mine]
        row = {"generator": g, "requests": len(mine), **{k: kinds.get(k, 0) for k in
               ("world", "error", "bug", "crash", "timeout")},
               "median_s": statistics.median(secs), "max_s": max(secs)}
        rows.append(row)
        print(f"{g:<10} {row['requests']:>8} {row['world']:>6} {row['error']:>6} {row['bug']:>4} {row['crash']:>5} "
              f"{row['timeout']:>7} {row['median_s']:>8.3f} {row['max_s']:>7.1f}")
    defects = [{"kind": o.kind, "request": o.request, "detail": o.detail} for o in outcomes if not o.ok]
    print(f"{len(requests)} requests in {took:.0f} s with {args.jobs} workers; {len(defects)} defects")
    for d in defects:
        print(f"  {d['kind']}: {json.dumps(d['request'])} -> {d['detail'][:300]}")
    slowest = sorted(outcomes, key=lambda o: -o.seconds)[:5]
    print("slowest requests:")
    for o in slowest:
        print(f"  {o.seconds:7.1f} s {o.kind}: {json.dumps(o.request)} -> {o.detail[:120]}")
    RESULTS.parent.mkdir(exist_ok=True)
    RESULTS.write_text(json.dumps({"seed": args.seed, "seconds": took, "rows": rows, "defects": defects,
                                  "slowest": [{"seconds": o.seconds, "kind": o.kind, "request": o.request} for o in slowest]},
                                  indent=2, sort_keys=True) + "\n")
    return 1 if defects else 0


if __name__ == "__main__":
    sys.exit(main())
