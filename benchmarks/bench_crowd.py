"""What the crowd files (pedsim.xml, hunav_agents.yaml) cost when asked for, against the 50-box pipeline.

    .venv/bin/python benchmarks/bench_crowd.py [--runs N]

The 50-box pipeline is bench_pipeline.py's: ``generate("cluttered", size=[20, 20], n_obstacles=50)`` with
its three default formats and world.json, in memory (median over seeds 0 .. runs-1). A crowd file needs
people, so each export is timed on the people benchmark's world (the same 50 boxes and 20 people walking
60 s, bench_people.py), rendered afresh each time (median over ``runs`` renderings): "share" is the
export over the 50-box pipeline, "share_of_its_world" over that world's own pipeline (the same, its people
walked and certified; median over runs / 3 seeds). "default_unchanged" says that world.json and the files of a default
write of that world are the same bytes from a World that rendered the crowd files first as from one that
never did.
"""

from __future__ import annotations

import argparse
import json
import statistics
import time

import worldgen
from worldgen.export import crowd
from worldgen.export.formats import FORMATS, render

BOXES = {"size": [20, 20], "n_obstacles": 50}
PEOPLE = {**BOXES, "n_people": 20}


def _pipeline(seed: int, params=BOXES) -> float:
    start = time.perf_counter()
    world = worldgen.generate("cluttered", seed=seed, **params)
    world.metadata_for(world.rendered_files(FORMATS))
    return time.perf_counter() - start


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--runs", type=int, default=15)
    runs = parser.parse_args().runs
    _pipeline(0)  # imports and caches, once
    pipeline = statistics.median(_pipeline(seed) for seed in range(runs))
    default = worldgen.generate("cluttered", seed=0, **PEOPLE).folder_blobs(preview=False)
    world = worldgen.generate("cluttered", seed=0, **PEOPLE)  # another World: nothing of the first is shared
    people = statistics.median(_pipeline(seed, PEOPLE) for seed in range(max(3, runs // 3)))
    out = {"pipeline_50_boxes_ms": round(pipeline * 1e3, 2), "pipeline_50_boxes_20_people_ms": round(people * 1e3, 2),
           "runs": runs}
    for fmt in ("pedsim", "hunav"):
        times = []
        for _ in range(runs):
            crowd._ROUTES.clear()  # a fresh World's scene: its corners not yet found
            start = time.perf_counter()
            data = render(fmt, world.scene, world.world_id, world.params, world=world)
            times.append(time.perf_counter() - start)
        out[f"{fmt}_ms"] = round(statistics.median(times) * 1e3, 2)
        out[f"{fmt}_share"] = round(statistics.median(times) / pipeline, 3)
        out[f"{fmt}_share_of_its_world"] = round(statistics.median(times) / people, 3)
        out[f"{fmt}_bytes"] = len(data)
        world.export_bytes(fmt)
    out["default_unchanged"] = world.folder_blobs(preview=False) == default
    print(json.dumps(out, indent=2))


if __name__ == "__main__":
    main()
