"""``corridor``'s terrain option (``terrain=true``, docs/terrain.md): ramps across the corridor.

Each ramp spans the corridor from side wall to side wall, its run along the leg it stands on: up over its
run, along its landing, down again; drawn from the ``terrain`` generator's ramp parameters and placed as an
obstacle is, on a free stretch of a leg's straight part, the passage (``min_passage``) clear of the
obstacles, the side openings, the other ramps and the spawn's and goal's room. The robot drives over it or
not at all, so a ramp steeper than it climbs (``robot_max_incline``) is refused up front. Off, the option's
parameters are neither taken nor recorded (``Param.option_of``): every corridor made before keeps its bytes.
"""

from __future__ import annotations

import math
from dataclasses import replace
from typing import Any, Callable, Mapping, Optional

import numpy as np

from worldgen.errors import InfeasibleError, ParameterError
from worldgen.floats import round_float
from worldgen.generators.terrain_layout import TERRAIN_PARAMS
from worldgen.params import CLIMB_PARAMS, Param
from worldgen.scene.terrain import Ramp

__all__ = ["RAMP_PARAMS", "OPTION_PARAMS", "ramp_length", "check_ramps", "place_ramps"]

#: The ``terrain`` generator's ramp parameters a corridor takes (a ramp's width is the corridor's).
RAMP_PARAMS = ("n_ramps", "ramp_incline", "ramp_rise", "ramp_landing")
OPTION_PARAMS: tuple[Param, ...] = (
    Param("terrain", "bool", False, "add ramps across the corridor (the terrain generator's ramp parameters "
          "below; docs/terrain.md)", option_of="terrain"),
) + tuple(replace(p, option_of="terrain") for p in TERRAIN_PARAMS + CLIMB_PARAMS
          if p.name in RAMP_PARAMS or p in CLIMB_PARAMS)


def ramp_length(rise: float, incline_deg: float, landing: float) -> float:
    """A ramp's length along the corridor (m): two runs and its landing."""
    return 2.0 * rise / math.tan(math.radians(incline_deg)) + landing


def check_ramps(params: Mapping[str, Any], longest: float, gap: float) -> None:
    """Refuse ramps no leg can hold (``longest``: the longest usable stretch of a leg, ``gap`` the passage
    kept either side) and ramps steeper than the robot climbs, which would close the corridor."""
    if not params["n_ramps"]:
        return
    shortest = ramp_length(params["ramp_rise"][0], params["ramp_incline"][1], params["ramp_landing"][0])
    if shortest + 2 * gap > longest:
        raise ParameterError(f"parameter 'ramp_rise' and 'ramp_incline' make every ramp at least {shortest:.3g} m "
                             f"long, which with {gap:g} m of passage either side no leg holds ({max(longest, 0.0):.3g} m "
                             f"usable); lengthen the corridor or lower n_ramps")
    if params["ramp_incline"][0] > params["robot_max_incline"]:
        raise InfeasibleError(f"parameter 'ramp_incline' {params['ramp_incline']!r} deg is steeper than the robot "
                              f"climbs (robot_max_incline {params['robot_max_incline']:g}): a ramp across the corridor "
                              "would close it")


def place_ramps(params: Mapping[str, Any], rng: np.random.Generator, lay, width: float,
                place: Callable[..., Optional[tuple[int, float, float]]], heading) -> list[Ramp] | str:
    """The ramps placed along the legs by ``place(rng, draw_length, gap)`` (the corridor's own placer, sharing
    its taken stretches), each across the corridor (``width``) with yaw ``heading(leg)``; or why they did not fit."""
    ramps = []
    for k in range(params["n_ramps"]):
        rise = round_float(rng.uniform(*params["ramp_rise"]))
        run = round_float(rise / math.tan(math.radians(round_float(rng.uniform(*params["ramp_incline"])))))
        landing = round_float(rng.uniform(*params["ramp_landing"]))
        spot = place(rng, lambda: 2.0 * run + landing)
        if spot is None:
            return f"could not place ramp {k + 1} of {params['n_ramps']} along the corridor"
        leg, a, b = spot
        centre = lay.points[leg] + (a + b) / 2 * lay.u(leg)
        ramps.append(Ramp(round_float(centre[0]), round_float(centre[1]), heading(leg), round_float(width), rise, run,
                          landing))
    return ramps
