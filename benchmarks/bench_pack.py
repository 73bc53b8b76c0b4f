"""Pack build throughput: cluttered 20 x 20 m worlds with 50 obstacles, every format, maps and metadata.

    .venv/bin/python benchmarks/bench_pack.py [--worlds 1000] [--jobs 1,2] [--preview]

Each --jobs value builds the same recipe into a fresh temporary pack in its own
child process, which reports the wall time and the peak resident memory of
itself and its workers (resource.getrusage RUSAGE_SELF and RUSAGE_CHILDREN,
ru_maxrss: the largest single process, not a sum). The manifests of all runs
must be byte-identical. The table goes to stdout, the figures to
benchmarks/results/pack.json. Not part of the test suite.
"""

from __future__ import annotations

import argparse
import json
import os
import platform
import resource
import subprocess
import sys
import tempfile
import time
from pathlib import Path

RECIPE = """\
name: bench
preview: {preview}
seeds: {worlds}
worlds:
  - generator: cluttered
    params:
      size: [20, 20]
      n_obstacles: 50
"""


#: Issue 9's target: this pack (1,000 worlds, no preview) with --jobs 2 in at most 20 s on a 2-core machine.
TARGET_WORLDS, TARGET_JOBS, TARGET_SECONDS = 1000, 2, 20.0


def one(worlds: int, jobs: int, out: Path, preview: bool) -> dict:
    from worldgen.pack import build_pack, parse_recipe

    recipe = parse_recipe(RECIPE.format(worlds=worlds, preview=str(preview).lower()), "bench.yaml", "bench")
    start = time.perf_counter()
    summary = build_pack(recipe, out, jobs=jobs)
    seconds = time.perf_counter() - start
    rss = max(resource.getrusage(resource.RUSAGE_SELF).ru_maxrss, resource.getrusage(resource.RUSAGE_CHILDREN).ru_maxrss)
    return {"jobs": jobs, "worlds": summary.built, "rejected_jobs": summary.rejected_jobs,
            "extra_draws": summary.extra_draws, "seconds": round(seconds, 3),
            "worlds_per_second": round(summary.built / seconds, 2), "peak_rss_mb": round(rss / 1024, 1)}


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--worlds", type=int, default=1000)
    ap.add_argument("--jobs", default="1,2", help="comma-separated --jobs values")
    ap.add_argument("--preview", action="store_true", help="also write preview.png (off in packs by default)")
    ap.add_argument("--one", type=int, help=argparse.SUPPRESS)  # internal: run one build in this process
    ap.add_argument("--out", type=Path, help=argparse.SUPPRESS)
    args = ap.parse_args()
    if args.one:
        print(json.dumps(one(args.worlds, args.one, args.out, args.preview)))
        return
    runs = []
    with tempfile.TemporaryDirectory(prefix="bench-pack-") as tmp:
        for jobs in (int(j) for j in args.jobs.split(",")):
            out = Path(tmp) / f"jobs{jobs}"
            cmd = [sys.executable, __file__, "--one", str(jobs), "--worlds", str(args.worlds), "--out", str(out)]
            cmd += ["--preview"] if args.preview else []
            run = json.loads(subprocess.run(cmd, check=True, capture_output=True, text=True).stdout)
            run["manifest_bytes"] = (out / "manifest.json").stat().st_size
            runs.append(run)
            print(f"--jobs {jobs}: {run['worlds']} worlds in {run['seconds']:.1f} s, "
                  f"{run['worlds_per_second']:.1f} worlds/s, peak RSS {run['peak_rss_mb']:.0f} MB", flush=True)
        manifests = {(Path(tmp) / f"jobs{r['jobs']}" / "manifest.json").read_bytes() for r in runs}
    same = len(manifests) == 1
    base = runs[0]["seconds"]
    for r in runs:
        r["speedup"] = round(base / r["seconds"], 2)
    print(f"speed-up vs --jobs {runs[0]['jobs']}: " + ", ".join(f"jobs {r['jobs']} {r['speedup']}x" for r in runs))
    print(f"manifests identical across --jobs: {same}")
    targets = []
    for r in runs:
        if r["jobs"] == TARGET_JOBS and args.worlds == TARGET_WORLDS and not args.preview:
            met = r["seconds"] <= TARGET_SECONDS
            targets.append({"target": f"{TARGET_WORLDS} worlds with --jobs {TARGET_JOBS}", "limit": TARGET_SECONDS,
                            "measured": r["seconds"], "unit": "s", "met": met})
            print(f"target (issue 9): {'met' if met else 'MISSED'}: {TARGET_WORLDS} worlds with --jobs {TARGET_JOBS} "
                  f"in {r['seconds']:.1f} s (limit {TARGET_SECONDS:g} s)")
    result = {"worlds": args.worlds, "preview": args.preview, "cpus": os.cpu_count(), "python": platform.python_version(),
              "runs": runs, "manifests_identical": same, "targets": targets}
    target = Path(__file__).parent / "results" / "pack.json"
    target.parent.mkdir(exist_ok=True)
    target.write_text(json.dumps(result, indent=2, sort_keys=True) + "\n")
    if not same:
        sys.exit("manifests differ across --jobs")


if __name__ == "__main__":
    main()
