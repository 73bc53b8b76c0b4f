"""``terrain``: a walled room of ramps, kerbs, potholes and rough patches, with obstacles among them.

The room and its obstacles are ``cluttered``'s (the same parameters), drawn first; then the terrain
elements (worldgen.scene.terrain) on their own stream, each a rectangle kept ``terrain_gap`` from the walls,
the obstacles and each other; then the tasks, off every element (a spawn and a goal stand on the flat
floor, z = 0). Whether the robot can drive what was made is proven afterwards, for its climbing limits
(``robot_max_incline``, ...; worldgen.scene.drivable): the feasibility planner treats ground it cannot
drive as an obstacle. docs/terrain.md.
"""

from __future__ import annotations

from typing import Any, Mapping

import numpy as np

import worldgen.generators.cluttered as cluttered
from worldgen.generators.base import Draft, GeneratorSpec, robot_from_params
from worldgen.generators.knob import Knob
from worldgen.generators.room import floor_node, room_bounds, wall_nodes
from worldgen.generators.tasks import sample_tasks
from worldgen.generators.terrain_layout import TERRAIN_PARAMS, check_terrain, with_terrain
from worldgen.params import CLIMB_PARAMS, Param
from worldgen.scene import Physics, Scene
from worldgen.scene.footprint import FootprintIndex, robot_footprints

__all__ = ["SPEC", "KNOB", "build"]

PARAMS = tuple(p if p.name != "n_obstacles" else Param("n_obstacles", "int", 8, p.doc, 0, cluttered.MAX_OBSTACLES)
               for p in cluttered.BASE_PARAMS) + TERRAIN_PARAMS + CLIMB_PARAMS


def check(params: Mapping[str, Any]) -> None:
    cluttered.check(params)
    check_terrain(params)


def build(params: Mapping[str, Any], rng: np.random.Generator) -> Draft:
    obstacle_rng, task_rng, terrain_rng = rng.spawn(3)
    size = params["size"]
    bounds = room_bounds(size)
    nodes = [floor_node(size, params["wall_thickness"] if params["walls"] else 0.5, params["friction"])]
    if params["walls"]:
        nodes += wall_nodes(size, params["wall_height"], params["wall_thickness"], params["friction"])
    count = cluttered.obstacle_count(params)
    obstacles = cluttered.place_obstacles(params, obstacle_rng, bounds, count)
    if obstacles is None:
        return Draft(None, rejected="obstacle_placement",
                     detail=f"could not place {count} obstacles with min_gap {params['min_gap']:g} m")
    nodes += obstacles
    robot = robot_from_params(params)
    flat = Scene(tuple(nodes), (), bounds, Physics(params["step_size"], params["real_time_factor"]))
    made = with_terrain(flat, params, terrain_rng, robot)
    if isinstance(made, str):
        return Draft(None, rejected="terrain_placement", detail=made)
    scene, off_terrain = made
    # Spawns and goals stand on the flat floor: every element is kept out of their draw.
    index = FootprintIndex(robot_footprints(scene, robot) + off_terrain)
    tasks, reason = sample_tasks(task_rng, index, bounds, robot, params["n_tasks"], params["min_spawn_goal_distance"],
                                 params["goal_tolerance"], params["spawn"], params["goal"], params["task_region"])
    if reason:
        return Draft(scene, rejected="task_placement", detail=reason)
    return Draft(scene, tuple(tasks))


#: A level request turns the obstacle count as cluttered's knob does, from cluttered's calibration; the
#: score it aims at reads the terrain too (worldgen.groundtruth.difficulty's terrain terms, docs/metrics.md).
KNOB = Knob("n_obstacles", cluttered.KNOB.start, step=cluttered.KNOB.step, high=cluttered.KNOB.high,
            per_area=True, excludes=("density",))

SPEC = GeneratorSpec(
    name="terrain",
    summary="a walled room with ramps, kerbs, potholes and rough patches among obstacles, proven drivable "
            "for the robot's climbing limits",
    params=PARAMS,
    build=build,
    check=check,
    examples=(
        "worldgen generate terrain --seed 3 --set size=20,20 --out worlds",
        "worldgen generate terrain --set n_ramps=3 --set ramp_incline=8,12 --set robot_max_incline=12 --out worlds",
    ),
    knob=KNOB,
)
