"""`worldgen drive` wall time: a ~10 m reference path driven in Gazebo (and in MuJoCo beside it).

    .venv/bin/python benchmarks/bench_drive.py [--repeats 5]

The world: cluttered, seed 3, size 12 x 12 m (a 10.35 m reference path). Each run is the real command
in a fresh process, `worldgen drive WORLD --sim gazebo --out DIR`, timed from start to exit: Python's
imports, Gazebo's start-up (headless, unthrottled, paused), the spawn, the lockstep drive at 20 Hz
through the C++ bridge (built once before timing), the bag and the judge. Median of --repeats.
Without Gazebo the Gazebo row says so and the MuJoCo row still runs.

Prints a table with the target met or missed; writes benchmarks/results/drive.json.
"""

from __future__ import annotations

import argparse
import json
import re
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT))

TARGET_S = 10.0  # wall seconds for a 10 m path in Gazebo, 2 cores


def timed_drive(folder: Path, sim: str, out: Path) -> tuple[float, str]:
    started = time.perf_counter()
    done = subprocess.run([sys.executable, "-m", "worldgen", "drive", str(folder), "--sim", sim, "--out", str(out)],
                          capture_output=True, text=True, cwd=ROOT)
    wall = time.perf_counter() - started
    if done.returncode != 0:
        raise SystemExit(f"worldgen drive --sim {sim} failed ({done.returncode}): {done.stdout}{done.stderr}")
    return wall, done.stdout.splitlines()[0]


def main() -> int:
    ap = argparse.ArgumentParser()
    ap.add_argument("--repeats", type=int, default=5)
    args = ap.parse_args()
    import worldgen
    from worldgen.errors import MissingDependencyError

    results: dict = {"world": "cluttered seed 3 size 12x12", "repeats": args.repeats, "target_s": TARGET_S}
    with tempfile.TemporaryDirectory(prefix="bench-drive-") as tmp:
        folder = worldgen.generate("cluttered", seed=3, size=[12, 12]).write(Path(tmp) / "worlds", preview=False)
        length = json.loads((folder / "world.json").read_text())["tasks"][0]["path"]["length"]
        results["path_length_m"] = length
        sims = ["mujoco"]
        try:
            from worldgen.sim.bridge import build_bridge
            from worldgen.sim.gazebo import locate

            build_bridge(locate().env)  # the one-off build is not part of a drive's time
            sims.append("gazebo")
        except MissingDependencyError as exc:
            print(f"gazebo: skipped ({exc})")
        for sim in sims:
            walls, line = [], ""
            for k in range(args.repeats):
                wall, line = timed_drive(folder, sim, Path(tmp) / f"{sim}-{k}")
                walls.append(wall)
            simulated = float(re.search(r"\(([\d.]+) s simulated", line).group(1))
            results[sim] = {"median_wall_s": statistics.median(walls), "walls_s": walls, "simulated_s": simulated,
                            "verdict": line}
    print(f"worldgen drive, {length:.2f} m reference path, median of {args.repeats} fresh processes")
    print(f"{'sim':<8} {'wall (s)':>9} {'simulated (s)':>14}  target")
    for sim in ("gazebo", "mujoco"):
        if sim in results:
            r = results[sim]
            target = (f"<= {TARGET_S:g} s: {'met' if r['median_wall_s'] <= TARGET_S else 'MISSED'}"
                      if sim == "gazebo" else "-")
            print(f"{sim:<8} {r['median_wall_s']:>9.2f} {r['simulated_s']:>14.2f}  {target}")
    out = ROOT / "benchmarks" / "results"
    out.mkdir(parents=True, exist_ok=True)
    (out / "drive.json").write_text(json.dumps(results, indent=2, sort_keys=True) + "\n")
    return 0


if __name__ == "__main__":
    sys.exit(main())
