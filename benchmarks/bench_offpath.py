"""Certificates off the path, forced (docs/people.md, "Off the path"): every task of random dynamic worlds
certified off its static path, whether or not it has a timed path along it, re-proved by ``worldgen check``'s
own code and driven in MuJoCo.

    .venv/bin/python benchmarks/bench_offpath.py [--worlds N] [--start SEED] [--no-drive]

The worlds are bench_drive_dynamic's draws (every generator in turn, movers, people of every behaviour,
doors in every state), from ``--start`` (default 100, another set than that benchmark's). For each world
with something that moves, every task gets :func:`worldgen.people.offpath.off_path`'s certificate; the
world.json those certificates make is checked by :func:`worldgen.verify.timed.check_timed`, and, unless
``--no-drive``, the world carrying them is driven by ``worldgen drive --sim mujoco`` (a pass: the goal
reached, no contact). Figures to stdout and benchmarks/results/offpath.json; CPU time per search.
"""

from __future__ import annotations

import argparse
import json
import tempfile
import time
from dataclasses import replace
from pathlib import Path

import numpy as np
from bench_drive_dynamic import draw

RESULT = Path(__file__).resolve().parent / "results" / "offpath.json"


def certified_off_path(world):
    """(the world with every task's certificate off its path, how many found, CPU seconds of each search)."""
    from worldgen.feasibility.collision import Colliders
    from worldgen.people.behaviours import Tube, behaviours_of, tube_of
    from worldgen.people.offpath import off_path
    from worldgen.people.timed import limits_of
    from worldgen.scene.doors import open_scene
    from worldgen.world import World

    agents = list(world.scene.movers)
    reacting = iter(tube_of(b) for b in behaviours_of(world.params))
    tubes = [next(reacting) if m.person else Tube(0.0, 0.0) for m in agents]
    tracks = [np.asarray(m.trajectory, dtype=float) for m in agents]
    colliders = Colliders(open_scene(world.scene))
    found, cpu = [], []
    for task, path in zip(world.tasks, world.feasibility.paths):
        t0 = time.process_time()
        found.append(off_path(world.scene, colliders, task, path.waypoints, world.robot, limits_of(world.params),
                              tracks, [m.radius for m in agents], tubes, [m.loop and not m.person for m in agents]))
        cpu.append(time.process_time() - t0)
    report = replace(world.feasibility, timed_paths=tuple(found))
    made = World(world.generator, world.seed, world.params, world.scene, world.tasks, world.robot, report,
                 world.attempts, world.allow_infeasible)
    return made, sum(f is not None for f in found), cpu


def main() -> None:
    import worldgen
    from worldgen.errors import InfeasibleError
    from worldgen.verify.timed import TimedPathError, check_timed

    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--worlds", type=int, default=80)
    parser.add_argument("--start", type=int, default=100)
    parser.add_argument("--no-drive", action="store_true")
    args = parser.parse_args()
    out = {"worlds": args.worlds, "start": args.start, "tasks": 0, "found": 0, "checked": 0, "checked_bad": [],
           "drives": 0,
           "drive_failures": [], "cpu": []}
    with tempfile.TemporaryDirectory(prefix="bench-offpath-") as tmp:
        for k in range(args.worlds):
            generator, params = draw(k, args.start)
            seed = args.start + k
            try:
                world = worldgen.generate(generator, seed=seed, **params)
            except InfeasibleError:
                continue
            if not world.scene.movers:
                continue
            made, found, cpu = certified_off_path(world)
            out["tasks"] += len(world.tasks)
            out["found"] += found
            out["cpu"] += [round(c, 3) for c in cpu]
            note = ""
            if found < len(world.tasks):  # check_timed asks a world recorded feasible for every certificate
                print(f"{k:4d} {generator:9s} seed {seed:5d} off the path {found} of {len(world.tasks)}", flush=True)
                continue
            out["checked"] += 1
            try:
                check_timed(made.metadata_for({}), made)
            except TimedPathError as exc:
                out["checked_bad"].append({"generator": generator, "seed": seed, "why": str(exc)})
            if not args.no_drive:
                from worldgen.sim.drive import drive

                outcome = drive(made, Path(tmp) / str(k), sim="mujoco")
                out["drives"] += 1
                ok = outcome.passed and not outcome.contacts
                note = "drive ok" if ok else f"drive FAIL {outcome.ended} {outcome.contacts[:1]}"
                if not ok:
                    out["drive_failures"].append({"generator": generator, "seed": seed, "params": params,
                                                  "ended": outcome.ended, "contacts": outcome.contacts[:2]})
            print(f"{k:4d} {generator:9s} seed {seed:5d} off the path {found} of {len(world.tasks)} {note}", flush=True)
    cpu = np.array(out["cpu"] or [0.0])
    passed = out["drives"] - len(out["drive_failures"])
    print(f"{out['found']} of {out['tasks']} tasks certified off the path; of the {out['checked']} worlds certified "
          f"so, {len(out['checked_bad'])} refused by check_timed; {passed} of {out['drives']} drives pass; "
          f"search CPU median {np.median(cpu):.2f} s, max {cpu.max():.2f} s")
    RESULT.parent.mkdir(parents=True, exist_ok=True)
    RESULT.write_text(json.dumps(out, indent=1, sort_keys=True) + "\n")


if __name__ == "__main__":
    main()
