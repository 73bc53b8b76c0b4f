"""``corridor``: a walled corridor, straight or with 90 degree turns, spawn at one end, goal at the other.

The centreline starts at the origin heading +x and runs through ``segments``
(lengths, m), turning 90 degrees ``left`` or ``right`` between them:
``straight`` is one segment, ``L`` two (one turn), ``U`` three (two turns the
same way), ``zigzag`` any number (turns as given, alternating by default).
Both ends are closed by a wall, so the robot cannot leave by the ends; side
openings (gaps in the side walls) lead to the floor around the corridor,
which lies inside the bounds where the corridor bends round it.

Obstacles are boxes standing against a side wall. Each leaves at least
``min_passage`` (unset: 2 x (robot_radius + clearance) + 0.2, and never less
than :func:`proven_width`) to the opposite wall, and obstacles on one leg are at least
``min_passage`` apart along it (and as far from the leg's corners, openings,
spawn and goal), so every gap on the way is at least ``min_passage`` wide.

Width: a corridor narrower than 2 x (robot_radius + clearance) cannot be driven,
and :func:`check` says so with the numbers (:class:`~worldgen.errors.InfeasibleError`).
The checker plans exactly in the continuous plane with a safety margin of
:data:`~worldgen.scene.footprint.SAFETY` (0.1 mm) on each side, so every
corridor from :func:`proven_width` = 2 x (robot_radius + clearance + SAFETY)
(plus the walls' rounding to 6 decimals) on is proven passable: 1 mm more than
the footprint needs is enough. ``generate(..., allow_infeasible=True)`` still
builds a narrower corridor, and its feasibility report then says which check failed.
"""

from __future__ import annotations

import math
from typing import Any, Mapping

import numpy as np

from worldgen.errors import InfeasibleError, ParameterError
from worldgen.floats import round_float
from worldgen.generators.base import Draft, GeneratorSpec, robot_from_params
from worldgen.generators.corridor_layout import Layout, layout
from worldgen.generators.corridor_terrain import OPTION_PARAMS, check_ramps, place_ramps
from worldgen.generators.knob import Knob
from worldgen.generators.room import FLOOR_RGBA, FLOOR_THICKNESS, WALL_RGBA
from worldgen.params import Param
from worldgen.scene import Box, Material, Node, Physics, Pose, Scene, Task
from worldgen.scene.footprint import SAFETY
from worldgen.scene.terrain import Terrain

__all__ = ["SPEC", "build", "check", "proven_width"]

#: Room (m) on top of the checker's margin for the walls' coordinates, rounded to 6 decimals.
WALL_ROUNDING = 1e-5
#: Tries to place one obstacle or opening before the draw counts as too crowded.
PLACEMENT_TRIES = 60
#: Density (kg/m^3) for the obstacles' nominal mass: static, but inertia must be valid.
OBSTACLE_DENSITY = 300.0
OBSTACLE_RGBA = (0.80, 0.52, 0.25, 1.0)
PARAMS = (
    # One task, from one end of the corridor to the other: a request for more is refused, not dropped.
    Param("n_tasks", "int", 1, "spawn/goal pairs per world: one here, from one end to the other", 1, 1),
    Param("shape", "choice", "straight", "layout of the centreline", choices=("straight", "L", "U", "zigzag")),
    Param("width", "float", 1.5, "free width between the side walls", 0.05, 50.0, unit="m"),
    Param("length", "float", 10.0, "centreline length of every segment (unless 'segments' is given)",
          0.5, 500.0, unit="m"),
    Param("segments", "list", None, "centreline length of each segment: straight 1, L 2, U 3, zigzag 2 or more",
          0.5, 500.0, optional=True, unit="m"),
    Param("turns", "words", None, "direction of each turn (L 1, U 2 alike, zigzag one fewer than segments); "
          "unset: left, left-left for U, alternating for zigzag", choices=("left", "right"), optional=True),
    Param("wall_height", "float", 1.0, "height of the walls", 0.05, 50.0, unit="m"),
    Param("wall_thickness", "float", 0.1, "thickness of the walls", 0.01, 10.0, unit="m"),
    Param("n_obstacles", "int", 0, "boxes standing against the side walls", 0, 500),
    Param("min_passage", "float", None, "smallest gap the obstacles leave; unset: 2 x (robot_radius + clearance) "
          "+ 0.2 (at least the proven width)", 0.01, 50.0, optional=True, unit="m"),
    Param("obstacle_length", "range", [0.2, 0.6], "range of each obstacle's extent along the corridor",
          0.01, 50.0, unit="m"),
    Param("obstacle_height", "range", [0.5, 1.0], "range of obstacle heights", 0.01, 50.0, unit="m"),
    Param("side_openings", "int", 0, "gaps in the side walls, on random sides and legs", 0, 100),
    Param("opening_width", "float", 1.0, "width of each side opening", 0.05, 50.0, unit="m"),
) + OPTION_PARAMS


def proven_width(params: Mapping[str, Any]) -> float:
    """The narrowest corridor (or gap) the feasibility checker proves passable for this robot."""
    return 2 * (robot_from_params(params).inflation + SAFETY) + WALL_ROUNDING


def _end_offset(params: Mapping[str, Any]) -> float:
    """Distance of spawn (goal) from the start (end) wall: half the width, at least the footprint + 0.05 m."""
    return max(params["width"] / 2, params["robot_radius"] + params["clearance"] + 0.05)


def _passage(params: Mapping[str, Any], proven: float) -> float:
    """The gap obstacles must leave: ``min_passage``, or 0.2 m more than the footprint needs (at least ``proven``)."""
    if params["min_passage"] is not None:
        return params["min_passage"]
    return max(proven, 2 * (params["robot_radius"] + params["clearance"]) + 0.2)


# long: one check per parameter combination, each a line or two, with its message
def check(params: Mapping[str, Any]) -> None:
    """Reject parameters no corridor can satisfy; a too-narrow width is an InfeasibleError."""
    lay = layout(params)
    w, t = params["width"], params["wall_thickness"]
    name = "segments" if params["segments"] is not None else "length"
    k = len(lay.lengths)
    e = _end_offset(params)
    for i, length in enumerate(lay.lengths):
        corners = (i > 0) + (i < k - 1)
        ends = 2 - corners
        need = corners * w / 2 + ends * e + (0.1 if k == 1 else 0.0)
        if length <= need:
            raise ParameterError(
                f"parameter '{name}' must make each leg longer than its corner squares and spawn/goal room "
                f"({need:g} m for leg {i} of this corridor), got {params[name]!r}")
    rects = lay.rects(extra=t)
    for i in range(k):
        for j in range(i + 2, k):
            a, b = rects[i], rects[j]
            if a[0] < b[2] - 1e-9 and b[0] < a[2] - 1e-9 and a[1] < b[3] - 1e-9 and b[1] < a[3] - 1e-9:
                raise ParameterError(
                    f"parameter 'turns' makes leg {j} run into leg {i} (walls included); lengthen 'segments' or "
                    f"change the turns, got turns={params['turns']!r}, segments={lay.lengths!r}")
    r, c = params["robot_radius"], params["clearance"]
    need = 2 * (r + c)
    proven = proven_width(params)
    g = _passage(params, proven)
    # Obstacles need room beside the passage whether or not the corridor itself is passable:
    # --allow-infeasible skips only the InfeasibleErrors below, never a world that cannot be built.
    if params["n_obstacles"]:
        if g < proven <= w:
            raise ParameterError(
                f"parameter 'min_passage' must be in [{proven:.5f}, {w:g}] (from the narrowest gap the checker "
                f"proves passable for this robot to the width), got {params['min_passage']!r}")
        if w - g < 0.05 and params["min_passage"] is not None:
            raise ParameterError(
                f"parameter 'min_passage' must be at most width - 0.05 = {w - 0.05:g} m so obstacles have depth, "
                f"got {g:g}")
        if w - g < 0.05:
            raise ParameterError(
                f"parameter 'n_obstacles' must be 0 in a corridor {w:g} m wide: obstacles need width >= passage + "
                f"0.05 = {g + 0.05:.3f} m (or set 'min_passage' as low as {proven:.5f}), got {params['n_obstacles']!r}")
    if params["side_openings"] and params["opening_width"] > max(b - a for a, b in
                                                                 (lay.straight_part(i) for i in range(k))):
        raise ParameterError(f"parameter 'opening_width' must fit in a leg's straight part, got {params['opening_width']!r}")
    if params.get("terrain"):
        check_ramps(params, max(hi - lo for lo, hi in _usable(lay, params)), g)
    # Last, so that allow_infeasible (which skips this error) still had every other check.
    if params["n_obstacles"]:
        shortest = params["obstacle_length"][0] + 2 * g
        longest = max(hi - lo for lo, hi in _usable(lay, params))
        if longest < shortest:
            raise InfeasibleError(
                f"no corridor of this shape holds {params['n_obstacles']} obstacle(s): one needs {shortest:.3g} m of a leg "
                f"({params['obstacle_length'][0]:g} m long and {g:g} m of passage on each side), and the longest leg "
                f"has {max(longest, 0.0):.3g} m left after the spawn's and goal's room; lengthen the corridor or set "
                f"n_obstacles=0")
    if w < need:
        raise InfeasibleError(
            f"corridor width {w:g} m cannot pass a {r:g} m radius robot with {c:g} m clearance (needs >= {_m(need)} m)")
    if w < proven:
        raise InfeasibleError(
            f"corridor width {w:g} m leaves less than the checker's {SAFETY * 1e3:g} mm safety margin on each side "
            f"of the {need:g} m a {r:g} m radius robot with {c:g} m clearance needs; the checker proves corridors "
            f"from {proven:.5f} m wide")


def _usable(lay, params: Mapping[str, Any]) -> list[tuple[float, float]]:
    """Per leg, the along-leg interval where openings and obstacles may go: the straight part, less the
    spawn's and the goal's room on the first and last legs."""
    e, inflation = _end_offset(params), params["robot_radius"] + params["clearance"]
    k = len(lay.lengths)
    usable = []
    for i in range(k):
        lo, hi = lay.straight_part(i)
        if i == 0:
            lo = e + inflation
        if i == k - 1:
            hi = lay.lengths[i] - e - inflation
        usable.append((lo, hi))
    return usable


def build(params: Mapping[str, Any], rng: np.random.Generator) -> Draft:
    opening_rng, obstacle_rng = rng.spawn(2)
    lay = layout(params)
    w, t, height = params["width"], params["wall_thickness"], params["wall_height"]
    friction = params["friction"]
    bounds = lay.bounds()
    k = len(lay.lengths)
    e = _end_offset(params)
    g = _passage(params, proven_width(params))
    usable = _usable(lay, params)
    taken: list[list[tuple[float, float]]] = [[] for _ in range(k)]

    openings: list[list[tuple[float, float]]] = [[] for _ in range(2 * k)]  # per (leg, side)
    ow = params["opening_width"]
    for _ in range(params["side_openings"]):
        spot = _place(opening_rng, usable, taken, lambda: ow, 0.2)
        if spot is None:
            n = params["side_openings"]
            return Draft(None, rejected="opening_placement",
                         detail=f"could not fit {n} side opening{'s' if n != 1 else ''} of {ow:g} m in the side walls")
        leg, a, b = spot
        side = int(opening_rng.integers(2))
        openings[2 * leg + side].append((a, b))

    nodes = [_floor(bounds, t, friction)]
    nodes += _walls(lay, t, height, friction, openings)
    lo_len, hi_len = params["obstacle_length"]
    width_of = len(str(max(params["n_obstacles"] - 1, 0)))
    mat = Material("obstacle_box", OBSTACLE_RGBA, friction)
    for j in range(params["n_obstacles"]):
        spot = _place(obstacle_rng, usable, taken, lambda: obstacle_rng.uniform(lo_len, hi_len), g)
        if spot is None:
            n = params["n_obstacles"]
            room = sum(max(hi - lo, 0.0) for lo, hi in usable)
            return Draft(None, rejected="obstacle_placement",
                         detail=f"placed {j} of {n} obstacle{'s' if n != 1 else ''} {lo_len:g}-{hi_len:g} m long, each "
                                f"{g:g} m from the others and from the corridor's ends, in {room:.3g} m of usable "
                                f"corridor (the rest is kept free at the spawn and goal)")
        leg, a, b = spot
        wall = 1.0 if obstacle_rng.random() < 0.5 else -1.0  # the side wall it stands against
        depth = round_float(obstacle_rng.uniform(min(0.1, w - g), w - g))
        h = round_float(obstacle_rng.uniform(*params["obstacle_height"]))
        along = round_float(b - a)
        centre = lay.points[leg] + (a + b) / 2 * lay.u(leg) + wall * (w / 2 - depth / 2) * lay.n(leg)
        nodes.append(Node(f"obstacle_{j:0{width_of}d}", "obstacle", Box((along, depth, h)),
                          _pose(centre, h / 2, lay.heads[leg]),
                          mass=round_float(max(along * depth * h * OBSTACLE_DENSITY, 1e-3)), material=mat))
    scene = Scene(tuple(nodes), (), bounds, Physics(params["step_size"], params["real_time_factor"]))
    if params.get("terrain") and params["n_ramps"]:  # a third stream, spawned only then: the rest keep theirs
        ramps = place_ramps(params, rng.spawn(1)[0], lay, w,
                            lambda r, length: _place(r, usable, taken, length, g), lambda leg: _yaw(lay.heads[leg]))
        if isinstance(ramps, str):
            return Draft(None, rejected="terrain_placement", detail=ramps)
        scene = scene.with_terrain(Terrain(tuple(ramps)))
    start = lay.points[0] + e * lay.u(0)
    end = lay.points[-1] - e * lay.u(k - 1)
    task = Task("task_0", Pose(round_float(start[0]), round_float(start[1]), 0.0, 0.0, 0.0, _yaw(lay.heads[0])),
                Pose(round_float(end[0]), round_float(end[1]), 0.0, 0.0, 0.0, _yaw(lay.heads[-1])),
                params["goal_tolerance"])
    return Draft(scene, (task,))


def _place(rng, usable, taken, draw_length, gap):
    """(leg, a, b): a free along-leg interval of a drawn length, ``gap`` from every taken one; None if none."""
    spans = np.array([max(hi - lo, 0.0) for lo, hi in usable])
    if spans.sum() <= 0:
        return None
    weights = spans / spans.sum()
    for _ in range(PLACEMENT_TRIES):
        length = float(draw_length())
        leg = int(rng.choice(len(usable), p=weights))
        lo, hi = usable[leg]
        lo, hi = lo + gap, hi - gap
        if hi - lo < length:
            continue
        a = round_float(rng.uniform(lo, hi - length))
        b = round_float(a + length)
        if all(b + gap <= c or a >= d + gap for c, d in taken[leg]):
            taken[leg].append((a, b))
            return leg, a, b
    return None


def _yaw(head: int) -> float:
    return round_float((0.0, math.pi / 2, math.pi, -math.pi / 2)[head])


def _pose(centre, z: float, head: int) -> Pose:
    """A box pose on a leg: boxes are symmetric, so -x/-y legs reuse the +x/+y yaw (exact)."""
    return Pose(round_float(centre[0]), round_float(centre[1]), z, 0.0, 0.0, 0.0 if head % 2 == 0 else _yaw(1))


def _floor(bounds, margin: float, friction: float) -> Node:
    (x0, y0), (x1, y1) = bounds
    return Node("floor", "floor", Box((x1 - x0 + 2 * margin, y1 - y0 + 2 * margin, FLOOR_THICKNESS)),
                Pose(round_float((x0 + x1) / 2), round_float((y0 + y1) / 2), -FLOOR_THICKNESS / 2),
                material=Material("floor", FLOOR_RGBA, friction))


def _walls(lay: Layout, t: float, height: float, friction: float, openings) -> list[Node]:
    """Side walls along both face lines (mitred at the corners) and a wall across each end.

    A side wall is extended by ``t`` past an outer corner so the two legs' walls
    overlap there and close the corner; at an inner corner they meet at the face.
    """
    mat = Material("wall", WALL_RGBA, friction)
    w, k = lay.width, len(lay.lengths)
    nodes = []
    for side, label in ((1, "left"), (-1, "right")):
        for i in range(k):
            a, b = lay.straight_part(i)
            # The face's corner: at an inner corner it is the straight part's end; at an outer one the
            # face runs on across the corner square (w) plus the wall thickness.
            if i > 0:
                a = a if lay.turns[i - 1] == side else a - w - t
            if i < k - 1:
                b = b if lay.turns[i] == side else b + w + t
            pieces = _cut(a, b, sorted(openings[2 * i + (0 if side == 1 else 1)]))
            for p, (pa, pb) in enumerate(pieces):
                centre = lay.points[i] + (pa + pb) / 2 * lay.u(i) + side * (w / 2 + t / 2) * lay.n(i)
                nodes.append(Node(f"wall_{label}_{i}_{p}", "wall", Box((round_float(pb - pa), t, height)),
                                  _pose(centre, height / 2, lay.heads[i]), material=mat))
    for name, point, u, head in (("wall_start", lay.points[0], -lay.u(0), lay.heads[0]),
                                 ("wall_end", lay.points[-1], lay.u(k - 1), lay.heads[-1])):
        centre = point + (t / 2) * u
        nodes.append(Node(name, "wall", Box((t, w + 2 * t, height)), _pose(centre, height / 2, head), material=mat))
    return nodes


def _cut(a: float, b: float, gaps) -> list[tuple[float, float]]:
    """[a, b] with the (sorted, disjoint) gaps removed."""
    out, cursor = [], a
    for ga, gb in gaps:
        if ga > cursor:
            out.append((cursor, ga))
        cursor = max(cursor, gb)
    if b > cursor:
        out.append((cursor, b))
    return out


SPEC = GeneratorSpec(
    name="corridor",
    summary="a walled corridor (straight, L, U or zigzag) with optional obstacles and side openings",
    params=PARAMS,
    build=build,
    check=check,
    examples=(
        "worldgen generate corridor --set width=0.8 --out worlds",
        "worldgen generate corridor --set terrain=true --set n_ramps=2 --set length=12 --out worlds",
        "worldgen generate corridor --set shape=zigzag --set segments=4,3,4 --set turns=left,right --out worlds",
        "worldgen generate corridor --set shape=L --set n_obstacles=4 --set side_openings=2 --out worlds",
    ),
    # Levels: straight corridors with more and more obstacles, then an L, then a U bend (two turns); the
    # starts are the counts whose worlds' median level is the level (seeds 100-109, docs/metrics.md).
    knob=Knob("n_obstacles", (0, 3, 4, 5, 6, 0, 1, 4, 0, 2), step=1.0, high=6.0,
              fixed=((1, 5, {"shape": "straight"}), (6, 8, {"shape": "L"}), (9, 10, {"shape": "U"}))),
)


def _m(x: float) -> str:
    """Metres for a message: up to 3 decimals, at least one (1.0, 0.45)."""
    text = f"{x:.3f}".rstrip("0")
    return text + "0" if text.endswith(".") else text
