"""Generate a world, read its ground truth, load it in MuJoCo, and write its files.

    .venv/bin/python examples/quickstart.py [OUT_DIR]

What a navigation test does with worldgen, in a few lines: the world comes with
the truth an assertion needs (spawn, goal, the shortest path for the robot's
footprint and its clearance), and loads in a simulator straight from memory.
"""

from __future__ import annotations

import sys
import tempfile

import mujoco
import numpy as np

import worldgen


def main(out_dir: str) -> None:
    world = worldgen.generate("cluttered", seed=7, size=[20, 20], n_obstacles=50)
    meta = world.metadata
    task = meta["tasks"][0]
    print(f"world {meta['world_id']}: {meta['metrics']['obstacle_count']} obstacles, "
          f"feasible after {meta['feasibility']['attempts']} draw(s)")
    print(f"spawn {task['spawn'][:2]} -> goal {task['goal'][:2]}: shortest path {task['path']['length']:.3f} m "
          f"(straight line {task['straight_line_distance']:.3f} m), clearance {task['path']['min_clearance']:.3f} m")

    # In memory, as an RL loop would: no files touched.
    model = mujoco.MjModel.from_xml_string(world.to_mjcf())
    data = mujoco.MjData(model)
    mujoco.mj_step(model, data, nstep=500)
    assert not any(w.number for w in data.warning), "MuJoCo reported warnings"
    first = meta["entities"][5]
    pos = data.geom(first["name"]).xpos
    print(f"MuJoCo: {model.ngeom} geoms; '{first['name']}' at {np.round(pos, 3).tolist()} "
          f"(world.json says {first['pose'][:3]})")

    folder = world.write(out_dir)
    print(f"files written to {folder}: {', '.join(sorted(p['path'] for p in meta['files'].values()))}")


if __name__ == "__main__":
    main(sys.argv[1] if len(sys.argv) > 1 else tempfile.mkdtemp(prefix="worldgen-"))
