"""People: a 20 x 20 m cluttered world with 50 obstacles and N people walking for 60 s, generated, walked
and certified (docs/people.md).

    make bench                      # or: .venv/bin/python benchmarks/bench_people.py [--worlds N] [--all-cores]

For N = 10, 20 and 50 people and --worlds seeds (default 15): the whole of worldgen.generate (every draw
it took, each drawing obstacles, walking the people and certifying the task), then, on the world it
returned, its stages timed again on their own: the static world and its feasibility check without
people, the people drawn and walked (generators.people + feasibility.crowd) and, within that walk, the
people's routing (feasibility.roadmap: its tangent graph, and every exact route query, timed call by
call), the certificate (feasibility.timed). Medians over the worlds; the draws a world took and its arrival time beside them.
Pinned to one core (--all-cores to not pin). Target (issue 20): the whole, 20 people, median <= 150 ms.

The table goes to stdout, the figures to benchmarks/results/people.json.
"""

from __future__ import annotations

import argparse
import json
import os
import platform
import statistics
import time
from pathlib import Path

RESULTS = Path(__file__).resolve().parent / "results" / "people.json"
WORLD = {"size": [20.0, 20.0], "n_obstacles": 50, "people_duration": 60.0}
COUNTS = (10, 20, 50)
TARGET_MS = 150.0


def _ms(fn) -> tuple[float, object]:
    t = time.perf_counter()
    out = fn()
    return (time.perf_counter() - t) * 1e3, out


class _Routing:
    """Times the people's routing inside the ``with`` block: the tangent graph a walk builds once
    (``Roadmap.__init__``), every exact route query (``Roadmap.shortest``, or ``Planner.shortest`` where
    a walk is too short for the graph to pay), counted."""

    def __enter__(self):
        from worldgen.feasibility.planner import Planner
        from worldgen.feasibility.roadmap import Roadmap
        self.ms, self.calls = 0.0, 0
        self._orig = [(cls, name, getattr(cls, name)) for cls in (Roadmap, Planner) for name in ("shortest", "__init__")]
        outer = self

        def timed(fn, count):
            def call(*args):
                t = time.perf_counter()
                try:
                    return fn(*args)
                finally:
                    outer.ms += (time.perf_counter() - t) * 1e3
                    outer.calls += count
            return call
        for cls, name, fn in self._orig:
            setattr(cls, name, timed(fn, int(name == "shortest")))
        return self

    def __exit__(self, *exc):
        for cls, name, fn in self._orig:
            setattr(cls, name, fn)
        return False


def measure(n_people: int, seeds: range) -> dict:
    import worldgen
    from worldgen.feasibility import check
    from worldgen.people.crowd import walk_people
    from worldgen.people.timed import certify
    from worldgen.seeding import people_rng

    rows = []
    for seed in seeds:
        whole, world = _ms(lambda: worldgen.generate("cluttered", seed, n_people=n_people, **WORLD))
        attempt = world.attempts - 1
        static = world.scene.with_movers(())
        base, _ = _ms(lambda: worldgen.generate("cluttered", seed, **WORLD))
        with _Routing() as routing:
            walk, _ = _ms(lambda: walk_people(static, world.tasks, world.robot, world.params, people_rng(seed, attempt)))
        report = check(static, world.tasks, world.robot)
        cert, _ = _ms(lambda: certify(report, world.scene, world.tasks, world.robot, world.params["robot_speed"]))
        rows.append({"seed": seed, "whole_ms": whole, "draws": world.attempts, "static_world_ms": base,
                     "walk_ms": walk, "routing_ms": routing.ms, "queries": routing.calls, "certify_ms": cert,
                     "arrival_s": world.feasibility.check("timed_path").value})
    med = {key: statistics.median(r[key] for r in rows)
           for key in ("whole_ms", "draws", "static_world_ms", "walk_ms", "routing_ms", "queries", "certify_ms",
                       "arrival_s")}
    first_draw = [r["whole_ms"] for r in rows if r["draws"] == 1]
    med["whole_first_draw_ms"] = statistics.median(first_draw) if first_draw else None
    return {"n_people": n_people, "median": med, "worlds": rows}


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--worlds", type=int, default=15)
    ap.add_argument("--all-cores", action="store_true")
    args = ap.parse_args()
    if not args.all_cores and hasattr(os, "sched_setaffinity"):
        os.sched_setaffinity(0, {sorted(os.sched_getaffinity(0))[0]})  # the target is per core
    import worldgen
    worldgen.generate("cluttered", 0, n_people=2, size=[6.0, 6.0], n_obstacles=4, people_duration=5.0)  # warm up
    results = [measure(n, range(args.worlds)) for n in COUNTS]
    head = ("| people | whole | whole, first-draw worlds | draws | static world | walk | of which routing (queries) "
            "| certify | arrival |")
    print(f"20 x 20 m, 50 obstacles, 60 s of walking; medians over {args.worlds} seeds, ms (arrival s)")
    print(head)
    print("|---|---|---|---|---|---|---|---|---|")
    for r in results:
        m = r["median"]
        first = "-" if m["whole_first_draw_ms"] is None else f"{m['whole_first_draw_ms']:.0f}"
        print(f"| {r['n_people']} | {m['whole_ms']:.0f} | {first} | {m['draws']:g} | {m['static_world_ms']:.1f} | "
              f"{m['walk_ms']:.0f} | {m['routing_ms']:.0f} ({m['queries']:g}) | {m['certify_ms']:.1f} | "
              f"{m['arrival_s']:.1f} |")
    twenty = next(r for r in results if r["n_people"] == 20)["median"]["whole_ms"]
    print(f"target: 20 people, whole <= {TARGET_MS:g} ms median: {twenty:.0f} ms, "
          f"{'met' if twenty <= TARGET_MS else 'missed'}")
    out = {"worldgen_version": worldgen.__version__, "python": platform.python_version(),
           "machine": platform.machine(), "cpus": os.cpu_count(), "pinned_to_one_core": not args.all_cores,
           "load_average": list(os.getloadavg()) if hasattr(os, "getloadavg") else None,
           "world": WORLD, "target_ms": TARGET_MS, "results": results}
    RESULTS.parent.mkdir(parents=True, exist_ok=True)
    tmp = RESULTS.with_suffix(".json.tmp")
    tmp.write_text(json.dumps(out, indent=2, sort_keys=True) + "\n")
    tmp.replace(RESULTS)


if __name__ == "__main__":
    main()
