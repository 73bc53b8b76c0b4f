"""A generator's difficulty knob: the parameter a level request turns, declared in the generator's spec.

A generator offers levels (``worldgen.generate(name, difficulty="7/10")``, worldgen.leveling) by giving its
:class:`~worldgen.generators.GeneratorSpec` a ``knob=Knob(...)`` beside its ``params``, calibrated on its own
worlds; a generator whose worlds cannot be turned gives ``no_levels="why"`` instead. The spec checks that
what the knob names are parameters of the generator, so a knob cannot drift from the parameters it turns,
and a generator from another package (entry-point group ``worldgen.generators``) declares one the same way.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any, Mapping, Optional, Union

from worldgen.errors import ParameterError

__all__ = ["LEVELS", "Knob"]

#: Levels of world.json's ``metrics.difficulty_level`` (worldgen.groundtruth.difficulty.level_of): a knob
#: has one starting value per level.
LEVELS = 10


@dataclass(frozen=True)
class Knob:
    """How one generator is turned towards a level: the parameter a request sets draw by draw.

    ``start[level - 1]`` is the first draw's value for that level, None where the generator cannot reach the
    level (a request for it is refused up front). After a draw that misses, the value moves by ``step`` per
    level missed (up for a world too easy), within [``low``, ``high``]; a draw the generator cannot build
    (InfeasibleError: too crowded) moves it ``step`` down. ``per_area``: ``start``, ``step`` and ``high`` are
    per 100 m^2 of the request's ``size``. ``fixed`` sets further parameters by level: (first level, last
    level, {parameter: value}). The request sets the knob, every ``fixed`` parameter and ``excludes``; the
    caller leaves them out.
    """

    param: str
    start: tuple[Optional[float], ...]
    step: float
    high: float
    low: float = 0.0
    per_area: bool = False
    fixed: tuple[tuple[int, int, Mapping[str, Any]], ...] = ()
    excludes: tuple[str, ...] = ()
    integer: bool = True

    def __post_init__(self) -> None:
        # A spec is built at import time: a malformed knob is refused there, not at the first request.
        if len(self.start) != LEVELS:
            raise ParameterError(f"a knob's start must give one value (or None) per level 1..{LEVELS}, "
                                 f"got {len(self.start)} for {self.param!r}")
        if not self.low <= self.high or self.step <= 0:
            raise ParameterError(f"a knob must have low <= high and a positive step, got low={self.low}, "
                                 f"high={self.high}, step={self.step} for {self.param!r}")

    def value(self, x: float) -> Union[int, float]:
        """The parameter's value for the knob's position ``x``: a whole number for an integer knob."""
        return int(round(x)) if self.integer else round(float(x), 6)

    def sets(self, level: int) -> dict:
        """The parameters besides the knob a request for ``level`` sets."""
        return {k: v for lo, hi, values in self.fixed if lo <= level <= hi for k, v in values.items()}

    def owned(self) -> tuple[str, ...]:
        """Every parameter a request sets (the caller must leave them out)."""
        names = [self.param, *(k for _, _, values in self.fixed for k in values), *self.excludes]
        return tuple(dict.fromkeys(names))

    def reachable(self) -> tuple[int, ...]:
        """The levels this knob can be asked for: those with a starting value."""
        return tuple(i + 1 for i, v in enumerate(self.start) if v is not None)
