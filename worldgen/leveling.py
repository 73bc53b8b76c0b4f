"""Worlds at a requested difficulty level: ``worldgen.generate("cluttered", seed=3, difficulty="7/10")``.

The level is world.json's ``metrics.difficulty_level`` (1..10, the frozen model
of :mod:`worldgen.groundtruth.difficulty`). A request draws worlds until one
lands in the level, each draw a whole world of its own:

- draw ``k``'s seed is :func:`worldgen.seeding.level_seed` ``(seed, k)``;
- its knob (the cluttered generator's ``n_obstacles``, scaled by the floor
  area: :data:`START` obstacles per 100 m^2 for each level) starts at the
  level's calibrated count and moves after every draw by :data:`STEP` times
  the levels it missed by (up for too easy, down for too hard), within
  ``[0, MAX_KNOB * area / 100]``;
- the first draw whose level is the one asked for is the world; after
  :data:`MAX_DRAWS` misses the request is an InfeasibleError naming the levels
  reached.

The world is an ordinary one: its ``seed`` and ``params`` (with the knob's
value) regenerate it without any of this. world.json's ``difficulty_request``
records how it was reached: the level asked for, the request's seed and every
draw (seed, knob, difficulty, level). The same request gives the same world in
any process.
"""

from __future__ import annotations

import re
from typing import Any, Callable, Mapping

from worldgen.errors import InfeasibleError, ParameterError, quoted
from worldgen.floats import finite_or_none
from worldgen.groundtruth import difficulty, truth
from worldgen.seeding import level_seed

__all__ = ["LEVELS", "MAX_DRAWS", "STEP", "START", "MAX_KNOB", "KNOBS", "parse_level", "check_request", "score",
           "generate_at_level"]

#: Levels of world.json's ``difficulty_level``.
LEVELS = 10
#: Draws a request may make before it gives up.
MAX_DRAWS = 40
#: Obstacles (per 100 m^2) the knob moves per level missed.
STEP = 4.0
#: Most obstacles per 100 m^2 a draw may ask for.
MAX_KNOB = 120.0
#: Obstacles per 100 m^2 of floor the first draw for each level asks for (levels 1..10). Calibrated on
#: default 10 x 10 m cluttered rooms (seeds 0-7 at 0-80 obstacles): the median level reached.
START = (0.0, 10.0, 20.0, 30.0, 35.0, 40.0, 45.0, 55.0, 65.0, 75.0)
#: The generators that can be asked for a level, and the parameter each turns.
KNOBS = {"cluttered": "n_obstacles"}

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
    """(level, knob) of a request for ``level_value`` from generator ``name`` with ``params``; one-line
    ParameterError for a bad level, a generator without a knob, or a knob the caller also set."""
    level = parse_level(level_value)
    knob = KNOBS.get(name)
    if knob is None:
        raise ParameterError(f"parameter 'difficulty' is offered by the generators {', '.join(sorted(KNOBS))}, "
                             f"not by {name!r}")
    for fixed in (knob, "density"):
        if params.get(fixed) is not None:
            raise ParameterError(f"parameter 'difficulty' sets {knob} itself; leave out {fixed!r} "
                                 f"(got {fixed}={quoted(params[fixed])})")
    return level, knob


def generate_at_level(generate: Callable, name: str, seed: int, level_value: Any, params: Mapping[str, Any]):
    """A world of generator ``name`` at the level ``level_value`` asks for (see the module); ``generate`` is
    :func:`worldgen.generate`."""
    level, knob = check_request(name, level_value, params)
    size = params.get("size", (10.0, 10.0))
    area = float(size[0]) * float(size[1]) if isinstance(size, (list, tuple)) and len(size) == 2 else 100.0
    scale = area / 100.0
    count = START[level - 1] * scale
    draws = []
    for k in range(MAX_DRAWS):
        draw_seed = level_seed(seed, k)
        n = int(round(count))
        try:
            world = generate(name, draw_seed, **{**params, knob: n})
        except InfeasibleError:  # too crowded a room to place or drive: ease off
            draws.append({"seed": draw_seed, knob: n, "difficulty": None, "level": None})
            count = max(0.0, count - STEP * scale)
            continue
        got = score(world)
        draws.append({"seed": draw_seed, knob: n, "difficulty": got["difficulty"], "level": got["difficulty_level"]})
        if got["difficulty_level"] == level:
            world.difficulty_request = {"level": f"{level}/{LEVELS}", "seed": seed, "knob": knob, "draws": draws}
            return world
        missed = level - (got["difficulty_level"] or level)
        count = min(max(count + STEP * scale * missed, 0.0), MAX_KNOB * scale)
    reached = sorted({d["level"] for d in draws if d["level"] is not None})
    raise InfeasibleError(f"no '{name}' world at level {level}/{LEVELS} for seed {seed} within {MAX_DRAWS} draws "
                          f"(levels reached: {', '.join(map(str, reached)) or 'none'}); try another seed or a "
                          f"level nearer {_nearest(reached, level)}", {"difficulty_level": MAX_DRAWS})


def _nearest(reached: list, level: int) -> str:
    return str(min(reached, key=lambda v: (abs(v - level), v))) if reached else "the middle"
