"""What a generator is: a name, its parameters, its difficulty knob, and a pure build function."""

from __future__ import annotations

import math
import re
from dataclasses import dataclass, field
from typing import Any, Callable, Mapping, Optional

import numpy as np

from worldgen.errors import ParameterError
from worldgen.floats import round_float
from worldgen.generators.knob import Knob
from worldgen.params import COMMON_PARAMS, Param, validate_params
from worldgen.scene import Robot, Scene, Task
from worldgen.scene.robot import CLIMB_DEFAULTS

__all__ = ["Draft", "GeneratorSpec", "robot_from_params"]


@dataclass(frozen=True)
class Draft:
    """One draw of a generator: a scene and its tasks, not yet checked for feasibility.

    ``rejected`` names the check a draw failed on the generator's side (e.g. the
    obstacles did not fit); the pipeline counts it like a failed feasibility check.
    """

    scene: Optional[Scene]
    tasks: tuple[Task, ...] = ()
    rejected: Optional[str] = None
    detail: str = ""


@dataclass(frozen=True)
class GeneratorSpec:
    """A registered generator.

    ``build(params, rng)`` must be a pure function of the validated parameters and
    the ``numpy.random.Generator``; ``check(params)`` may reject combinations of
    parameters (raising :class:`~worldgen.errors.ParameterError`). ``knob`` is the
    parameter a request for a difficulty level turns (:class:`~worldgen.generators.Knob`,
    worldgen.leveling); a generator without one says why in ``no_levels``.
    """

    name: str
    summary: str
    params: tuple[Param, ...]
    build: Callable[[Mapping[str, Any], np.random.Generator], Draft]
    check: Optional[Callable[[Mapping[str, Any]], None]] = None
    examples: tuple[str, ...] = field(default=())
    knob: Optional[Knob] = None
    no_levels: str = ""

    def __post_init__(self) -> None:
        # The name becomes part of every world_id, and so of folder names: keep it plain.
        if not re.fullmatch(r"[a-z][a-z0-9_]{0,31}", self.name):
            raise ParameterError(f"generator name {self.name!r} must be 1-32 of a-z, 0-9, _ (starting with a letter)")
        if self.knob is not None and self.no_levels:
            raise ParameterError(f"generator {self.name!r} declares a knob and says it has no levels; give one of them")
        if self.knob is not None:
            # Declared beside the parameters it turns, and checked against them: a renamed parameter
            # fails here, when the generator is defined, not at the first request for a level.
            known = {p.name for p in self.all_params}
            unknown = [name for name in self.knob.owned() if name not in known]
            if unknown:
                raise ParameterError(f"generator {self.name!r}: its knob sets {', '.join(map(repr, unknown))}, "
                                     f"which it has no parameter for")

    @property
    def all_params(self) -> tuple[Param, ...]:
        """The generator's own parameters plus the common ones, by name."""
        own = {p.name for p in self.params}
        return tuple(sorted(self.params + tuple(p for p in COMMON_PARAMS if p.name not in own), key=lambda p: p.name))

    def resolve(self, given: Mapping[str, Any]) -> dict[str, Any]:
        """Validated parameters with every default filled in."""
        resolved = validate_params(self.all_params, given)
        if self.check is not None:
            self.check(resolved)
        return resolved


def robot_from_params(params: Mapping[str, Any]) -> Robot:
    limits = {name: params[f"robot_{name}"] for name in CLIMB_DEFAULTS if f"robot_{name}" in params}
    if "max_incline" in limits:  # given in degrees, kept in radians as every angle of a world
        limits["max_incline"] = round_float(math.radians(limits["max_incline"]))
    return Robot(params["robot_radius"], params["robot_height"], params["clearance"], **limits)
