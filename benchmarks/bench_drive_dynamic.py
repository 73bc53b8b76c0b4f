"""``worldgen drive`` in random dynamic worlds (issue 37): how many drives succeed, and why the others fail.

    .venv/bin/python benchmarks/bench_drive_dynamic.py [--worlds N] [--start SEED] [--all-cores]
        [--sim mujoco|gazebo] [--gz-release RELEASE] [--generator NAME]

World k is drawn from its own seed (``--start`` + k): a generator (cluttered, door, barn, corridor,
minimal, in turn), and for it movers (0 to 3), people (0 to 6, each behaviour in turn and a mix) and, in
the door generator, every door's state and swing drawn (``state=random``, ``swing=random``). A draw the
generator refuses (no timed path among the people, a door that cannot swing) is counted as refused and
not driven. ``--generator`` keeps only the draws of that generator (the same draws, the others skipped, not
counted). A drive succeeds when the judge passes the run (the goal reached in time, no collision) and
MuJoCo saw no contact of the robot but with door leaves (Gazebo's bridge reports no contacts: there the judge,
which places every person and mover where world.json has them, decides alone). A failure is listed with what the drive
followed (``plan``), how it ended, the first contact, the world's parameters and a ``cause`` read from
world.json (no schedule exists; a mover runs over the spawn or the goal; the schedule was left; a pull
door's leaf sweeps the spawn).

Pinned to one core (--all-cores to not pin; a Gazebo server and the drive bridge inherit the pin). The table
goes to stdout, the figures to benchmarks/results/drive_dynamic.json (``--sim gazebo``:
drive_dynamic_gazebo.json), each failure marked with whether its world has movers (issue 37 item 1 certifies
them; until then a mover's failure is expected and listed apart).
"""

from __future__ import annotations

import argparse
import json
import os
import platform
import tempfile
import time
from pathlib import Path

import numpy as np

RESULTS = {"mujoco": Path(__file__).resolve().parent / "results" / "drive_dynamic.json",
           "gazebo": Path(__file__).resolve().parent / "results" / "drive_dynamic_gazebo.json"}
GENERATORS = ("cluttered", "door", "barn", "corridor", "minimal")
BEHAVIOURS = ("impassive", "regular", "surprised", "scared", "curious", "impassive,regular,surprised,scared,curious")
#: Per generator, what keeps a draw small enough to walk people in quickly and wide enough to pass them.
BASE = {"cluttered": {"size": [10.0, 10.0], "n_obstacles": 6}, "door": {"state": "random", "swing": "random"},
        "barn": {}, "corridor": {"width": 3.0}, "minimal": {}}


def draw(k: int, start: int) -> tuple[str, dict]:
    """World k's generator and parameters, from its own seed."""
    rng = np.random.default_rng([start, k])
    generator = GENERATORS[k % len(GENERATORS)]
    params = dict(BASE[generator])
    params["n_movers"] = int(rng.integers(0, 4))
    people = int(rng.integers(0, 7))
    if people:
        params.update(n_people=people, people_duration=20.0,
                      people_behaviour=BEHAVIOURS[int(rng.integers(0, len(BEHAVIOURS)))])
    if params["n_movers"] == 0 and not people and generator != "door":
        params["n_movers"] = 1  # every world has something that moves (a door world has its doors)
    return generator, params


def cause(world, outcome) -> str:
    """Why a drive failed, as far as world.json tells: no certificate, the certificate left (the follower's
    lag), a mover over the spawn or the goal, or a door."""
    from worldgen.scene.motion import positions_at

    meta = world.metadata_for({})
    task, robot = meta["tasks"][0], meta["robot"]
    movers = meta.get("dynamic_obstacles") or []
    why = []
    # MuJoCo's own contacts, else (Gazebo's bridge reports none) the judge's collisions
    if outcome.plan == "timed_path" and (outcome.contacts or outcome.run["collisions"]):
        why.append("the robot left its certificate (tasks[].timed_path)")
    elif movers and outcome.plan != "timed_path":
        why.append(f"no certificate among the movers and people; it followed the {outcome.plan.replace('_', ' ')}")
    if movers:
        t = np.arange(0.0, float(task["time_limit"]), 0.01)
        at = positions_at([np.asarray(m["trajectory"]) for m in movers], [True] * len(movers), t)
        for where in ("spawn", "goal"):
            gap = np.hypot(*(at - np.asarray(task[where][:2])).transpose(2, 0, 1)) - \
                (np.array([m["radius"] for m in movers]) + robot["radius"])
            k, j = np.unravel_index(np.argmin(gap), gap.shape)
            if gap[k, j] < 0:
                why.append(f"{movers[j]['name']} runs over the {where} at {t[k]:.2f} s")
    if outcome.ended == "stuck" and outcome.doors_opened:
        for d in meta.get("doors") or []:
            if d["name"] not in outcome.doors_opened:
                continue
            reach = float(np.hypot(*(np.asarray(task["spawn"][:2]) - np.asarray(d["hinge"][:2]))))
            why.append(f"stuck at pull door {d['name']}, its leaf opening onto the robot" + (
                f" (the leaf sweeps the spawn, {reach:.2f} m from its hinge)" if reach < d["width"] + robot["radius"]
                else ""))
    return "; ".join(why) or "unknown"


def run(n: int, start: int, sim: str = "mujoco", gz_release=None, only=None) -> dict:
    import worldgen
    from worldgen.errors import InfeasibleError, WorldgenError
    from worldgen.sim.drive import drive

    out = {"sim": sim, "gz_release": gz_release, "worlds": n, "start": start, "generator": only, "driven": 0,
           "refused": 0, "succeeded": 0, "plans": {}, "drives": [], "failures": [], "refusals": []}
    t0 = time.perf_counter()
    with tempfile.TemporaryDirectory(prefix="bench-drive-") as tmp:
        for k in range(n):
            generator, params = draw(k, start)
            seed = start + k
            if only is not None and generator != only:
                continue
            cpu = time.process_time()
            try:
                world = worldgen.generate(generator, seed=seed, **params)
            except InfeasibleError as exc:
                out["refused"] += 1
                out["refusals"].append({"generator": generator, "seed": seed, "params": params,
                                        "generate_cpu": round(time.process_time() - cpu, 2),
                                        "why": str(exc).splitlines()[0][:200]})
                print(f"{k:4d} {generator:9s} seed {seed:5d} refused", flush=True)
                continue
            cpu = time.process_time() - cpu
            # Gazebo loads world.sdf from disk
            where = world.write(Path(tmp) / "worlds", preview=False) if sim == "gazebo" else world
            t1 = time.perf_counter()
            try:
                outcome = drive(where, Path(tmp) / str(k), sim=sim, gz_release=gz_release)
            except WorldgenError as exc:  # a simulator that failed under the drive is a failure of the drive
                out["driven"] += 1
                out["failures"].append({"generator": generator, "seed": seed, "params": params, "plan": None,
                                        "ended": "error", "movers": bool(world.metadata_for({}).get("dynamic_obstacles")),
                                        "cause": str(exc).splitlines()[0][:300]})
                print(f"{k:4d} {generator:9s} seed {seed:5d} error: {exc}", flush=True)
                continue
            wall = time.perf_counter() - t1
            out["driven"] += 1
            out["plans"][outcome.plan] = out["plans"].get(outcome.plan, 0) + 1
            ok = outcome.passed and not outcome.contacts
            out["succeeded"] += ok
            meta = world.metadata_for({})
            out["drives"].append({"generator": generator, "seed": seed, "plan": outcome.plan, "ok": bool(ok),
                                  "generate_cpu": round(cpu, 2), "attempts": world.attempts,
                                  "off_path": "off the static path" in world.feasibility.checks[-1].detail,
                                  "wall": round(wall, 2), "sim_seconds": round(outcome.sim_seconds, 2),
                                  "movers": len(meta.get("dynamic_obstacles") or []),
                                  "people": len(meta.get("people") or []), "doors": len(meta.get("doors") or [])})
            if not ok:
                run = outcome.run
                out["failures"].append({
                    "generator": generator, "seed": seed, "params": params, "plan": outcome.plan,
                    "ended": outcome.ended, "sim_contact": outcome.contacts[:1] if outcome.contacts else [],
                    "judged_collision": run["collisions"][:1], "reached_goal": run["reached_goal"],
                    "doors_opened": outcome.doors_opened, "movers": bool(meta.get("dynamic_obstacles")),
                    "cause": cause(world, outcome)})
            print(f"{k:4d} {generator:9s} seed {seed:5d} {outcome.plan:10s} {outcome.ended:10s} "
                  f"{'ok' if ok else 'FAIL'}", flush=True)
    out["seconds"] = round(time.perf_counter() - t0, 1)
    return out


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--worlds", type=int, default=200)
    parser.add_argument("--start", type=int, default=0)
    parser.add_argument("--all-cores", action="store_true")
    parser.add_argument("--sim", choices=("mujoco", "gazebo"), default="mujoco")
    parser.add_argument("--gz-release", default=None, help="with --sim gazebo: the release (default: drive's)")
    parser.add_argument("--generator", choices=GENERATORS, default=None, help="only the draws of this generator")
    args = parser.parse_args()
    if not args.all_cores and hasattr(os, "sched_setaffinity"):
        os.sched_setaffinity(0, {min(os.sched_getaffinity(0))})
    result = run(args.worlds, args.start, args.sim, args.gz_release, args.generator)
    result["machine"] = platform.platform()
    print(f"driven {result['driven']} of {result['worlds']} ({result['refused']} refused by the generator): "
          f"{result['succeeded']} succeeded; plans {result['plans']}; {result['seconds']} s")
    for movers in (False, True):
        print("failures in worlds with movers (uncertified):" if movers else "failures in worlds without movers:")
        for f in result["failures"]:
            if f["movers"] == movers:
                print("  FAIL", json.dumps(f, sort_keys=True))
    RESULTS[args.sim].parent.mkdir(parents=True, exist_ok=True)
    RESULTS[args.sim].write_text(json.dumps(result, indent=1, sort_keys=True) + "\n")


if __name__ == "__main__":
    main()
