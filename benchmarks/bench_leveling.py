"""Worlds at a requested difficulty level (worldgen.leveling): how often a request lands, in how many draws, how fast.

    make bench          # or: nice -n 10 .venv/bin/python benchmarks/bench_leveling.py [--seeds N] [--size X Y]

For every level 1..10 and seeds 0..N-1 (default 10: 100 requests), ``worldgen.generate("cluttered", seed,
difficulty="k/10", size=[X, Y])`` (default 20 x 20 m, the issue's target room), timed with
time.perf_counter (draws that missed included). Each request is timed twice, interleaved so both see the
same machine load: with the shipped calibration (the cluttered spec's knob, ``worldgen.generators.cluttered.KNOB``)
and with :data:`PREVIOUS_START`, the
calibration before it, so a change of calibration is measured in one run. Targets (issue 19): at least
95 % of requests land, at a median of at most 5 draws; a world at a level in at most 50 ms median. The
table goes to stdout, the figures to benchmarks/results/leveling.json.
"""

from __future__ import annotations

import argparse
import dataclasses
import json
import statistics
import sys
import time
from pathlib import Path

RESULTS = Path(__file__).resolve().parent / "results" / "leveling.json"
#: The cluttered calibration before the current one (obstacles per 100 m^2 for levels 1..10).
PREVIOUS_START = (0.0, 10.0, 20.0, 30.0, 35.0, 40.0, 45.0, 55.0, 65.0, 75.0)


def _request(spec, level: int, seed: int, size) -> dict:
    from worldgen.errors import InfeasibleError
    from worldgen.leveling import LEVELS, MAX_DRAWS, generate_at_level

    t0 = time.perf_counter()
    try:
        # The request worldgen.generate makes for difficulty=, with the calibration under test in its spec.
        world = generate_at_level(spec, seed, f"{level}/{LEVELS}", {"size": list(size)})
        landed, draws = True, len(world.difficulty_request["draws"])
    except InfeasibleError:
        landed, draws = False, MAX_DRAWS
    return {"level": level, "seed": seed, "landed": landed, "draws": draws,
            "ms": round((time.perf_counter() - t0) * 1e3, 3)}


def _summary(rows: list[dict]) -> dict:
    return {"requests": len(rows), "landed": sum(r["landed"] for r in rows),
            "median_draws": statistics.median(r["draws"] for r in rows),
            "median_ms": statistics.median(r["ms"] for r in rows)}


def main(argv=None) -> int:
    from worldgen import leveling
    from worldgen.generators import get

    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--seeds", type=int, default=10)
    ap.add_argument("--size", type=float, nargs=2, default=[20.0, 20.0], metavar=("X", "Y"))
    args = ap.parse_args(argv)
    shipped = get("cluttered")
    assert shipped.knob is not None
    calibrations = {"current": shipped,
                    "previous": dataclasses.replace(shipped, knob=dataclasses.replace(shipped.knob, start=PREVIOUS_START))}
    rows: dict[str, list] = {name: [] for name in calibrations}
    print(f"cluttered {args.size[0]:g} x {args.size[1]:g} m; per calibration: landed, median draws, median ms")
    print("level  " + "  ".join(f"{name:>24s}" for name in calibrations))
    for level in range(1, leveling.LEVELS + 1):
        cells = []
        for seed in range(args.seeds):
            for name, spec in calibrations.items():  # interleaved: both see the same load
                rows[name].append(_request(spec, level, seed, args.size))
        for name in calibrations:
            runs = [r for r in rows[name] if r["level"] == level]
            s = _summary(runs)
            cells.append(f"{s['landed']:3d}/{len(runs):<3d} {s['median_draws']:5.1f} {s['median_ms']:9.1f}")
        print(f"{level:5d}  " + "  ".join(f"{c:>24s}" for c in cells))
    summary = {name: _summary(r) for name, r in rows.items()}
    now = summary["current"]
    ok = {"landed >= 95 %": now["landed"] >= 0.95 * now["requests"], "median draws <= 5": now["median_draws"] <= 5,
          "median <= 50 ms": now["median_ms"] <= 50}
    for name, s in summary.items():
        print(f"{name}: {s['landed']}/{s['requests']} landed, median {s['median_draws']} draws, median {s['median_ms']:.1f} ms")
    print(", ".join(f"{k}: {'met' if v else 'MISSED'}" for k, v in ok.items()))
    RESULTS.parent.mkdir(exist_ok=True)
    tmp = RESULTS.with_suffix(".tmp")
    tmp.write_text(json.dumps({"size": args.size, "summary": summary, "targets": ok, "runs": rows}, indent=1) + "\n")
    tmp.replace(RESULTS)
    return 0 if all(ok.values()) else 1


if __name__ == "__main__":
    sys.exit(main())
