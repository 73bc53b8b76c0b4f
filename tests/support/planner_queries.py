"""The stored query set of the exact planner: worlds, the configuration spaces the planner meets in them
(the robot's, as feasibility builds it; a person's, as the crowd builds it), and free start/goal pairs.

``python tests/support/planner_queries.py`` rewrites ``tests/feasibility/data/planner_queries.json`` with the lengths the
current planner gives; it was written once, before the planner was made faster, and the test
(test_planner_queries.py) holds every later planner to those answers.
"""

from __future__ import annotations

import json
import sys
from pathlib import Path

import numpy as np

import worldgen
from worldgen.feasibility.cspace import ConfigSpace
from worldgen.feasibility.geometry import Obstacles2D
from worldgen.people.places import SLACK, people_footprints
from worldgen.scene.footprint import SAFETY, robot_footprints

__all__ = ["DATA", "WORLDS", "space", "queries"]

DATA = Path(__file__).resolve().parents[1] / "feasibility" / "data" / "planner_queries.json"

#: (generator, seed, params, space: "robot" or a person's radius, random queries): cluttered rooms of the
#: benchmarks' sizes, walls, doors, BARN's cells.
WORLDS = [
    ("cluttered", 0, {"size": [20.0, 20.0], "n_obstacles": 50}, "robot", 40),
    ("cluttered", 1, {"size": [20.0, 20.0], "n_obstacles": 50}, "robot", 40),
    ("cluttered", 2, {"size": [20.0, 20.0], "n_obstacles": 50}, 0.25, 40),
    ("cluttered", 3, {"size": [20.0, 20.0], "n_obstacles": 200}, "robot", 30),
    ("cluttered", 4, {"size": [10.0, 10.0]}, "robot", 30),
    ("cluttered", 5, {"size": [12.0, 12.0], "n_obstacles": 30}, 0.4, 30),
    ("corridor", 6, {"shape": "zigzag"}, "robot", 25),
    ("door", 7, {"state": "open"}, "robot", 25),
    ("barn", 8, {}, "robot", 30),
    ("barn", 9, {}, 0.1, 30),
    ("minimal", 10, {}, "robot", 10),
]


def space(generator: str, seed: int, params: dict, which) -> tuple[ConfigSpace, object]:
    """The configuration space (and the world) of one entry of :data:`WORLDS`."""
    world = worldgen.generate(generator, seed, **params)
    if which == "robot":
        obstacles = Obstacles2D.from_footprints(robot_footprints(world.scene, world.robot))
        return ConfigSpace.build(obstacles, world.robot.inflation + SAFETY, world.scene.bounds), world
    obstacles = Obstacles2D.from_footprints(people_footprints(world.scene, world.tasks, world.robot))
    return ConfigSpace.build(obstacles, float(which) + SLACK, world.scene.bounds), world


def queries(cs: ConfigSpace, world, seed: int, n: int) -> list[tuple[list[float], list[float]]]:
    """The world's own tasks (robot spaces) and ``n`` random pairs of free points."""
    rng = np.random.default_rng(1000 + seed)
    (x0, y0, x1, y1) = cs.box
    pts = np.column_stack([rng.uniform(x0, x1, 8 * n), rng.uniform(y0, y1, 8 * n)])
    pts = pts[cs.points_clearance(pts) > 0][: 2 * n]
    out = [(a.tolist(), b.tolist()) for a, b in zip(pts[::2], pts[1::2])]
    for task in world.tasks:
        s, g = np.array([task.spawn.x, task.spawn.y]), np.array([task.goal.x, task.goal.y])
        if (cs.points_clearance(np.array([s, g])) > 0).all():
            out.append((s.tolist(), g.tolist()))
    return out


def _write() -> None:
    from worldgen.feasibility.planner import Planner

    worlds, rows = [], []
    for w, (generator, seed, params, which, n) in enumerate(WORLDS):
        cs, world = space(generator, seed, params, which)
        planner = Planner(cs)
        worlds.append(json.dumps([generator, seed, params, which]))
        for start, goal in queries(cs, world, seed, n):
            route = planner.shortest(np.array(start), np.array(goal))
            rows.append(json.dumps([w, start, goal, None if route is None else route.length,
                                    None if route is None else len(route.contacts)]))
    # One world or query a line: [world, start, goal, length (None: no path), contacts].
    DATA.write_text('{"worlds": [\n' + ",\n".join(worlds) + '\n],\n"queries": [\n' + ",\n".join(rows) + "\n]}\n")
    print(f"{len(rows)} queries, {sum(1 for r in rows if json.loads(r)[4])} with contacts", file=sys.stderr)

if __name__ == "__main__":
    _write()
