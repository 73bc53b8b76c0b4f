"""No cliffs: the requests issue 30 measured slow, against their parts, and a random sweep of requests.

    make bench          # or: nice -n 10 .venv/bin/python benchmarks/bench_requests.py [--runs N] [--sample N]

Targets (medians of CPU time, ``time.process_time``, over --runs runs, pinned to one core: the machine is
shared, and CPU time moves less than wall time under load; every ratio is of figures taken in this run):

- ``level+people``: ``cluttered --difficulty 7/10 --set n_people=10`` at most ``level`` (the same request
  without people) plus ``people`` (the world it returned made again from its own seed and params: its people
  walked once, no level draws) plus 20 %, for request seeds 0-9 (the median of the per-seed ratios, also over
  the seeds whose people refused no landed draw) and for seed 3, the issue's (its own ratio);
- ``boxes65``: ``cluttered --seed 5 --set n_obstacles=65 --set n_people=10`` (10 x 10 m) at most 1 s;
- ``check``: ``worldgen check``'s work (``verify.check_folder``) on the level+people world of seed 3 at
  most its generation.

The sweep: --sample random requests (default 1000) over the documented ranges of the five generators'
parameters and the presets (:func:`_request`): each a generator or preset, two to four of its own or the
common parameters drawn from their ranges, a level in a third of them and people in a quarter; timed
(wall, generate + world.json with every file rendered) with a listener on ``worldgen.progress`` that
records when the first progress message came. Listed: the slowest 20, and every request over 2 s whose
first message came after 2 s (which the progress line would have left blank: none may). A request is
stopped after --limit s (default 60) and listed as such.

The table goes to stdout, the figures to benchmarks/results/requests.json.
"""

from __future__ import annotations

import argparse
import json
import logging
import math
import os
import platform
import random
import signal
import statistics
import sys
import tempfile
import time
from pathlib import Path

RESULTS = Path(__file__).resolve().parent / "results" / "requests.json"
COMMON = ("n_tasks", "robot_radius", "clearance", "n_movers", "n_people", "person_radius", "people_duration",
          "group_size", "map_resolution", "lidar_samples")


def _cpu(fn, runs: int) -> float | None:
    """Median CPU seconds of ``fn`` over ``runs`` runs; None where it raised InfeasibleError (no such world)."""
    from worldgen.errors import InfeasibleError

    times = []
    for _ in range(runs):
        t = time.process_time()
        try:
            fn()
        except InfeasibleError:
            return None
        times.append(time.process_time() - t)
    return statistics.median(times)


def targets(runs: int) -> dict:
    import worldgen
    from worldgen.verify import check_folder

    level = {s: _cpu(lambda s=s: worldgen.generate("cluttered", seed=s, difficulty="7/10"), runs) for s in range(10)}
    both = {s: _cpu(lambda s=s: worldgen.generate("cluttered", seed=s, difficulty="7/10", n_people=10), runs)
            for s in range(10)}
    # The people alone: the world the level request with people returned, made again from its own seed and params
    # (its people walked once, no level draws).
    landed = {s: _landed(s) for s in range(10)}
    people = {s: None if w is None else _cpu(lambda w=w: worldgen.generate("cluttered", w.seed, **w.params), runs)
              for s, w in landed.items()}
    refused = {s: None if w is None else sum(d["level"] is None for d in w.difficulty_request["draws"])
               for s, w in landed.items()}
    ratio = {s: both[s] / (level[s] + people[s]) for s in range(10) if None not in (both[s], level[s], people[s])}
    static65 = _cpu(lambda: worldgen.generate("cluttered", seed=5, n_obstacles=65), runs)
    boxes65 = _cpu(lambda: worldgen.generate("cluttered", seed=5, n_obstacles=65, n_people=10), runs)
    with tempfile.TemporaryDirectory() as tmp:
        folder = (landed[3] or worldgen.generate("cluttered", seed=3, difficulty="7/10", n_people=10)).write(tmp)
        check = _cpu(lambda: check_folder(folder), runs)
    return {"level_s": level, "people_s": people, "level_people_s": both, "ratio": ratio, "refused_draws": refused,
            "ratio_median_unrefused": statistics.median(r for s, r in ratio.items() if not refused[s]),
            "ratio_median": statistics.median(ratio.values()), "ratio_seed3": ratio.get(3),
            "no_world": [s for s in range(10) if s not in ratio],
            "boxes65_static_s": static65, "boxes65_people_s": boxes65,
            "check_seed3_s": check, "generate_seed3_s": both[3]}


def _landed(seed: int):
    import worldgen
    from worldgen.errors import InfeasibleError

    try:
        return worldgen.generate("cluttered", seed=seed, difficulty="7/10", n_people=10)
    except InfeasibleError:
        return None


class _Heard(logging.Handler):
    def __init__(self):
        super().__init__(logging.INFO)
        self.first: float | None = None
        self.start = 0.0

    def emit(self, record):
        if self.first is None:
            self.first = time.perf_counter() - self.start


def _value(p, rng: random.Random):
    """A value from parameter ``p``'s documented range: log-uniform over a positive range wider than 100x (so a
    sample is not all huge rooms), else uniform."""
    def number(lo, hi, integer):
        if lo > 0 and hi / lo > 100:
            x = math.exp(rng.uniform(math.log(lo), math.log(hi)))
        else:
            x = rng.uniform(lo, hi)
        return int(round(x)) if integer else round(x, 4)

    if p.kind == "bool":
        return rng.random() < 0.5
    if p.kind == "choice":
        return rng.choice(p.choices)
    if p.kind in ("int", "float"):
        return number(p.low, p.high, p.kind == "int")
    if p.kind == "pair":
        return [number(p.low, p.high, False) for _ in range(2)]
    if p.kind == "range":
        a, b = sorted(number(p.low, p.high, False) for _ in range(2))
        return [a, b]
    return None  # triple, list, words: left at their defaults


def _request(rng: random.Random, specs, presets) -> tuple[str, dict, dict]:
    """(label, generate's keyword arguments, the parameters drawn) of one random request."""
    from worldgen.leveling import reachable

    if rng.random() < 0.2 and presets:
        preset = rng.choice(presets)
        name, params, label = preset.generator, dict(preset.params), f"preset {preset.name}"
    else:
        spec = rng.choice(specs)
        name, params, label = spec.name, {}, spec.name
    spec = next(s for s in specs if s.name == name)
    by_name = {p.name: p for p in spec.all_params}
    candidates = [p for p in spec.params if p.name != "max_attempts"] + [by_name[c] for c in COMMON if c in by_name]
    drawn = {}
    for p in rng.sample(candidates, rng.randint(2, 4)):
        value = _value(p, rng)
        if value is not None:
            drawn[p.name] = value
    if rng.random() < 0.25:
        drawn["n_people"] = rng.randint(1, 20)
    kwargs = {**params, **drawn}
    if spec.knob is not None and rng.random() < 1 / 3:
        kwargs["difficulty"] = f"{rng.choice(reachable(name))}/10"
        for owned in spec.knob.owned():
            kwargs.pop(owned, None)
    return label, {"name": name, **kwargs}, drawn


class _Stop(Exception):
    pass


def _stop(signum, frame):
    raise _Stop()


def sweep(sample: int, limit: float, seed: int = 30) -> dict:
    import worldgen
    from worldgen.errors import WorldgenError
    from worldgen.generators import all_specs
    from worldgen.presets import all_presets

    rng = random.Random(seed)
    specs, presets = all_specs(), all_presets()
    heard = _Heard()
    logger = logging.getLogger("worldgen.progress")
    logger.addHandler(heard)
    logger.setLevel(logging.INFO)
    logger.propagate = False
    signal.signal(signal.SIGALRM, _stop)
    rows = []
    for i in range(sample):
        label, kwargs, drawn = _request(rng, specs, presets)
        name = kwargs.pop("name")
        request_seed = rng.randrange(1000)
        heard.first, heard.start = None, time.perf_counter()
        outcome = "ok"
        signal.setitimer(signal.ITIMER_REAL, limit)
        try:
            world = worldgen.generate(name, seed=request_seed, **kwargs)
            world.metadata  # every file rendered, as a written world
        except _Stop:
            outcome = f"stopped at {limit:g} s"
        except WorldgenError as exc:
            outcome = f"refused (exit {exc.exit_status})"
        finally:
            signal.setitimer(signal.ITIMER_REAL, 0)
        took = time.perf_counter() - heard.start
        rows.append({"i": i, "request": label, "seed": request_seed, "params": {**drawn, **(
            {"difficulty": kwargs["difficulty"]} if "difficulty" in kwargs else {})}, "outcome": outcome,
            "s": round(took, 3), "first_progress_s": None if heard.first is None else round(heard.first, 3)})
        print(f"\r{i + 1}/{sample}", end="", file=sys.stderr, flush=True)
    print(file=sys.stderr)
    logger.removeHandler(heard)
    slowest = sorted(rows, key=lambda r: -r["s"])[:20]
    silent = [r for r in rows if r["s"] > 2 and (r["first_progress_s"] is None or r["first_progress_s"] > 2)]
    return {"sample": sample, "limit_s": limit, "slowest": slowest, "silent_over_2s": silent,
            "over_2s": sum(r["s"] > 2 for r in rows), "median_s": statistics.median(r["s"] for r in rows),
            "outcomes": {o: sum(r["outcome"] == o for r in rows) for o in sorted({r["outcome"] for r in rows})}}


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--runs", type=int, default=5)
    ap.add_argument("--sample", type=int, default=1000)
    ap.add_argument("--limit", type=float, default=60.0)
    ap.add_argument("--skip-targets", action="store_true")
    ap.add_argument("--all-cores", action="store_true")
    args = ap.parse_args()
    if not args.all_cores and hasattr(os, "sched_setaffinity"):
        os.sched_setaffinity(0, {min(os.sched_getaffinity(0))})
    out: dict = {"machine": platform.platform(), "date": time.strftime("%Y-%m-%d")}
    if not args.skip_targets:
        t = out["targets"] = targets(args.runs)
        print(f"level+people / (level + people): median over seeds 0-9 {t['ratio_median']:.2f}, seed 3 "
              f"{t['ratio_seed3']:.2f} (target <= 1.20: {'met' if t['ratio_median'] <= 1.2 else 'missed'}); "
              f"no world for seeds {t['no_world']}; median over the seeds the people refused no draw of "
              f"{t['ratio_median_unrefused']:.2f}")
        print(f"65 boxes + 10 people, 10 x 10 m: {t['boxes65_people_s']:.2f} s CPU (target <= 1 s: "
              f"{'met' if t['boxes65_people_s'] <= 1 else 'missed'}); the static world alone {t['boxes65_static_s']:.2f} s")
        print(f"check {t['check_seed3_s']:.2f} s vs its generation {t['generate_seed3_s']:.2f} s "
              f"({'met' if t['check_seed3_s'] <= t['generate_seed3_s'] else 'missed'})")
    if args.sample:
        s = out["sweep"] = sweep(args.sample, args.limit)
        print(f"sweep of {s['sample']} requests: median {s['median_s']:.3f} s, {s['over_2s']} over 2 s, "
              f"{len(s['silent_over_2s'])} of them with no progress message in their first 2 s; {s['outcomes']}")
        print("slowest 20 (s, first progress message at s, request):")
        for r in s["slowest"]:
            print(f"  {r['s']:8.2f}  {r['first_progress_s']}  {r['request']} seed {r['seed']} {r['params']}  {r['outcome']}")
    RESULTS.parent.mkdir(parents=True, exist_ok=True)
    RESULTS.write_text(json.dumps(out, indent=1, sort_keys=True, default=str) + "\n")


if __name__ == "__main__":
    main()
