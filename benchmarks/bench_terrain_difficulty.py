"""The difficulty score in terrain worlds: the flat model alone against it with the terrain's terms, on the
reference probes' failures (docs/metrics.md, "Terrain").

    nice -n 10 .venv/bin/python benchmarks/bench_terrain_difficulty.py [--seeds N]          # validate
    nice -n 10 .venv/bin/python benchmarks/bench_terrain_difficulty.py --fit [--seeds N]    # print a new TERRAIN_MODEL

Worlds: ``terrain`` worlds (10 x 10 m) of every configuration of :data:`CONFIGS` (obstacle counts by terrain
loads, light to heavy) with seeds 0..N-1 (validation) or FIT_SEED0.. (fitting; disjoint). In each, both
probes of ``worldgen.envs.probes`` drive the first task in worldgen/Navigation-v0 (the terrain robot,
worldgen.envs.terrain); a probe fails when the episode is not a success.

The terrain model is fitted per probe as a logistic regression of failure on the standardised terrain inputs
(``difficulty.TERRAIN_FEATURES``) with the frozen flat model's logit as an offset, so the flat model is kept
and the terrain only adds to it. Reported per probe: the AUC of the flat score and of the score with the
terrain's terms for telling failures from successes, and the log loss of the probe's own chance under each. Records are kept in
benchmarks/results/terrain_difficulty_<fit|val>.json (a rerun with the same seeds reads them).
"""

from __future__ import annotations

import argparse
import json
import sys
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
from bench_difficulty import PROBES, auc, logistic  # noqa: E402  (a sibling script: the same AUC, probes, fit)

RESULTS = Path(__file__).resolve().parent / "results"
FIT_SEED0 = 2_000_000
#: Terrain loads, light to heavy, each with 0 to 20 obstacles.
LOADS = (
    {"n_ramps": 1, "n_kerbs": 1, "n_rough": 0},
    {"n_ramps": 2, "n_kerbs": 2, "n_rough": 1},
    {"n_ramps": 3, "n_kerbs": 4, "n_rough": 2, "ramp_incline": [7.0, 10.0], "kerb_height": [0.01, 0.02]},
)
CONFIGS = tuple(dict(load, n_obstacles=n) for load in LOADS for n in (0, 6, 12, 20))


def drive(env, k: int, seed: int) -> dict:
    """One world (config index, seed): its score's inputs (the flat logit per probe, the terrain inputs) and
    both probes' outcomes."""
    import worldgen
    from worldgen.envs.probes import run_episode
    from worldgen.envs.source import OneWorldSource
    from worldgen.errors import WorldgenError
    from worldgen.groundtruth import difficulty

    rec: dict = {"config": k, "seed": seed}
    try:
        world = worldgen.generate("terrain", seed, **CONFIGS[k])
    except WorldgenError as exc:
        return dict(rec, skipped=str(exc).splitlines()[0])
    f = difficulty.features(world.metadata)
    if f is None:
        return dict(rec, skipped="no reference path")
    rec["terrain"] = [f[name] for name, _ in difficulty.TERRAIN_FEATURES]
    rec["flat_logit"] = {p: difficulty.logit(f, difficulty.MODEL[p]) for p in PROBES}
    env.source = OneWorldSource(world)
    for probe in PROBES:
        info = run_episode(env, probe, seed=0, options={"world_seed": seed})
        rec[probe] = bool(info["success"])
    return rec


def collect(seeds: range, cache: Path, fresh: bool) -> list[dict]:
    todo = [(k, s) for s in seeds for k in range(len(CONFIGS))]
    if cache.exists() and not fresh:
        done = json.loads(cache.read_text())
        if [(r["config"], r["seed"]) for r in done] == todo:
            return done
    import gymnasium

    import worldgen.envs  # noqa: F401  (registers the id)

    env = gymnasium.make("worldgen/Navigation-v0", generator="minimal").unwrapped
    t0 = time.perf_counter()
    records = [drive(env, k, s) for k, s in todo]
    print(f"drove {len(todo)} worlds in {time.perf_counter() - t0:.0f} s", file=sys.stderr)
    RESULTS.mkdir(exist_ok=True)
    tmp = cache.with_suffix(".tmp")
    tmp.write_text(json.dumps(records))
    tmp.replace(cache)
    return records


def fit_probe(rows: list[dict], probe: str, l2: float = 1.0) -> dict:
    """Logistic regression (Newton, L2 penalty on the weights) of one probe's failure on the standardised
    terrain inputs, the flat model's logit an offset."""
    x = np.array([r["terrain"] for r in rows], dtype=float)
    y = np.array([float(not r[probe]) for r in rows])
    offset = np.array([r["flat_logit"][probe] for r in rows])
    return logistic(x, y, l2, offset)


def validate(rows: list[dict]) -> dict:
    from worldgen.groundtruth import difficulty

    def chance(r, probe, terrain):
        z = r["flat_logit"][probe]
        if terrain:
            f = dict(zip([n for n, _ in difficulty.TERRAIN_FEATURES], r["terrain"]))
            z += difficulty.logit(f, difficulty.TERRAIN_MODEL[probe], difficulty.TERRAIN_FEATURES)
        return 1 / (1 + np.exp(-z))

    out: dict = {"worlds": len(rows), "model": difficulty.TERRAIN_MODEL_ID, "probes": {}}
    flat = np.array([np.mean([chance(r, p, False) for p in PROBES]) for r in rows])
    both = np.array([np.mean([chance(r, p, True) for p in PROBES]) for r in rows])
    for probe in PROBES:
        fail = np.array([not r[probe] for r in rows])
        own = {t: np.array([chance(r, probe, t) for r in rows]) for t in (False, True)}
        # The probe's own chance against its outcomes: how well calibrated, not only how well ordered.
        loss = {t: float(-np.mean(np.where(fail, np.log(own[t]), np.log(1 - own[t])))) for t in own}
        out["probes"][probe] = {"failures": int(fail.sum()), "auc_flat": round(auc(flat, fail), 3),
                                "auc_terrain": round(auc(both, fail), 3), "log_loss_flat": round(loss[False], 3),
                                "log_loss_terrain": round(loss[True], 3)}
    return out


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--seeds", type=int, default=20, help="seeds per configuration (default 20: 240 worlds)")
    ap.add_argument("--fit", action="store_true", help="fit a new terrain model on the fitting seeds and print it")
    ap.add_argument("--fresh", action="store_true", help="drive every world again, ignoring kept records")
    args = ap.parse_args(argv)
    if args.fit:
        records = collect(range(FIT_SEED0, FIT_SEED0 + args.seeds), RESULTS / "terrain_difficulty_fit.json", args.fresh)
        rows = [r for r in records if "skipped" not in r]
        print(json.dumps({p: fit_probe(rows, p) for p in PROBES}, indent=1))
        return 0
    records = collect(range(args.seeds), RESULTS / "terrain_difficulty_val.json", args.fresh)
    v = validate([r for r in records if "skipped" not in r])
    v["skipped"] = sum("skipped" in r for r in records)
    for probe, p in v["probes"].items():
        print(f"{probe:9s} failures {p['failures']:4d}  AUC flat {p['auc_flat']:.3f}  with terrain {p['auc_terrain']:.3f}  "
              f"log loss flat {p['log_loss_flat']:.3f}  with terrain {p['log_loss_terrain']:.3f}")
    print(f"{v['worlds']} worlds, {v['skipped']} skipped; model {v['model']}")
    tmp = RESULTS / "terrain_difficulty.json.tmp"
    tmp.write_text(json.dumps(v, indent=1) + "\n")
    tmp.replace(RESULTS / "terrain_difficulty.json")
    return 0


if __name__ == "__main__":
    sys.exit(main())
