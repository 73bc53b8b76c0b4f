"""The difficulty ladder: the reactive probe's success at each level 1..10, per generator.

    make bench          # or: nice -n 10 .venv/bin/python benchmarks/bench_ladder.py [--seeds N] [--end-seeds M]
                        #     [--only NAME ...]

For each configuration of :data:`CONFIGS` (or those whose name starts with an ``--only``) and each level
1..10 it asked for, request seeds 0..N-1 (default 16), at levels 1 and 5 0..M-1 (default 44: the seeds of
tests/envs/test_ladder.py, which the intervals of levels 1 and 5 need to be apart): ``worldgen.generate(generator, seed,
difficulty=level, **params)``, then the reactive probe drives the first task in
worldgen/Navigation-v0 (worldgen.envs.ladder). Reported per level: worlds, successes, rate, 95 %
Wilson interval; per configuration: Spearman's rho of rate with level. Targets (issue 19): rho <=
-0.9; level 1 >= 0.9, level 10 <= 0.2; levels 1, 5 and 10 with disjoint intervals. The table goes to
stdout, the figures to benchmarks/results/ladder.json.
"""

from __future__ import annotations

import argparse
import json
import sys
import time
from pathlib import Path

RESULTS = Path(__file__).resolve().parent / "results" / "ladder.json"
BARN_ROOM = {"size": [5, 5], "box_size": [0.2, 0.6], "cylinder_radius": [0.1, 0.25], "min_spawn_goal_distance": 3.0}
#: (name, generator, params): what is asked for at each level.
CONFIGS = (
    ("cluttered 5x5 (barn_like)", "cluttered", BARN_ROOM),
    ("cluttered 10x10 (default)", "cluttered", {}),
    ("corridor (default)", "corridor", {}),
    # Not in the test: its level 9-10 requests take 3-10 s each (dense fields, many draws, each proved exactly).
    ("barn (default)", "barn", {}),
)
#: Levels whose intervals must be apart from their neighbours' and so get --end-seeds seeds.
ENDS = (1, 5)


def _disjoint(a, b) -> bool:
    return a["wilson"][1] < b["wilson"][0] or b["wilson"][1] < a["wilson"][0]


def main(argv=None) -> int:
    from worldgen.envs.ladder import ladder_figures, success_by_level
    from worldgen.leveling import reachable

    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--seeds", type=int, default=16)
    ap.add_argument("--end-seeds", type=int, default=44)
    ap.add_argument("--only", nargs="*", default=None, help="configurations whose name starts with one of these")
    args = ap.parse_args(argv)
    out, all_met = {}, True
    for name, generator, params in CONFIGS:
        if args.only is not None and not any(name.startswith(o) for o in args.only):
            continue
        t0 = time.perf_counter()
        levels = reachable(generator)
        table = success_by_level(generator, [k for k in levels if k not in ENDS], range(args.seeds), params)
        table.update(success_by_level(generator, [k for k in levels if k in ENDS], range(args.end_seeds), params))
        figures = ladder_figures(table)
        rows = figures["levels"]
        print(f"\n{name}: Spearman {figures['spearman']:+.3f} ({time.perf_counter() - t0:.0f} s)")
        print("level  worlds  reactive success  Wilson 95 %")
        for level, r in rows.items():
            print(f"{level:5d}  {r['worlds']:6d}  {r['rate']:16.2f}  [{r['wilson'][0]:.2f}, {r['wilson'][1]:.2f}]")
        lo, mid, hi = rows.get(1), rows.get(5), rows.get(10)
        ok = {"rho <= -0.9": figures["spearman"] <= -0.9,
              "level 1 >= 0.9": bool(lo and lo["rate"] >= 0.9), "level 10 <= 0.2": bool(hi and hi["rate"] <= 0.2),
              "1, 5, 10 disjoint": bool(lo and mid and hi and _disjoint(lo, mid) and _disjoint(mid, hi)
                                        and _disjoint(lo, hi))}
        print(", ".join(f"{k}: {'met' if v else 'MISSED'}" for k, v in ok.items()))
        all_met &= all(ok.values())
        out[name] = {"generator": generator, "params": params, "seeds": args.seeds, "end_seeds": args.end_seeds,
                     "targets": ok, **figures}
    RESULTS.parent.mkdir(exist_ok=True)
    tmp = RESULTS.with_suffix(".tmp")
    tmp.write_text(json.dumps(out, indent=1) + "\n")
    tmp.replace(RESULTS)
    return 0 if all_met else 1


if __name__ == "__main__":
    sys.exit(main())
