"""Worlds at a requested difficulty level: ``worldgen.generate("cluttered", seed=3, difficulty="7/10")``.

The level is world.json's ``metrics.difficulty_level`` (1..10, the frozen model
of :mod:`worldgen.groundtruth.difficulty`). A request draws worlds until one
lands in the level, each draw a whole world of its own:

- draw ``k``'s seed is :func:`worldgen.seeding.level_seed` ``(seed, k)``;
- its knob (:data:`KNOBS`: a parameter per generator, e.g. the cluttered
  generator's ``n_obstacles`` scaled by the floor area, the corridor's
  ``n_obstacles`` with its ``shape`` set by level, the door world's ``n_doors``
  with its doors' ``state`` set by level) starts at the level's calibrated
  value and moves after every draw by the knob's step times the levels it
  missed by (up for too easy, down for too hard), within the knob's bounds;
- the first draw whose level is the one asked for is the world; after
  :data:`MAX_DRAWS` misses the request is an InfeasibleError naming the levels
  reached. A level a generator cannot reach (:func:`reachable`; ``worldgen list
GENERATOR`` prints it) and a generator without a knob (:data:`NO_LEVELS`) are
refused up front in one line.

With people (``n_people``) a draw is judged on its world without them (``n_people=0``; the level never
reads the people) and the people are walked only on a draw that landed, on the attempt it landed on; where
they refuse it (no timed path) the draw is recorded with no level and the next draw keeps the knob. Such
refusals have their own budget of :data:`MAX_DRAWS` beside the misses' (docs/metrics.md). Walking them on
every attempt of every draw made a 10-draw request 133 s of CPU.

The world is an ordinary one: its ``seed`` and ``params`` (with the knob's
value) regenerate it without any of this. world.json's ``difficulty_request``
records how it was reached: the level asked for, the request's seed and every
draw (seed, knob, difficulty, level). The same request gives the same world in
any process.
"""

from __future__ import annotations

import logging
import re
from dataclasses import dataclass
from typing import Any, Callable, Mapping, Optional

from worldgen.errors import InfeasibleError, ParameterError, quoted
from worldgen.floats import finite_or_none
from worldgen.groundtruth import difficulty, truth
from worldgen.seeding import level_seed

#: Where a long request says what it is doing (worldgen.cli.progress shows it on a terminal; nothing else does).
_progress = logging.getLogger("worldgen.progress")

__all__ = ["LEVELS", "MAX_DRAWS", "STEP", "START", "MAX_KNOB", "Knob", "KNOBS", "NO_LEVELS", "reachable",
           "describe_levels", "parse_level", "check_request", "score", "generate_at_level"]

#: Levels of world.json's ``difficulty_level``.
LEVELS = 10
#: Draws a request may make before it gives up.
MAX_DRAWS = 40
#: Obstacles (per 100 m^2) the cluttered knob moves per level missed.
STEP = 4.0
#: Most obstacles per 100 m^2 a cluttered draw may ask for.
MAX_KNOB = 120.0
#: Obstacles per 100 m^2 of floor the first cluttered draw for each level asks for (levels 1..10). Calibrated on
#: default 10 x 10 m cluttered rooms: about the median obstacle count of the worlds that landed in each level
#: (requests with seeds 100-111; the first calibration, 0, 10, 20, 30, 35, 40, 45, 55, 65, 75, left level 9
#: at a median of 77 obstacles, above level 10's 75).
START = (0.0, 8.0, 17.0, 23.0, 31.0, 36.0, 41.0, 50.0, 70.0, 78.0)


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

    def value(self, x: float):
        """The parameter's value for the knob's position ``x``: a whole number for an integer knob."""
        return int(round(x)) if self.integer else round(float(x), 6)

    def sets(self, level: int) -> dict:
        """The parameters besides the knob a request for ``level`` sets."""
        return {k: v for lo, hi, values in self.fixed if lo <= level <= hi for k, v in values.items()}

    def owned(self) -> tuple[str, ...]:
        """Every parameter a request sets (the caller must leave them out)."""
        names = [self.param, *(k for _, _, values in self.fixed for k in values), *self.excludes]
        return tuple(dict.fromkeys(names))


#: The generators that can be asked for a level, and how each is turned. Calibrations (``start``): the
#: value whose worlds' median level is the level, measured with seeds the tests do not use (docs/metrics.md).
#: Every registered generator is a row here or in :data:`NO_LEVELS` (tests/test_leveling.py holds it).
KNOBS: dict[str, Knob] = {
    "cluttered": Knob("n_obstacles", START, STEP, MAX_KNOB, per_area=True, excludes=("density",)),
    # Straight corridors with more and more obstacles, then an L, then a U bend (two turns).
    "corridor": Knob("n_obstacles", (0, 3, 4, 5, 6, 0, 1, 4, 0, 2), 1.0, 6.0,
                     fixed=((1, 5, {"shape": "straight"}), (6, 8, {"shape": "L"}), (9, 10, {"shape": "U"}))),
    # Open doors (rooms in a row) up to level 5, closed leaves to push from level 6.
    "door": Knob("n_doors", (None, 1, 1, 1, 1, 1, 1, 1, 2, 4), 1.0, 5.0, low=1.0,
                 fixed=((1, 5, {"state": "open"}), (6, 10, {"state": "closed"}))),
    # BARN's cellular-automaton fields, fuller and fuller (the field's size is the request's, not scaled:
    # a fill fraction is already per cell). Medians of seeds 0-19: level 1 at 0.1, 5 at 0.2, 8 at 0.3. No
    # higher than 0.325: at 0.35 most fields cannot be crossed, and a draw refused 400 times costs 0.6 s
    # (six level-10 requests: 38 s with 0.35 as the top, 21 s with 0.325).
    "barn": Knob("fill_fraction", (0.1, 0.15, 0.175, 0.19, 0.2, 0.225, 0.275, 0.3, 0.325, 0.325), 0.025, 0.325,
                 integer=False),
}
#: Generators without a level, and why (a request for one is refused in one line saying so).
NO_LEVELS: dict[str, str] = {
    "minimal": "it has no random draws: one target at an exact distance for a sensor test",
}


def reachable(name: str) -> tuple[int, ...]:
    """The levels generator ``name`` can be asked for (none for a generator without a knob)."""
    knob = KNOBS.get(name)
    return () if knob is None else tuple(i + 1 for i, v in enumerate(knob.start) if v is not None)


def describe_levels(name: str) -> str:
    """One line on the levels generator ``name`` can be asked for (``worldgen list GENERATOR`` prints it)."""
    levels = reachable(name)
    if not levels:
        why = NO_LEVELS.get(name, "no knob is calibrated for it")
        return f"difficulty: no levels ({why})"
    knob = KNOBS[name]
    also = sorted({k for k in knob.owned() if k != knob.param})
    sets = f"; sets {', '.join(also)} by level" if knob.fixed else ""
    return f"difficulty: levels {_ranges(levels)} of {LEVELS} (--difficulty K/{LEVELS} turns {knob.param}{sets})"


def _ranges(levels) -> str:
    """"1-3, 5, 7-10" for (1, 2, 3, 5, 7, 8, 9, 10)."""
    out, run = [], [levels[0]]
    for v in levels[1:]:
        if v == run[-1] + 1:
            run.append(v)
            continue
        out.append(f"{run[0]}-{run[-1]}" if len(run) > 1 else str(run[0]))
        run = [v]
    out.append(f"{run[0]}-{run[-1]}" if len(run) > 1 else str(run[0]))
    return ", ".join(out)

_LEVEL = re.compile(r"^\s*(\d+)\s*/\s*(\d+)\s*$")


def parse_level(value: Any) -> int:
    """The level 1..10 of ``"k/10"`` or ``k``; one-line ParameterError otherwise."""
    level = None
    if isinstance(value, int) and not isinstance(value, bool):
        level = value
    elif isinstance(value, str):
        m = _LEVEL.match(value)
        if m and int(m.group(2)) == LEVELS:
            level = int(m.group(1))
        elif value.strip().isdigit():
            level = int(value)
    if level is None or not 1 <= level <= LEVELS:
        raise ParameterError(f"parameter 'difficulty' must be a level 'k/{LEVELS}' with k in 1..{LEVELS} "
                             f"(or the integer k), got {quoted(value)}")
    return level


def score(world) -> dict:
    """``difficulty``, ``difficulty_level`` and ``difficulty_model`` of ``world`` as its world.json will have
    them, from its paths and path-local figures alone (no file rendered)."""
    from worldgen.export.tasks import task_entry

    report = world.feasibility
    paths = list(report.paths) + [None] * max(0, len(world.tasks) - len(report.paths))
    meta = {
        "metrics": {"narrowest_passage": finite_or_none(report.narrowest_passage), **truth.difficulty(world)},
        "robot": {"radius": world.robot.radius},
        "tasks": [task_entry(world, task, path) for task, path in zip(world.tasks, paths)],
    }
    return difficulty.assess(meta)


def check_request(name: str, level_value: Any, params: Mapping[str, Any]) -> tuple[int, str]:
    """(level, knob parameter) of a request for ``level_value`` from generator ``name`` with ``params``; one-line
    ParameterError for a bad level, a generator without levels or without that level, or a parameter the
    request sets that the caller also set."""
    level = parse_level(level_value)
    knob = KNOBS.get(name)
    if knob is None:
        why = f" ({NO_LEVELS[name]})" if name in NO_LEVELS else ""
        raise ParameterError(f"parameter 'difficulty' is offered by the generators {', '.join(sorted(KNOBS))}, "
                             f"not by {name!r}{why}")
    levels = reachable(name)
    if level not in levels:
        raise ParameterError(f"parameter 'difficulty' {level}/{LEVELS} is out of reach of {name!r}: it reaches "
                             f"levels {_ranges(levels)}")
    for fixed in knob.owned():
        if params.get(fixed) is not None:
            owned = [knob.param, *sorted(k for k in knob.owned() if k != knob.param and k not in knob.excludes)]
            raise ParameterError(f"parameter 'difficulty' sets {' and '.join(owned)} itself; leave out {fixed!r} "
                                 f"(got {fixed}={quoted(params[fixed])})")
    return level, knob.param


def generate_at_level(generate: Callable, name: str, seed: int, level_value: Any, params: Mapping[str, Any],
                      people_on: Callable):
    """A world of generator ``name`` at the level ``level_value`` asks for (see the module); ``generate`` is
    :func:`worldgen.generate`, ``people_on(world, params)`` the world with people of the same draw and attempt,
    or None where they refuse it (worldgen.api)."""
    level, param = check_request(name, level_value, params)
    knob = KNOBS[name]
    scale = 1.0
    if knob.per_area:
        size = params.get("size", (10.0, 10.0))
        scale = float(size[0]) * float(size[1]) / 100.0 if isinstance(size, (list, tuple)) and len(size) == 2 else 1.0
    value = float(knob.start[level - 1] or 0.0) * scale
    low, high, step = knob.low * scale, knob.high * scale, knob.step * scale
    fixed = {**params, **knob.sets(level)}
    people = bool(params.get("n_people"))
    # With people the level is judged on the draw without them, and they are added only to a draw that
    # landed (see the module): the people are walked once per landed draw, not once per draw.
    drawn = _without_people(fixed) if people else fixed
    draws: list[dict] = []
    refused = 0  # landed draws the people refused: a budget of their own, beside the draws' (see the module)
    for k in range(2 * MAX_DRAWS):
        if len(draws) - refused >= MAX_DRAWS or refused >= MAX_DRAWS:
            break
        draw_seed = level_seed(seed, k)
        n = knob.value(value)
        _progress.info("%s at level %d/%d, seed %d: draw %d of at most %d (%s=%s)%s", name, level, LEVELS, seed,
                       len(draws) - refused + 1, MAX_DRAWS, param, n, _last(draws))
        try:
            world = generate(name, draw_seed, **{**drawn, param: n})
        except InfeasibleError:  # too crowded to place or drive: ease off
            draws.append({"seed": draw_seed, param: n, "difficulty": None, "level": None})
            value = max(low, value - step)
            continue
        got = score(world)
        if people and got["difficulty_level"] == level:
            _progress.info("%s at level %d/%d, seed %d: draw %d landed; walking %d people", name, level, LEVELS,
                           seed, len(draws) - refused + 1, params["n_people"])
            with_people = people_on(world, {**fixed, param: n})
            if with_people is None:  # no timed path among them on the landed attempt: same knob, next draw
                draws.append({"seed": draw_seed, param: n, "difficulty": None, "level": None})
                refused += 1
                continue
            world = with_people
        draws.append({"seed": draw_seed, param: n, "difficulty": got["difficulty"], "level": got["difficulty_level"]})
        if got["difficulty_level"] == level:
            return world.set_provenance(difficulty_request={"level": f"{level}/{LEVELS}", "seed": seed, "knob": param,
                                                            "draws": draws})
        missed = level - (got["difficulty_level"] or level)
        value = min(max(value + step * missed, low), high)
    reached = sorted({d["level"] for d in draws if d["level"] is not None})
    also = f" and {refused} landed draws the people refused (no timed path among them)" if refused else ""
    raise InfeasibleError(f"no '{name}' world at level {level}/{LEVELS} for seed {seed} within {MAX_DRAWS} draws{also} "
                          f"(levels reached: {', '.join(map(str, reached)) or 'none'}); try another seed or a "
                          f"level nearer {_nearest(reached, level)}", {"difficulty_level": MAX_DRAWS})


def _without_people(params: Mapping[str, Any]) -> dict:
    """``params`` with every people parameter left out (a world without people refuses them)."""
    from worldgen.params import PEOPLE_PARAMS

    return {k: v for k, v in params.items() if k not in PEOPLE_PARAMS}


def _last(draws: list) -> str:
    """", the last at level K" for the progress line (", the last refused" for a draw that could not be built)."""
    if not draws:
        return ""
    return ", the last refused" if draws[-1]["level"] is None else f", the last at level {draws[-1]['level']}"


def _nearest(reached: list, level: int) -> str:
    return str(min(reached, key=lambda v: (abs(v - level), v))) if reached else "the middle"
