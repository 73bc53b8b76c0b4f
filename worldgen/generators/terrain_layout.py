"""Terrain elements drawn and placed for a generator: the ``terrain`` generator's, and ``cluttered``'s
with ``terrain=true``. Ramps, kerbs and potholes, rough patches (worldgen.scene.terrain), each drawn from
its range parameter and placed ``terrain_gap`` clear of the walls, the obstacles and each other, on the
stream the caller gives; spawns and goals are then drawn off every element (they stand on the flat floor).
docs/terrain.md.
"""

from __future__ import annotations

import math
from typing import Any, Mapping

import numpy as np
import shapely

from worldgen.errors import ParameterError
from worldgen.floats import round_float
from worldgen.params import Param
from worldgen.scene import Scene
from worldgen.scene.footprint import Footprint, robot_footprints
from worldgen.scene.terrain import Element, Ramp, Rough, Step, Terrain

__all__ = ["TERRAIN_PARAMS", "check_terrain", "with_terrain", "MAX_ELEMENTS", "PLACEMENT_TRIES"]

#: Tries to place one terrain element before the draw counts as too full.
PLACEMENT_TRIES = 60
#: Most terrain elements of each kind one world may ask for.
MAX_ELEMENTS = 50

TERRAIN_PARAMS = (
    Param("n_ramps", "int", 1, "ramps: up, a landing, down", 0, MAX_ELEMENTS),
    Param("ramp_incline", "range", [5.0, 9.0], "range each ramp's incline is drawn from", 0.5, 40.0, unit="deg"),
    Param("ramp_rise", "range", [0.05, 0.15], "range each ramp's height is drawn from", 0.005, 1.0, unit="m"),
    Param("ramp_width", "range", [1.5, 2.5], "range each ramp's width is drawn from", 0.2, 20.0, unit="m"),
    Param("ramp_landing", "range", [0.5, 1.5], "range each ramp's landing length is drawn from (0: a bump)",
          0.0, 20.0, unit="m"),
    Param("n_kerbs", "int", 2, "kerbs and potholes: rectangles raised or sunk by a step", 0, MAX_ELEMENTS),
    Param("kerb_height", "range", [0.01, 0.05], "range each step's height (or pothole's depth) is drawn from",
          0.001, 0.5, unit="m"),
    Param("kerb_size", "range", [0.5, 1.5], "range each side of a kerb or pothole is drawn from", 0.1, 20.0, unit="m"),
    Param("pothole_share", "float", 0.3, "share of the kerbs that are potholes (sunk, not raised)", 0.0, 1.0),
    Param("n_rough", "int", 1, "rough patches: seeded heights on a grid", 0, MAX_ELEMENTS),
    Param("rough_size", "range", [1.5, 3.0], "range each side of a rough patch is drawn from", 0.2, 50.0, unit="m"),
    Param("rough_amplitude", "float", 0.01, "largest height (up or down) of a rough patch's grid nodes",
          0.0, 0.5, unit="m"),
    Param("rough_cell", "float", 0.25, "spacing of a rough patch's grid", 0.05, 5.0, unit="m"),
    Param("terrain_gap", "float", 0.2, "smallest distance between a terrain element and a wall, an obstacle or "
          "another element", 0.0, 10.0, unit="m"),
)


def check_terrain(params: Mapping[str, Any]) -> None:
    """Reject element sizes no room of ``size`` could hold."""
    sx, sy = params["size"]
    for kind, side in (("ramp_width", params["ramp_width"][0]), ("kerb_size", params["kerb_size"][0]),
                       ("rough_size", params["rough_size"][0])):
        if side > min(sx, sy):
            raise ParameterError(f"parameter {kind!r} must fit in the room ({min(sx, sy):g} m), got {params[kind]!r}")
    if params["rough_size"][0] < 2 * params["rough_cell"]:
        raise ParameterError(f"parameter 'rough_size' must be at least 2 x rough_cell = {2 * params['rough_cell']:g} m "
                             f"(a patch needs an inner grid node), got {params['rough_size']!r}")


def with_terrain(flat: Scene, params: Mapping[str, Any], rng: np.random.Generator, robot) -> \
        tuple[Scene, list[Footprint]] | str:
    """(``flat`` with its terrain, the elements' outlines to keep spawns and goals off), or why the elements
    did not fit."""
    elements = _place_terrain(params, rng, flat.bounds, robot_footprints(flat, robot))
    if isinstance(elements, str):
        return elements
    scene = flat.with_terrain(Terrain(tuple(elements)) if elements else None)
    return scene, [Footprint(f"terrain_{k}", "terrain", polygon=e.outline()) for k, e in enumerate(elements)]


def _draw_element(kind: str, params, rng: np.random.Generator) -> Element:
    """One element of ``kind`` at the origin (placed by the caller)."""
    def draw(name):
        return round_float(rng.uniform(*params[name]))
    if kind == "ramp":
        rise, incline = draw("ramp_rise"), draw("ramp_incline")
        run = round_float(rise / math.tan(math.radians(incline)))
        return Ramp(0.0, 0.0, 0.0, draw("ramp_width"), rise, run, draw("ramp_landing"))
    if kind == "step":
        length, width, height = draw("kerb_size"), draw("kerb_size"), draw("kerb_height")
        return Step(0.0, 0.0, 0.0, length, width, -height if rng.random() < params["pothole_share"] else height)
    cell = params["rough_cell"]
    nx, ny = (max(2, int(round(draw("rough_size") / cell))) for _ in range(2))
    grid = np.zeros((ny + 1, nx + 1))
    a = params["rough_amplitude"]
    grid[1:-1, 1:-1] = [[round_float(v) for v in row] for row in rng.uniform(-a, a, size=(ny - 1, nx - 1))]
    return Rough(0.0, 0.0, 0.0, cell, tuple(tuple(float(v) for v in row) for row in grid))


def _place_terrain(params, rng: np.random.Generator, bounds, footprints) -> list[Element] | str:
    """The elements placed clear of the obstacles and each other, or why they did not fit."""
    gap = params["terrain_gap"]
    taken = [f.polygon if f.polygon is not None else shapely.Point(f.centre).buffer(f.radius, quad_segs=16)
             for f in footprints if f.role != "floor" and f.role != "wall"]
    (x0, y0), (x1, y1) = bounds
    room = shapely.box(x0 + gap, y0 + gap, x1 - gap, y1 - gap)
    placed: list[Element] = []
    kinds = ["ramp"] * params["n_ramps"] + ["step"] * params["n_kerbs"] + ["rough"] * params["n_rough"]
    for kind in kinds:
        shape = _draw_element(kind, params, rng)
        for _ in range(PLACEMENT_TRIES):
            x, y = round_float(rng.uniform(x0, x1)), round_float(rng.uniform(y0, y1))
            yaw = round_float(rng.uniform(-math.pi, math.pi))
            element = _moved(shape, x, y, yaw)
            outline = element.outline()
            if not room.contains(outline):
                continue
            near = outline.buffer(gap)
            if any(near.intersects(t) for t in taken):
                continue
            taken.append(outline)
            placed.append(element)
            break
        else:
            return f"could not place {kind} {len(placed) + 1} of {len(kinds)} terrain elements " \
                   f"with terrain_gap {gap:g} m"
    return placed


def _moved(e: Element, x: float, y: float, yaw: float) -> Element:
    if isinstance(e, Ramp):
        return Ramp(x, y, yaw, e.width, e.rise, e.run, e.landing)
    if isinstance(e, Step):
        return Step(x, y, yaw, e.length, e.width, e.height)
    return Rough(x, y, yaw, e.cell, e.grid)
