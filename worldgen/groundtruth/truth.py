"""The ground truth of one World, as world.json and the files beside it want it.

The one place that reads a World's parameters for lidar, map and metrics, so
that world.json and the written map files always agree. A world's occupancy map
and difficulty figures are made once and remembered (worlds are written after their metadata is built,
and a world asked for at a level is scored before it).
"""

from __future__ import annotations

import weakref

from worldgen.errors import InfeasibleError, ParameterError
from worldgen.files import MAP_IMAGE_NAME, MAP_YAML_NAME
from worldgen.groundtruth import barn as barn_grid
from worldgen.groundtruth import lidar, metrics, occupancy
from worldgen.groundtruth.terrain import with_undrivable
from worldgen.params import COMMON_PARAMS
from worldgen.scene import Pose
from worldgen.scene.doors import open_scene

__all__ = ["lidar_spec", "sensors", "planning_scene", "occupancy_map", "start_occupancy_map", "doors_start_shut",
           "occupancy_block", "map_files", "difficulty", "barn", "barn_inputs", "MAP_KEYS"]

#: world.json ``files`` keys of the map's two files.
MAP_KEYS = ("map_pgm", "map_yaml")

_DEFAULTS = {p.name: p.default for p in COMMON_PARAMS}
_MAPS: "weakref.WeakKeyDictionary" = weakref.WeakKeyDictionary()
#: The difficulty figures of each world, computed once: a world asked for at a level was scored with them
#: (worldgen.leveling) before its world.json is built.
_DIFFICULTY: "weakref.WeakKeyDictionary" = weakref.WeakKeyDictionary()


def _param(world, name: str):
    return world.params.get(name, _DEFAULTS[name])


def lidar_spec(world) -> lidar.LidarSpec:
    """The world's lidar: at its first task's spawn, ``lidar_height`` up (a world without
    tasks, made by hand, gets it at the centre of its bounds, facing +x)."""
    params = {name: _param(world, name) for name in
              ("lidar_height", "lidar_fov", "lidar_angle_min", "lidar_samples", "lidar_range_min", "lidar_range_max")}
    if world.tasks:
        at = world.tasks[0].spawn
    else:
        (x0, y0), (x1, y1) = world.scene.bounds
        at = Pose((x0 + x1) / 2, (y0 + y1) / 2)
    return lidar.spec_from_params(params, at)


def sensors(world) -> dict:
    """world.json's ``sensors`` block."""
    return {"lidar": lidar.describe(world.scene, lidar_spec(world))}


def planning_scene(world):
    """The scene the reference paths were planned in: every door leaf at its open limit.

    The map and the difficulty metrics describe this scene, so that BARN's
    grid metrics computed on map.pgm along the path agree with world.json's;
    the lidar describes the scene as it starts (what the sensor sees at the spawn).
    """
    return open_scene(world.scene)


def occupancy_map(world) -> occupancy.OccupancyMap:
    if world not in _MAPS:
        grid = occupancy.build(planning_scene(world), float(_param(world, "map_height")),
                               float(_param(world, "map_resolution")))
        _MAPS[world] = with_undrivable(grid, world.scene, world.robot)  # on terrain: ground it cannot drive
    return _MAPS[world]


def doors_start_shut(world) -> bool:
    """Whether a door leaf starts anywhere but at its open limit (closed or ajar): then the scene as it
    starts differs from :func:`planning_scene`, and so does its map."""
    from worldgen.scene.doors import door_joints, state_of

    return any(state_of(joint) != "open" for joint in door_joints(world.scene))


def start_occupancy_map(world) -> occupancy.OccupancyMap:
    """The occupancy map of the scene as it starts (every door leaf where it starts), with map.pgm's
    height, resolution and extent: what a localiser meets at the spawn. world.json's map stays
    :func:`occupancy_map` (the planning scene); the ROS 2 bundle gives nav2 this one."""
    grid = occupancy.build(world.scene, float(_param(world, "map_height")), float(_param(world, "map_resolution")))
    return with_undrivable(grid, world.scene, world.robot)


def occupancy_block(world) -> dict:
    """world.json's ``occupancy`` block."""
    return occupancy_map(world).describe(MAP_IMAGE_NAME, MAP_YAML_NAME)


def map_files(world) -> dict[str, tuple[str, bytes]]:
    """``{key: (relative path, bytes)}`` of the map's PGM and YAML files."""
    grid = occupancy_map(world)
    return {"map_pgm": (MAP_IMAGE_NAME, grid.pgm()),
            "map_yaml": (MAP_YAML_NAME, grid.yaml(MAP_IMAGE_NAME))}


def difficulty(world) -> dict:
    """worldgen's five exact figures of world.json's ``metrics`` (after BARN's; not BARN's numbers)."""
    if world not in _DIFFICULTY:
        _DIFFICULTY[world] = metrics.difficulty(planning_scene(world), world.robot, world.tasks,
                                                world.feasibility.paths)
    return dict(_DIFFICULTY[world])


def barn(world) -> dict:
    """world.json's ``metrics.barn``: BARN's own five metrics (its code's definitions, in cells)
    on BARN's inputs made from this world's map and reference paths (docs/metrics.md)."""
    grid = occupancy_map(world)
    paths = [None if p is None else p.waypoints for p in world.feasibility.paths]
    return barn_grid.world_metrics(grid.occupied, grid.origin, grid.resolution, world.robot.radius, paths)


def barn_inputs(world, task: int = 0, kernel=None):
    """(grid, path cells): BARN's inputs for one task's reference path, as ``metrics.barn`` uses
    them (``kernel=1``: the uninflated map and the chain in map cells), for
    :func:`worldgen.groundtruth.barn_metrics` with another radius or BARN's other tools."""
    paths = list(world.feasibility.paths)
    if not 0 <= task < len(world.tasks):
        raise ParameterError(f"task must be in [0, {len(world.tasks) - 1}] for this world, got {task!r}")
    path = paths[task] if task < len(paths) else None
    if path is None:
        raise InfeasibleError(f"task {task} of this world has no reference path, so it has no BARN inputs")
    grid = occupancy_map(world)
    return barn_grid.world_inputs(grid.occupied, grid.origin, grid.resolution, world.robot.radius, path.waypoints,
                                  kernel=kernel)
