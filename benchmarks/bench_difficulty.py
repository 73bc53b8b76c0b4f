"""Validation of world.json's difficulty score against the reference probes' failures.

    make bench          # or: nice -n 10 .venv/bin/python benchmarks/bench_difficulty.py [--seeds N] [--jobs J]
    .venv/bin/python benchmarks/bench_difficulty.py --fit [--seeds N]   # refit (prints a new MODEL)

Worlds: every configuration of :data:`CONFIGS` (four generators: cluttered rooms of 10 x 10 m and
BARN-like 5 x 5 m, corridors, door worlds, minimal) with seeds 0..N-1 (validation) or
FIT_SEED0.. FIT_SEED0+N-1 (fitting; disjoint from the validation seeds). In each world both
probes of ``worldgen.envs.probes`` (``reactive``, ``tracker``) drive the first task in
worldgen/Navigation-v0 with default settings but the speeds of worldgen.envs.ladder.SPEEDS; a probe
fails when the episode is not a success.

Reported per probe: Spearman's rank correlation of ``metrics.difficulty`` with failure (0/1),
the AUC of the score for telling failures from successes (Mann-Whitney), and success per
``difficulty_level`` with 95 % Wilson intervals. Target (issue 19): AUC >= 0.85 per probe.
The table goes to stdout, the figures to benchmarks/results/difficulty.json; the per-world
records are kept in benchmarks/results/difficulty_worlds_<fit|val>.json (a rerun with the same
seeds reads them instead of driving again; --fresh drives again).
"""

from __future__ import annotations

import argparse
import json
import math
import os
import platform
import sys
import time
from concurrent.futures import ProcessPoolExecutor
from pathlib import Path

import numpy as np

RESULTS = Path(__file__).resolve().parent / "results"
FIT_SEED0 = 1_000_000
PROBES = ("reactive", "tracker")
BARN_ROOM = {"size": [5, 5], "box_size": [0.2, 0.6], "cylinder_radius": [0.1, 0.25], "min_spawn_goal_distance": 3.0}
#: (generator, params): the worlds every seed is drawn in, easy to hard.
CONFIGS: tuple[tuple[str, dict], ...] = (
    *[("cluttered", {"n_obstacles": n}) for n in (5, 10, 20, 30, 40)],
    *[("cluttered", dict(BARN_ROOM, n_obstacles=n, min_gap=g)) for n in (4, 8, 12, 16) for g in (0.55, 0.3)],
    *[("corridor", {"shape": s, "width": w, "length": 6.0, "n_obstacles": k})
      for s in ("straight", "L", "zigzag") for w in (1.0, 1.5) for k in (0, 2)],
    *[("door", {"state": st, "n_doors": n, "size": [6.0 * n + 2, 4]}) for st in ("closed", "ajar", "open") for n in (1, 2)],
    ("minimal", {}),
)


_ENV = None


def _inputs(world) -> dict:
    """What the score reads of world.json (metrics, robot, tasks), kept so a new model can be fitted without driving."""
    meta = world.metadata
    return {"metrics": meta["metrics"], "robot": meta["robot"], "tasks": meta["tasks"]}


def _fill(job: tuple[int, int]) -> dict:
    import worldgen

    k, seed = job
    return _inputs(worldgen.generate(CONFIGS[k][0], seed, **CONFIGS[k][1]))


def features(records: list[dict]) -> list[dict]:
    """The records of driven worlds, each with its ``features`` under the package's difficulty module."""
    from worldgen.groundtruth import difficulty

    return [dict(r, features=difficulty.features(r["meta"])) for r in records if "meta" in r]


def drive(job: tuple[int, int]) -> dict:
    """One world (config index, seed): its difficulty features and both probes' outcomes."""
    global _ENV
    import gymnasium

    import worldgen
    import worldgen.envs  # noqa: F401
    from worldgen.envs.probes import run_episode
    from worldgen.envs.source import OneWorldSource
    from worldgen.errors import WorldgenError

    k, seed = job
    generator, params = CONFIGS[k]
    rec: dict = {"config": k, "generator": generator, "params": params, "seed": seed}
    try:
        world = worldgen.generate(generator, seed, **params)
    except WorldgenError as exc:
        return dict(rec, skipped=str(exc).splitlines()[0])
    rec.update(world_id=world.world_id, meta=_inputs(world))
    if _ENV is None:
        from worldgen.envs.ladder import SPEEDS  # the speeds its figures were measured at (docs/metrics.md)

        _ENV = gymnasium.make("worldgen/Navigation-v0", generator="minimal", **SPEEDS).unwrapped
    _ENV.source = OneWorldSource(world)
    for probe in PROBES:
        info = run_episode(_ENV, probe, seed=0, options={"world_seed": seed})
        rec[probe] = {"success": bool(info["success"]), "collided": bool(info["collisions"]),
                      "duration": round(float(info["duration"]), 3)}
    return rec


def collect(seeds: range, jobs: int, cache: Path, fresh: bool) -> list[dict]:
    todo = [(k, s) for s in seeds for k in range(len(CONFIGS))]
    if cache.exists() and not fresh:
        done = json.loads(cache.read_text())
        if [(r["config"], r["seed"]) for r in done] == todo:
            missing = [(r["config"], r["seed"]) for r in done if "meta" not in r and "skipped" not in r]
            if missing:  # records from before the inputs were kept: regenerate the worlds (no driving)
                with ProcessPoolExecutor(jobs) as pool:
                    filled = dict(zip(missing, pool.map(_fill, missing, chunksize=8)))
                done = [dict(r, meta=filled[(r["config"], r["seed"])]) if (r["config"], r["seed"]) in filled else r
                        for r in done]
                _save(cache, done)
            return done
    t0 = time.perf_counter()
    if jobs > 1:
        with ProcessPoolExecutor(jobs) as pool:
            records = list(pool.map(drive, todo, chunksize=4))
    else:
        records = [drive(j) for j in todo]
    print(f"drove {len(todo)} worlds in {time.perf_counter() - t0:.0f} s", file=sys.stderr)
    _save(cache, records)
    return records


def _save(path: Path, value) -> None:
    tmp = path.with_suffix(".tmp")
    tmp.write_text(json.dumps(value))
    tmp.replace(path)


# -- statistics ---------------------------------------------------------------------------------------------

def auc(score: np.ndarray, positive: np.ndarray) -> float:
    """P(score of a positive > score of a negative), ties counting half (Mann-Whitney U / (n+ n-))."""
    from scipy.stats import rankdata

    n1, n0 = int(positive.sum()), int((~positive).sum())
    if n1 == 0 or n0 == 0:
        return float("nan")
    ranks = rankdata(score)
    return float((ranks[positive].sum() - n1 * (n1 + 1) / 2) / (n1 * n0))


def wilson(k: int, n: int, z: float = 1.959964) -> tuple[float, float]:
    """95 % Wilson score interval of a proportion k / n."""
    if n == 0:
        return (float("nan"), float("nan"))
    p = k / n
    centre = (p + z * z / (2 * n)) / (1 + z * z / n)
    half = z * math.sqrt(p * (1 - p) / n + z * z / (4 * n * n)) / (1 + z * z / n)
    return (max(0.0, centre - half), min(1.0, centre + half))


def fit_probe(rows: list[dict], probe: str, l2: float = 1.0) -> dict:
    """Logistic regression (Newton's method, L2 penalty ``l2`` on the weights) of one probe's failure."""
    from worldgen.groundtruth import difficulty

    x = np.array([difficulty._vector(r["features"]) for r in rows])
    y = np.array([float(not r[probe]["success"]) for r in rows])
    return logistic(x, y, l2)


def logistic(x: np.ndarray, y: np.ndarray, l2: float, offset=0.0) -> dict:
    """Newton's method for a logistic model of ``y`` on the standardised columns of ``x`` (L2 penalty ``l2`` on
    the weights, none on the bias), each row's logit shifted by ``offset``: bias, means, scales, weights."""
    mean, std = x.mean(axis=0), x.std(axis=0)
    std[std == 0] = 1.0
    z = np.column_stack([np.ones(len(x)), (x - mean) / std])
    beta = np.zeros(z.shape[1])
    penalty = np.diag([0.0] + [l2] * (z.shape[1] - 1))
    for _ in range(100):
        p = 1 / (1 + np.exp(-(offset + z @ beta)))
        grad = z.T @ (p - y) + penalty @ beta
        hess = (z * (p * (1 - p))[:, None]).T @ z + penalty
        step = np.linalg.solve(hess, grad)
        beta -= step
        if np.abs(step).max() < 1e-10:
            break
    return {"bias": round(float(beta[0]), 6), "mean": [round(float(v), 6) for v in mean],
            "std": [round(float(v), 6) for v in std], "weight": [round(float(v), 6) for v in beta[1:]]}


def fit(records: list[dict]) -> dict:
    """A model of :mod:`worldgen.groundtruth.difficulty`'s form: one logistic model per probe."""
    rows = [r for r in features(records) if r["features"]]
    return {probe: fit_probe(rows, probe) for probe in PROBES}


def validate(records: list[dict]) -> dict:
    from scipy.stats import spearmanr

    from worldgen.groundtruth import difficulty

    rows = [r for r in features(records) if r["features"]]
    d = np.array([round(difficulty.score(r["features"]), 6) for r in rows])
    levels = np.array([difficulty.level_of(v) for v in d])
    out: dict = {"worlds": len(rows), "skipped": len(records) - len(rows), "model": difficulty.MODEL_ID,
                 "generators": {g: sum(r["generator"] == g for r in rows) for g in sorted({r["generator"] for r in rows})},
                 "levels": {str(k): int((levels == k).sum()) for k in range(1, 11)}, "probes": {}}
    for probe in PROBES:
        fail = np.array([not r[probe]["success"] for r in rows])
        rho = spearmanr(d, fail.astype(float)).statistic
        per_level = {}
        for k in range(1, 11):
            sel = levels == k
            n, s = int(sel.sum()), int((~fail[sel]).sum())
            lo, hi = wilson(s, n)
            per_level[str(k)] = {"worlds": n, "success": round(s / n, 3) if n else None,
                                 "wilson95": [round(lo, 3), round(hi, 3)] if n else None}
        per_gen = {}
        for g in out["generators"]:
            sel = np.array([r["generator"] == g for r in rows])
            a = auc(d[sel], fail[sel])  # undefined (None) where every world failed or none did
            per_gen[g] = {"success": round(float((~fail[sel]).mean()), 3), "auc": None if math.isnan(a) else round(a, 3)}
        out["probes"][probe] = {"failures": int(fail.sum()), "spearman": round(float(rho), 3),
                                "auc": round(auc(d, fail), 3), "per_level": per_level, "per_generator": per_gen}
    return out


def table(v: dict) -> str:
    lines = [f"{v['worlds']} worlds ({', '.join(f'{g} {n}' for g, n in v['generators'].items())}), "
             f"{v['skipped']} skipped; model {v['model']}"]
    for probe, p in v["probes"].items():
        ok = "met" if p["auc"] >= 0.85 else "MISSED"
        lines.append(f"{probe:9s} failures {p['failures']:4d}  spearman {p['spearman']:+.3f}  AUC {p['auc']:.3f} "
                     f"(target >= 0.85: {ok})")
    lines.append("level  worlds  " + "  ".join(f"{p:>22s}" for p in v["probes"]))
    for k in range(1, 11):
        cells = []
        for p in v["probes"].values():
            c = p["per_level"][str(k)]
            cells.append(f"{c['success']:.2f} [{c['wilson95'][0]:.2f}, {c['wilson95'][1]:.2f}]" if c["worlds"] else "-")
        lines.append(f"{k:5d}  {v['levels'][str(k)]:6d}  " + "  ".join(f"{c:>22s}" for c in cells))
    return "\n".join(lines)


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--seeds", type=int, default=50, help="seeds per configuration (default 50: 1,600 worlds)")
    ap.add_argument("--jobs", type=int, default=2)
    ap.add_argument("--fit", action="store_true", help="fit a new model on the fitting seeds and print it")
    ap.add_argument("--fresh", action="store_true", help="drive every world again, ignoring kept records")
    args = ap.parse_args(argv)
    RESULTS.mkdir(exist_ok=True)
    if args.fit:
        records = collect(range(FIT_SEED0, FIT_SEED0 + args.seeds), args.jobs, RESULTS / "difficulty_worlds_fit.json",
                          args.fresh)
        print(json.dumps(fit(records), indent=1))
        return 0
    records = collect(range(args.seeds), args.jobs, RESULTS / "difficulty_worlds_val.json", args.fresh)
    v = validate(records)
    print(table(v))
    v["machine"] = {"python": platform.python_version(), "cpus": os.cpu_count(), "seeds": args.seeds}
    tmp = RESULTS / "difficulty.json.tmp"
    tmp.write_text(json.dumps(v, indent=1) + "\n")
    tmp.replace(RESULTS / "difficulty.json")
    targets = all(p["auc"] >= 0.85 for p in v["probes"].values())
    return 0 if targets else 1


if __name__ == "__main__":
    sys.exit(main())
