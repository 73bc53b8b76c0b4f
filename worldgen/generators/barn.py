"""``barn``: a field of obstacles grown by a cellular automaton, crossed from a start strip to a goal strip.

After BARN (Perille, Truong, Xiao and Stone, "Benchmarking Metric Ground Navigation", 2020), whose
300 worlds are 30 x 30 grids of 0.15 m cells (a 4.5 m square field) grown from a random fill of 15 to
30 % of the cells and 2 to 4 smoothing passes (a cell with more than 4 filled neighbours fills, one
with fewer than 2 empties, any other stays as it was), with the robot starting below the field and
its goal above it. Here:

- the field is ``grid_cols`` x ``grid_rows`` cells of ``cell_size``, centred on the origin, grown
  by :mod:`worldgen.generators.cellular` (``fill_fraction``, ``smoothing_passes``, ``birth_limit``,
  ``death_limit``);
- a free strip ``end_depth`` deep lies below it (the start end, -y) and above it (the goal end, +y);
  the room is the field plus both strips, walled when ``walls``;
- each task's spawn lies on the start strip's centre line facing +y and its goal on the goal strip's,
  at x drawn across the width, so every task crosses the field;
- the filled cells become few static boxes (:func:`~worldgen.generators.cellular.merge_boxes`);
- a grid no disc of the robot's footprint can cross is rejected before the exact check (a cheap
  necessary condition, :func:`~worldgen.generators.cellular.crossing_blocked`); the pipeline then
  draws again, as with every draw the exact check refuses.

The grid and the tasks draw from separate streams, so asking for more tasks moves no obstacle.
"""

from __future__ import annotations

import math
from typing import Any, Mapping

import numpy as np

from worldgen.errors import ParameterError
from worldgen.floats import round_float
from worldgen.generators.base import Draft, GeneratorSpec, robot_from_params
from worldgen.generators.cellular import automaton, crossing_blocked, merge_boxes
from worldgen.generators.knob import Knob
from worldgen.generators.room import floor_node, wall_nodes
from worldgen.params import Param
from worldgen.scene import Box, Material, Node, Physics, Pose, Scene, Task

__all__ = ["SPEC", "build", "check", "field_grid", "field_scene", "layout"]

#: Density of the obstacles (kg/m^3) for their nominal mass: static, but inertia must be valid.
OBSTACLE_DENSITY = 300.0
#: Spawns and goals keep this much more than the footprint from the walls and the field.
SLACK = 1e-3
#: Facing across the field (+y), as written.
HEADING = round_float(math.pi / 2)

OBSTACLE_RGBA = (0.45, 0.36, 0.28, 1.0)

PARAMS = (
    # Most draws of a dense field are refused by the quick screen in about a millisecond: a budget of
    # 400 finds a world where 1 draw in 40 can be crossed (5 of 200 at fill 0.3, 2 passes, the default
    # robot) all but 4 times in 100,000 (0.975 ** 400).
    Param("max_attempts", "int", 400, "draws tried (each with a derived seed) before giving up", 1, 10000),
    Param("grid_cols", "int", 30, "cells across the field (x)", 2, 200),
    Param("grid_rows", "int", 30, "cells along the field, from the start end to the goal end (y)", 2, 200),
    Param("cell_size", "float", 0.15, "edge of one cell (BARN: 0.15)", 0.02, 2.5, unit="m"),
    Param("fill_fraction", "float", 0.2, "chance that a cell starts filled (BARN: 0.15 to 0.30)", 0.0, 0.9),
    Param("smoothing_passes", "int", 4, "cellular automaton passes after the random fill (BARN: 2 to 4)", 0, 50),
    Param("birth_limit", "int", 5, "a cell with at least this many of its 8 neighbours filled becomes filled "
          "(BARN: 5)", 1, 9),
    Param("death_limit", "int", 2, "a cell with fewer than this many of its 8 neighbours filled becomes empty "
          "(BARN: 2)", 0, 8),
    Param("end_depth", "float", 1.0, "depth of the free strips below (spawns) and above (goals) the field",
          0.02, 50.0, unit="m"),
    Param("obstacle_height", "float", 1.0, "height of the obstacles", 0.01, 50.0, unit="m"),
    Param("walls", "bool", True, "surround the field and both strips with walls"),
    Param("wall_height", "float", 1.0, "height of the walls", 0.05, 50.0, unit="m"),
    Param("wall_thickness", "float", 0.1, "thickness of the walls", 0.01, 10.0, unit="m"),
)


def layout(params: Mapping[str, Any]) -> tuple[float, float, float]:
    """(field width, field length, strip depth) in metres."""
    cell = params["cell_size"]
    return params["grid_cols"] * cell, params["grid_rows"] * cell, params["end_depth"]


def check(params: Mapping[str, Any]) -> None:
    """Reject sizes in which no spawn or goal could stand, naming the parameter and the bound."""
    if params["birth_limit"] < params["death_limit"]:
        raise ParameterError(f"parameter 'birth_limit' must be at least death_limit = {params['death_limit']}, "
                             f"got {params['birth_limit']!r}")
    width, _, depth = layout(params)
    keep = params["robot_radius"] + params["clearance"] + SLACK
    if depth < 2 * keep:
        raise ParameterError(f"parameter 'end_depth' must be at least 2 x (robot_radius + clearance + 1 mm) = "
                             f"{2 * keep:.4g} m, so the robot fits in the strips, got {params['end_depth']!r}")
    need = 2 * keep + (params["n_tasks"] - 1) * 2 * (keep - SLACK)
    if width < need:
        raise ParameterError(
            f"parameter 'grid_cols' x cell_size (the field's width, {width:.4g} m) must be at least {need:.4g} m "
            f"to hold {_robots(params['n_tasks'])} side by side in a strip, got grid_cols={params['grid_cols']!r}")


def _robots(n: int) -> str:
    return "the robot" if n == 1 else f"{n} robots"


def field_grid(params: Mapping[str, Any], rng: np.random.Generator) -> np.ndarray:
    """The grown field: (grid_rows, grid_cols) booleans, True = filled."""
    return automaton(rng, params["grid_rows"], params["grid_cols"], params["fill_fraction"],
                     params["smoothing_passes"], params["birth_limit"], params["death_limit"])


def build(params: Mapping[str, Any], rng: np.random.Generator) -> Draft:
    grid_rng, task_rng = rng.spawn(2)
    grid = field_grid(params, grid_rng)
    tasks = _tasks(params, task_rng, *layout(params))
    inflation = robot_from_params(params).inflation
    # Screened before the scene is built: most refused draws of a dense field stop here, in about a
    # millisecond, instead of in the exact check (tens of milliseconds).
    if crossing_blocked(grid, params["cell_size"], inflation):
        return Draft(None, tasks, rejected="field_blocked",
                     detail=f"no gap of {2 * inflation:g} m crosses the grown field")
    return Draft(field_scene(params, grid), tasks)


def field_scene(params: Mapping[str, Any], grid: np.ndarray) -> Scene:
    """The room around a grown field: floor, walls when asked for, one box per merged rectangle of cells."""
    width, length, depth = layout(params)
    friction = params["friction"]
    size = (width, length + 2 * depth)
    bounds = ((round_float(-width / 2), round_float(-size[1] / 2)), (round_float(width / 2), round_float(size[1] / 2)))
    nodes = [floor_node(size, params["wall_thickness"] if params["walls"] else 0.5, friction)]
    if params["walls"]:
        nodes += wall_nodes(size, params["wall_height"], params["wall_thickness"], friction)
    nodes += _obstacles(grid, params)
    return Scene(tuple(nodes), (), bounds, Physics(params["step_size"], params["real_time_factor"]))


def _obstacles(grid: np.ndarray, params: Mapping[str, Any]) -> list[Node]:
    """One static box per merged rectangle of filled cells."""
    cell, height = params["cell_size"], params["obstacle_height"]
    rows, cols = grid.shape
    x0, y0 = -cols * cell / 2, -rows * cell / 2
    boxes = merge_boxes(grid)
    digits = len(str(max(len(boxes) - 1, 0)))
    mat = Material("obstacle_box", OBSTACLE_RGBA, params["friction"])
    nodes = []
    for i, (r, c, h, w) in enumerate(boxes):
        shape = Box((round_float(w * cell), round_float(h * cell), height))
        pose = Pose(round_float(x0 + (c + w / 2) * cell), round_float(y0 + (r + h / 2) * cell), height / 2)
        nodes.append(Node(f"obstacle_{i:0{digits}d}", "obstacle", shape, pose,
                          mass=round_float(max(shape.volume() * OBSTACLE_DENSITY, 1e-3)), material=mat))
    return nodes


def _tasks(params: Mapping[str, Any], rng: np.random.Generator, width: float, length: float,
           depth: float) -> tuple[Task, ...]:
    """``n_tasks`` spawns on the start strip's centre line and goals on the goal strip's, each set of x
    uniform over the placements that keep neighbours two footprints apart; goal j pairs with a drawn spawn."""
    n = params["n_tasks"]
    keep = params["robot_radius"] + params["clearance"] + SLACK
    gap = 2 * (keep - SLACK)
    spawn_x, goal_x = (_spread(rng, n, width - 2 * keep, gap) - width / 2 + keep for _ in range(2))
    order = rng.permutation(n)
    y = length / 2 + depth / 2
    return tuple(
        Task(f"task_{i}", Pose(round_float(spawn_x[order[i]]), round_float(-y), 0.0, 0.0, 0.0, HEADING),
             Pose(round_float(goal_x[i]), round_float(y), 0.0, 0.0, 0.0, HEADING), params["goal_tolerance"])
        for i in range(n))


def _spread(rng: np.random.Generator, n: int, span: float, gap: float) -> np.ndarray:
    """``n`` sorted points in [0, span], neighbours at least ``gap`` apart (``check`` keeps room for them)."""
    slack = max(span - (n - 1) * gap, 0.0)
    return np.sort(rng.uniform(0.0, slack, n)) + gap * np.arange(n)


SPEC = GeneratorSpec(
    name="barn",
    summary="a BARN-style field grown by a cellular automaton, crossed from a start strip to a goal strip",
    params=PARAMS,
    build=build,
    check=check,
    examples=(
        "worldgen generate barn --seed 0 --out worlds",
        "worldgen generate barn --set fill_fraction=0.3 --set smoothing_passes=2 --count 10 --out worlds",
    ),
    # Levels: fuller and fuller fields (not scaled by the request's size: a fill fraction is already per
    # cell). Medians of seeds 0-19: level 1 at 0.1, 5 at 0.2, 8 at 0.3. No higher than 0.325: at 0.35 most
    # fields cannot be crossed, and a draw refused 400 times costs 0.6 s (six level-10 requests: 38 s with
    # 0.35 as the top, 21 s with 0.325).
    knob=Knob("fill_fraction", (0.1, 0.15, 0.175, 0.19, 0.2, 0.225, 0.275, 0.3, 0.325, 0.325), step=0.025,
              high=0.325, integer=False),
)
