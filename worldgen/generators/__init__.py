"""Generators: pure functions from validated parameters and a seeded RNG to a draft world."""

from worldgen.generators.base import Draft, GeneratorSpec, robot_from_params
from worldgen.generators.knob import LEVELS, Knob
from worldgen.generators.registry import ENTRY_POINT_GROUP, all_specs, get, names, register

__all__ = ["Draft", "GeneratorSpec", "Knob", "LEVELS", "robot_from_params", "ENTRY_POINT_GROUP", "all_specs", "get",
           "names", "register"]
