"""``minimal``: a floor, optionally walls, and one target at an exact distance and bearing.

The world of a sensor unit test ("a wall 2.0 m in front of the robot"): nothing
but the one thing the test looks at, placed so that the answer is known exactly.
No random draws: the seed only names the world.

What ``target_distance`` D means, measured in the floor plane from the spawn
point along the ray at ``spawn_yaw + target_bearing`` (counter-clockwise from +x):

- ``wall`` and ``box``: the distance to the target's near face. That face is
  perpendicular to the ray and centred on it, so a ray cast from the spawn along
  the bearing (at any height below ``target_height``) hits at exactly D.
- ``cylinder``: the distance to the cylinder's surface on that ray; its axis
  stands at D + ``target_radius``.

The goal is ``goal`` when given; otherwise it stands beside the target, on the
target's left of the ray (or its right when the left leaves the floor), level
with the near face (a cylinder's axis) and clear of the target's side by the
footprint (robot_radius + clearance) plus :func:`margin` plus 0.05 m.

The spawn, a given goal and the target keep :func:`margin` (1 mm) more than
the footprint from the target and the floor's edge: room for the feasibility
checker's 0.1 mm safety margin and the 6-decimal rounding of what is written.
Closer requests are refused with the numbers instead of failing every attempt.
"""

from __future__ import annotations

import math
from typing import Any, Mapping

import numpy as np

from worldgen.errors import ParameterError
from worldgen.floats import round_float
from worldgen.generators.base import Draft, GeneratorSpec
from worldgen.generators.room import floor_node, room_bounds, wall_nodes
from worldgen.params import Param
from worldgen.scene import Box, Cylinder, Material, Node, Physics, Pose, Scene, Shape, Task

__all__ = ["SPEC", "build", "check", "margin", "TARGET_DEFAULTS", "target_layout"]

#: Sizes used where a target size parameter is left unset, per target kind (m).
TARGET_DEFAULTS = {
    "wall": {"target_width": 4.0, "target_depth": 0.1},
    "box": {"target_width": 0.5, "target_depth": 0.5},
    "cylinder": {"target_radius": 0.25},
}
#: Extra room (m) between the default goal's footprint plus margin and the target's side.
GOAL_GAP = 0.05
#: Angles are accepted up to pi written with 4 decimals: world.json rounds pi to 3.141593,
#: and the params it records must generate the same world again.
ANGLE_LIMIT = 3.1416
#: Room (m) beyond the footprint that spawn, goal and target keep (see the module docs).
MARGIN = 1e-3
#: Density (kg/m^3) for the target's nominal mass: static, but inertia must be valid.
TARGET_DENSITY = 300.0
TARGET_RGBA = (0.85, 0.30, 0.25, 1.0)

PARAMS = (
    # One task: the robot at its spawn facing the target; a request for more is refused, not dropped.
    Param("n_tasks", "int", 1, "spawn/goal pairs per world: one here, the spawn facing the target", 1, 1),
    Param("size", "pair", [10.0, 10.0], "extents (x, y) of the floor, centred on the origin", 1.0, 500.0, unit="m"),
    Param("walls", "bool", False, "surround the floor with walls (they are seen by sensors too)"),
    Param("wall_height", "float", 1.0, "height of the surrounding walls", 0.05, 50.0, unit="m"),
    Param("wall_thickness", "float", 0.1, "thickness of the surrounding walls", 0.01, 10.0, unit="m"),
    Param("target", "choice", "wall", "the one object under test", choices=("wall", "box", "cylinder")),
    Param("target_distance", "float", 2.0,
          "from the spawn along the bearing to the target's near face (wall, box) or surface (cylinder)",
          0.01, 250.0, unit="m"),
    Param("target_bearing", "float", 0.0, "direction of the target, counter-clockwise from the robot's heading",
          -ANGLE_LIMIT, ANGLE_LIMIT, unit="rad"),
    Param("target_width", "float", None, "extent across the line of sight (wall, box); unset: 4.0 wall, 0.5 box",
          0.01, 500.0, optional=True, unit="m"),
    Param("target_depth", "float", None, "extent along the line of sight (wall, box); unset: 0.1 wall, 0.5 box",
          0.01, 100.0, optional=True, unit="m"),
    Param("target_radius", "float", None, "radius of a cylinder target; unset: 0.25", 0.01, 100.0,
          optional=True, unit="m"),
    Param("target_height", "float", 1.0, "height of the target", 0.01, 50.0, unit="m"),
    Param("spawn_yaw", "float", 0.0, "the robot's heading at the spawn (counter-clockwise from +x)",
          -ANGLE_LIMIT, ANGLE_LIMIT, unit="rad"),
    Param("spawn", "triple", None, "spawn pose [x, y, yaw] (default: the origin, heading spawn_yaw); "
          "its yaw replaces spawn_yaw", -10000.0, 10000.0, optional=True, unit="m, m, rad"),
    Param("goal", "pair", None, "goal [x, y] (default: beside the target, see the module docs)",
          -10000.0, 10000.0, optional=True, unit="m"),
)


def margin(params: Mapping[str, Any]) -> float:
    """Room (m) beyond robot_radius + clearance that spawn and goal keep from the target and floor edge."""
    return MARGIN


def _size(params: Mapping[str, Any], name: str) -> float:
    value = params[name]
    return TARGET_DEFAULTS[params["target"]][name] if value is None else value


def target_layout(params: Mapping[str, Any]):
    """((x, y, yaw) of the spawn, direction of the target ray (rad), its unit vector (2,)).

    Unrounded geometry; :func:`build` rounds what it writes.
    """
    if params["spawn"] is not None:
        sx, sy, yaw = params["spawn"]
    else:
        sx, sy, yaw = 0.0, 0.0, params["spawn_yaw"]
    direction = yaw + params["target_bearing"]
    u = np.array([math.cos(direction), math.sin(direction)])
    return (sx, sy, yaw), direction, u


def _target_node(params, spawn_xy, direction, u, friction) -> Node:
    d, h = params["target_distance"], params["target_height"]
    kind = params["target"]
    mat = Material("target", TARGET_RGBA, friction)
    if kind == "cylinder":
        r = _size(params, "target_radius")
        centre = spawn_xy + (d + r) * u
        shape: Shape = Cylinder(r, h)
        yaw = 0.0
    else:
        depth, width = _size(params, "target_depth"), _size(params, "target_width")
        centre = spawn_xy + (d + depth / 2) * u
        shape, yaw = Box((depth, width, h)), round_float(_wrap(direction))
    role = "wall" if kind == "wall" else "obstacle"
    mass = round_float(max(shape.volume() * TARGET_DENSITY, 1e-3))
    return Node("target", role, shape, Pose(round_float(centre[0]), round_float(centre[1]), h / 2, 0.0, 0.0, yaw),
                mass=mass, material=mat)


def _wrap(angle: float) -> float:
    return math.atan2(math.sin(angle), math.cos(angle))


def _target_half_width(params) -> float:
    return _size(params, "target_radius") if params["target"] == "cylinder" else _size(params, "target_width") / 2


def _target_reach(params) -> float:
    """How far past the near face/surface the target extends along the ray."""
    if params["target"] == "cylinder":
        return 2 * _size(params, "target_radius")
    return _size(params, "target_depth")


def _default_goal(params, spawn_xy, u):
    """Beside the target, level with its near face; None when neither side fits on the floor."""
    keep = params["robot_radius"] + params["clearance"] + margin(params)
    (x0, y0), (x1, y1) = room_bounds(params["size"])
    left = np.array([-u[1], u[0]])
    near = spawn_xy + params["target_distance"] * u
    offset = _target_half_width(params) + keep + GOAL_GAP
    if params["target"] == "cylinder":  # level with the axis, where the cylinder is widest
        near = near + _size(params, "target_radius") * u
    for side in (1.0, -1.0):
        g = near + side * offset * left
        g = np.array([round_float(g[0]), round_float(g[1])])
        if x0 + keep <= g[0] <= x1 - keep and y0 + keep <= g[1] <= y1 - keep:
            return g
    return None


def check(params: Mapping[str, Any]) -> None:
    """Reject layouts that cannot be driven or do not fit on the floor, naming the parameter."""
    inflation = params["robot_radius"] + params["clearance"]
    keep = inflation + margin(params)
    if params["spawn"] is not None and params["spawn_yaw"] != 0.0:
        raise ParameterError("parameters 'spawn' and 'spawn_yaw' both set the heading; give the yaw as spawn's "
                             f"third value only, got spawn={params['spawn']!r}, spawn_yaw={params['spawn_yaw']!r}")
    if params["spawn"] is not None and not -ANGLE_LIMIT <= params["spawn"][2] <= ANGLE_LIMIT:
        raise ParameterError(f"parameter 'spawn' yaw (third value) must be in [-{ANGLE_LIMIT}, {ANGLE_LIMIT}] rad, "
                             f"got {params['spawn']!r}")
    for name in ("target_width", "target_depth", "target_radius"):
        if params[name] is not None and name not in TARGET_DEFAULTS[params["target"]]:
            raise ParameterError(f"parameter '{name}' does not apply to a {params['target']} target; leave it unset "
                                 f"(applies: {', '.join(TARGET_DEFAULTS[params['target']])}), got {params[name]!r}")
    # The robot at the spawn keeps its clearance from the target, with the checker's margin.
    if params["target_distance"] < keep:
        raise ParameterError(
            f"parameter 'target_distance' must be at least robot_radius + clearance + 1 mm "
            f"= {keep:.3f} m, got {params['target_distance']!r}")
    (sx, sy, _), _, u = target_layout(params)
    spawn_xy = np.array([sx, sy])
    (x0, y0), (x1, y1) = room_bounds(params["size"])
    floor = f"[{x0:g}, {x1:g}] x [{y0:g}, {y1:g}]"
    if not (x0 + keep <= sx <= x1 - keep and y0 + keep <= sy <= y1 - keep):
        raise ParameterError(f"parameter 'spawn' must keep the robot's {inflation:g} m disc and 1 mm "
                             f"({keep:.3f} m) inside the floor {floor}, got {params['spawn']!r}")
    left = np.array([-u[1], u[0]])
    half = _target_half_width(params)
    far = params["target_distance"] + _target_reach(params)
    corners = [spawn_xy + a * u + b * left for a in (params["target_distance"], far) for b in (-half, half)]
    if not all(x0 <= c[0] <= x1 and y0 <= c[1] <= y1 for c in corners):
        raise ParameterError(
            f"parameter 'target_distance' puts the {params['target']} (reaching {far:g} m out, {2 * half:g} m wide) "
            f"off the floor {floor}; enlarge 'size' or move the target, got {params['target_distance']!r}")
    goal = params["goal"]
    if goal is not None and not (x0 + keep <= goal[0] <= x1 - keep and y0 + keep <= goal[1] <= y1 - keep):
        raise ParameterError(f"parameter 'goal' must keep the robot's {inflation:g} m disc and 1 mm "
                             f"({keep:.3f} m) inside the floor {floor}, got {goal!r}")
    if goal is None and _default_goal(params, spawn_xy, u) is None:
        raise ParameterError(f"parameter 'goal' must be given: neither side of the target leaves room for the "
                             f"default goal on the floor {floor}")


def build(params: Mapping[str, Any], rng: np.random.Generator) -> Draft:
    """The world; ``rng`` is not used (the layout is exact by design)."""
    del rng
    size, friction = params["size"], params["friction"]
    (sx, sy, yaw), direction, u = target_layout(params)
    spawn_xy = np.array([sx, sy])
    # The floor is `size` (the bounds) and, with walls, reaches under them: the bounds, the floor
    # and the map then end together, so rays and distances stop where the floor does.
    nodes = [floor_node(size, params["wall_thickness"] if params["walls"] else 0.0, friction)]
    if params["walls"]:
        nodes += wall_nodes(size, params["wall_height"], params["wall_thickness"], friction)
    nodes.append(_target_node(params, spawn_xy, direction, u, friction))
    goal = np.asarray(params["goal"]) if params["goal"] is not None else _default_goal(params, spawn_xy, u)
    scene = Scene(tuple(nodes), (), room_bounds(size), Physics(params["step_size"], params["real_time_factor"]))
    task = Task("task_0", Pose(round_float(sx), round_float(sy), 0.0, 0.0, 0.0, round_float(yaw)),
                Pose(round_float(goal[0]), round_float(goal[1]), 0.0), params["goal_tolerance"])
    return Draft(scene, (task,))


SPEC = GeneratorSpec(
    name="minimal",
    summary="a floor and one target (wall, box or cylinder) at an exact distance and bearing from the spawn",
    params=PARAMS,
    build=build,
    check=check,
    examples=(
        "worldgen generate minimal --set target_distance=2.0 --out worlds",
        "worldgen generate minimal --set target=cylinder --set target_bearing=0.5 --set walls=true --out worlds",
    ),
    no_levels="it has no random draws: one target at an exact distance for a sensor test",
)
