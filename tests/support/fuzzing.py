"""Fuzzing every generator's parameter space, each request in a child process.

A request is (generator, seed, params). Children are long-lived worker
processes (``python tests/support/fuzzing.py --worker``) reading one JSON request per
line and answering one JSON line; a child that dies (a native abort inside
FCL, MuJoCo or lxml) or hangs is recorded as that request's ``crash`` or
``timeout`` and replaced, so one crash fails the test instead of ending the run.

A request's acceptable outcomes are:

``world``  a world came out, and it passes the independent re-check: written to
           a folder, ``worldgen check`` finds it OK (files, schema, regeneration,
           feasibility re-run, byte-for-byte reproduction), and each reference
           path, driven as a trajectory, touches nothing by the oracles' own FCL
           sampling and keeps the clearance the world claims;
``error``  one :class:`~worldgen.errors.WorldgenError` whose message is one line.

Anything else (``bug``: another exception, a failed re-check, a multi-line
message; ``crash``; ``timeout``) is a failure. ``tests/test_fuzz.py`` runs a
derandomised few hundred requests; ``benchmarks/fuzz_sweep.py`` runs the whole
ranges, longer.
"""

from __future__ import annotations

import json
import math
import os
import selectors
import subprocess
import sys
import tempfile
import time
from concurrent.futures import ThreadPoolExecutor
from dataclasses import dataclass
from typing import Any, Optional

import numpy as np

#: Parameters whose upper end makes a request slow (memory and time grow with them)
#: rather than different in kind; the CI fuzz caps them, the benchmark sweep does not.
CI_CAPS = {
    "size": 30.0, "length": 30.0, "segments": 30.0, "n_obstacles": 60, "density": 0.6,
    "lidar_samples": 2000, "max_attempts": 5, "n_tasks": 3, "n_movers": 3, "n_doors": 4,
    "side_openings": 4, "task_region": 30.0, "mover_waypoints": 8, "grid_cols": 60, "grid_rows": 60,
}
#: Floor for parameters whose lower end only makes the occupancy map huge.
CI_FLOORS = {"map_resolution": 0.05}


@dataclass
class Outcome:
    request: dict
    kind: str  # world | error | bug | crash | timeout
    detail: str = ""
    seconds: float = 0.0

    @property
    def ok(self) -> bool:
        return self.kind in ("world", "error")


def _value(p, rng: np.random.Generator, caps: dict, floors: dict) -> Any:
    lo = p.low
    hi = p.high
    if p.name in caps and hi is not None:
        hi = min(hi, caps[p.name])
    if p.name in floors and lo is not None:
        lo = max(lo, floors[p.name])
    if p.kind == "bool":
        return bool(rng.integers(2))
    if p.kind == "choice":
        return p.choices[int(rng.integers(len(p.choices)))]
    if p.kind == "words":
        return ",".join(p.choices[int(i)] for i in rng.integers(len(p.choices), size=int(rng.integers(1, 4))))

    def number():
        # Both ends of the range are drawn as often as the inside: edges are where defects live.
        where = rng.random()
        if where < 0.25:
            x = lo
        elif where < 0.5:
            x = hi
        elif lo is not None and hi is not None and lo > 0 and hi / lo > 100:
            x = float(math.exp(rng.uniform(math.log(lo), math.log(hi))))  # log-uniform over wide ranges
        else:
            x = float(rng.uniform(lo, hi))
        if p.kind == "int":
            return int(round(x))
        return round(float(x), 4)

    if p.kind in ("float", "int"):
        return number()
    if p.kind == "pair":
        return [number(), number()]
    if p.kind == "range":
        return sorted([number(), number()])
    if p.kind == "triple":
        return [number(), number(), number()]
    if p.kind == "list":
        return [number() for _ in range(int(rng.integers(1, 5)))]
    raise AssertionError(p.kind)


def draw_request(rng: np.random.Generator, generator: str, caps: dict = CI_CAPS,
                 floors: dict = CI_FLOORS) -> dict:
    """A request setting a few of the generator's parameters, often at an end of their range.

    Besides single parameters at their ends, the edges that combine parameters
    are drawn on purpose: zero clearance, a robot exactly as tall as the door or
    the walls, obstacles with no gap between them, a corridor exactly as wide as
    the footprint needs.
    """
    from worldgen.generators import get

    specs = {p.name: p for p in get(generator).params}
    params: dict[str, Any] = {}
    names = sorted(specs)
    for i in rng.choice(len(names), size=int(rng.integers(1, 5)), replace=False):
        p = specs[names[int(i)]]
        if p.name in ("spawn", "goal"):
            continue  # fixed poses far outside the room are one ParameterError; the generators draw the rest
        params[p.name] = _value(p, rng, caps, floors)
    edge = rng.random()
    if edge < 0.2:
        params["clearance"] = 0.0
    if generator == "door" and rng.random() < 0.3:
        params["robot_height"] = params.get("door_height", 2.0)
    if "wall_height" in specs and rng.random() < 0.1:
        params["robot_height"] = min(params.get("wall_height", specs["wall_height"].default), 5.0)
    if "min_gap" in specs and rng.random() < 0.2:
        params["min_gap"] = 0.0
    if generator == "corridor" and rng.random() < 0.3:
        need = 2 * (params.get("robot_radius", 0.2) + params.get("clearance", 0.05))
        params["width"] = round(need + float(rng.choice([0.0, 0.001, 0.01])), 4)
    return {"generator": generator, "seed": int(rng.integers(0, 2**31)), "params": params}


# ---------------------------------------------------------------- the child

def _recheck(world) -> Optional[str]:
    """None when the world passes the independent re-check, else what failed."""
    from worldgen.testing import oracles
    from worldgen.verify import check_folder

    with tempfile.TemporaryDirectory() as tmp:
        folder = world.write(tmp)
        verdict = check_folder(folder)
        if not verdict.ok:
            return verdict.line()
    meta = world.metadata
    if not meta["feasibility"]["feasible"]:
        return None  # made on purpose (--allow-infeasible or infeasible=true): nothing to drive
    clearance = meta["robot"]["clearance"]
    for task in meta["tasks"]:
        path = task.get("path")
        if not path or task.get("requires_door_open"):
            continue  # a path through doors is proven with the leaves at their open limit
        xy = np.asarray(path["waypoints"], dtype=float)
        traj = np.column_stack([np.arange(len(xy), dtype=float), xy])
        hits = oracles.collisions(traj, world)
        if hits:
            return f"{task['id']}: the reference path touches {hits[0].entity}"
        gap = oracles.min_clearance(traj, world)
        if gap < clearance - 1e-6:
            return f"{task['id']}: the reference path keeps {gap:.6f} m, the world claims {clearance} m"
    return None


def _answer(request: dict) -> dict:
    import worldgen
    from worldgen.errors import WorldgenError

    try:
        world = worldgen.generate(request["generator"], request["seed"],
                                  allow_infeasible=request.get("allow_infeasible", False), **request["params"])
    except WorldgenError as exc:
        text = str(exc)
        if "\n" in text or not text:
            return {"kind": "bug", "detail": f"{type(exc).__name__} not one line: {text[:300]!r}"}
        return {"kind": "error", "detail": text}
    except Exception as exc:  # noqa: BLE001 - anything else is what the fuzz is for
        return {"kind": "bug", "detail": f"{type(exc).__name__}: {exc}"[:500]}
    try:
        problem = _recheck(world)
    except Exception as exc:  # noqa: BLE001
        return {"kind": "bug", "detail": f"re-check raised {type(exc).__name__}: {exc}"[:500]}
    if problem:
        return {"kind": "bug", "detail": f"re-check failed: {problem}"[:500]}
    return {"kind": "world", "detail": world.world_id}


def worker() -> None:
    for line in sys.stdin:
        request = json.loads(line)
        if request.get("abort"):  # the harness's own test: a native crash
            os.abort()
        reply = _answer(request)
        sys.stdout.write(json.dumps(reply) + "\n")
        sys.stdout.flush()


# ---------------------------------------------------------------- the parent

class _Child:
    def __init__(self):
        self.proc = None

    def _start(self):
        env = dict(os.environ, PYTHONFAULTHANDLER="1")
        self.proc = subprocess.Popen([sys.executable, __file__, "--worker"], stdin=subprocess.PIPE,
                                     stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, env=env)

    def ask(self, request: dict, timeout: float) -> Outcome:
        if self.proc is None or self.proc.poll() is not None:
            self._start()
        start = time.perf_counter()
        self.proc.stdin.write(json.dumps(request) + "\n")
        self.proc.stdin.flush()
        sel = selectors.DefaultSelector()
        sel.register(self.proc.stdout, selectors.EVENT_READ)
        ready = sel.select(timeout)
        sel.close()
        line = self.proc.stdout.readline() if ready else ""
        took = time.perf_counter() - start
        if line:
            reply = json.loads(line)
            return Outcome(request, reply["kind"], reply["detail"], took)
        if not ready:
            self.proc.kill()
            self.proc.wait()
            self.proc = None
            return Outcome(request, "timeout", f"no answer in {timeout:g} s", took)
        code = self.proc.wait()
        err = self.proc.stderr.read()
        self.proc = None
        return Outcome(request, "crash", f"child exited {code}: {err.strip()[-400:]}", took)

    def close(self):
        if self.proc is not None and self.proc.poll() is None:
            self.proc.stdin.close()
            self.proc.wait(timeout=30)


def run_requests(requests: list[dict], jobs: int = 2, timeout: float = 60.0) -> list[Outcome]:
    """Every request's outcome, in order, answered by ``jobs`` worker processes."""
    shares = [requests[i::jobs] for i in range(jobs)]

    def serve(share):
        child = _Child()
        try:
            return [child.ask(r, timeout) for r in share]
        finally:
            child.close()

    with ThreadPoolExecutor(jobs) as pool:
        answered = list(pool.map(serve, shares))
    out: list[Optional[Outcome]] = [None] * len(requests)
    for j, share in enumerate(answered):
        for k, outcome in enumerate(share):
            out[j + k * jobs] = outcome
    return out  # type: ignore[return-value]


if __name__ == "__main__" and sys.argv[1:] == ["--worker"]:
    worker()
