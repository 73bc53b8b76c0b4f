"""Worlds at a requested difficulty level: ``worldgen.generate("cluttered", seed=3, difficulty="7/10")``.

The level is world.json's ``metrics.difficulty_level`` (1..10, the frozen model
of :mod:`worldgen.groundtruth.difficulty`). A request draws worlds until one
lands in the level, each draw a whole world of its own:

- draw ``k``'s seed is :func:`worldgen.seeding.level_seed` ``(seed, k)``;
- its knob (the ``knob`` the generator's spec declares beside its parameters,
  :class:`worldgen.generators.Knob`: e.g. the cluttered generator's
  ``n_obstacles`` scaled by the floor area, the corridor's ``n_obstacles`` with
  its ``shape`` set by level, the door world's ``n_doors`` with its doors'
  ``state`` set by level) starts at the level's calibrated value and moves
  after every draw by the knob's step times the levels it missed by (up for
  too easy, down for too hard), within the knob's bounds;
- each draw is one request of :mod:`worldgen.pipeline` (attempts until one is
  kept), called from here, as ``worldgen.generate`` calls it;
- the first draw whose level is the one asked for is the world; after
  :data:`MAX_DRAWS` misses the request is an InfeasibleError naming the levels
  reached. A level a generator cannot reach (:func:`reachable`; ``worldgen list
GENERATOR`` prints it) and a generator without a knob (its spec's ``no_levels``
says why) are refused up front in one line.

With people (``n_people``) a draw is judged on its world without them (``n_people=0``; the level never
reads the people) and the people are walked only on a draw that landed, on the attempt it landed on
(:func:`worldgen.pipeline.attempt` of that number, with the people's parameters); where
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
import warnings
from typing import Any, Mapping

from worldgen.errors import InfeasibleError, ParameterError, quoted
from worldgen.export.tasks import leaves_on_path
from worldgen.floats import finite_or_none
from worldgen.generators import LEVELS, GeneratorSpec, Knob, all_specs, get
from worldgen.groundtruth import difficulty, truth
from worldgen.pipeline import attempt, first_feasible, prepare
from worldgen.seeding import level_seed
from worldgen.world import World

#: Where a long request says what it is doing (worldgen.cli.progress shows it on a terminal; nothing else does).
_progress = logging.getLogger("worldgen.progress")

__all__ = ["LEVELS", "MAX_DRAWS", "reachable", "describe_levels", "parse_level", "check_request", "score",
           "generate_at_level"]

#: Draws a request may make before it gives up.
MAX_DRAWS = 40


def _knob(spec: GeneratorSpec) -> Knob:
    """The knob ``spec`` declares; a one-line ParameterError saying why for a generator without one."""
    if spec.knob is None:
        offered = ", ".join(s.name for s in all_specs() if s.knob is not None)
        why = f" ({spec.no_levels})" if spec.no_levels else ""
        raise ParameterError(f"parameter 'difficulty' is offered by the generators {offered}, not by {spec.name!r}{why}")
    return spec.knob


def reachable(name: str) -> tuple[int, ...]:
    """The levels generator ``name`` can be asked for (none for a generator without a knob)."""
    knob = get(name).knob
    return () if knob is None else knob.reachable()


def describe_levels(name: str) -> str:
    """One line on the levels generator ``name`` can be asked for (``worldgen list GENERATOR`` prints it)."""
    spec = get(name)
    knob = spec.knob
    if knob is None or not knob.reachable():
        return f"difficulty: no levels ({spec.no_levels or 'no knob is calibrated for it'})"
    levels = knob.reachable()
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
    them, from the figures the model reads (:func:`worldgen.groundtruth.difficulty.features_from`): the five
    exact figures along its paths, its narrowest passage, the robot's radius, each task's reference path and
    whether that path needs a door leaf moved. No file is rendered and no world.json is built."""
    report = world.feasibility
    paths = [report.paths[i] if i < len(report.paths) else None for i in range(len(world.tasks))]
    f = difficulty.features_from(truth.difficulty(world), finite_or_none(report.narrowest_passage), world.robot.radius,
                                 [(p.waypoints, float(p.length)) for p in paths if p is not None],
                                 [bool(leaves_on_path(world, p)) for p in paths])
    terrain = world.scene.terrain
    if f is not None and terrain is not None:  # as world.json's score reads it: the first task's path
        first = next((fig for p, fig in zip(paths, getattr(report, "terrain", ())) if p is not None), None)
        f.update(difficulty.terrain_features(terrain, world.scene.bounds, None if first is None else first.profile,
                                             None if first is None else (first.largest_incline, first.largest_step)))
    return difficulty.rating(f)


def check_request(name: str, level_value: Any, params: Mapping[str, Any]) -> tuple[int, str]:
    """(level, knob parameter) of a request for ``level_value`` from generator ``name`` with ``params``; one-line
    ParameterError for a bad level, a generator without levels or without that level, or a parameter the
    request sets that the caller also set."""
    return _check(get(name), level_value, params)


def _check(spec: GeneratorSpec, level_value: Any, params: Mapping[str, Any]) -> tuple[int, str]:
    """:func:`check_request` of ``spec`` itself."""
    level = parse_level(level_value)
    knob, name = _knob(spec), spec.name
    levels = knob.reachable()
    if level not in levels:
        raise ParameterError(f"parameter 'difficulty' {level}/{LEVELS} is out of reach of {name!r}: it reaches "
                             f"levels {_ranges(levels)}")
    for fixed in knob.owned():
        if params.get(fixed) is not None:
            owned = [knob.param, *sorted(k for k in knob.owned() if k != knob.param and k not in knob.excludes)]
            raise ParameterError(f"parameter 'difficulty' sets {' and '.join(owned)} itself; leave out {fixed!r} "
                                 f"(got {fixed}={quoted(params[fixed])})")
    return level, knob.param


def generate_at_level(spec: GeneratorSpec, seed: int, level_value: Any, params: Mapping[str, Any]) -> World:
    """A world of generator ``spec`` at the level ``level_value`` asks for (see the module), drawn with
    ``seed`` and the caller's ``params`` (which leave out what the knob sets)."""
    level, param = _check(spec, level_value, params)
    knob, name = _knob(spec), spec.name
    scale = _scale(knob, params)
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
            world = first_feasible(prepare(spec, draw_seed, {**drawn, param: n}))
        except InfeasibleError:  # too crowded to place or drive: ease off
            draws.append({"seed": draw_seed, param: n, "difficulty": None, "level": None})
            value = max(low, value - step)
            continue
        got = score(world)
        if people and got["difficulty_level"] == level:
            _progress.info("%s at level %d/%d, seed %d: draw %d landed; walking %d people", name, level, LEVELS,
                           seed, len(draws) - refused + 1, params["n_people"])
            # The same draw's attempt with its people: every earlier attempt failed static checks that never
            # read the people, so this is the world the draw's seed and params, people included, regenerate.
            with_people = attempt(prepare(spec, draw_seed, {**fixed, param: n}), world.attempts - 1, proven=world)
            if not with_people.kept or with_people.world is None:  # no timed path among them: same knob, next draw
                draws.append({"seed": draw_seed, param: n, "difficulty": None, "level": None})
                refused += 1
                continue
            world = with_people.world
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


def _scale(knob: Knob, params: Mapping[str, Any]) -> float:
    """What a per-area knob's values are multiplied by: the request's floor in units of 100 m^2 (1 otherwise)."""
    if not knob.per_area:
        return 1.0
    size = params.get("size", (10.0, 10.0))
    return float(size[0]) * float(size[1]) / 100.0 if isinstance(size, (list, tuple)) and len(size) == 2 else 1.0


def _without_people(params: Mapping[str, Any]) -> dict:
    """``params`` with every people parameter left out (a world without people refuses them), and the robot's
    motion limits too unless it has movers (only people or movers have a certificate they bound)."""
    from worldgen.params import MOTION_PARAMS, PEOPLE_PARAMS

    drop = PEOPLE_PARAMS + (() if params.get("n_movers") else MOTION_PARAMS)
    return {k: v for k, v in params.items() if k not in drop}


def _last(draws: list) -> str:
    """", the last at level K" for the progress line (", the last refused" for a draw that could not be built)."""
    if not draws:
        return ""
    return ", the last refused" if draws[-1]["level"] is None else f", the last at level {draws[-1]['level']}"


def _nearest(reached: list, level: int) -> str:
    return str(min(reached, key=lambda v: (abs(v - level), v))) if reached else "the middle"


#: Names this module held before each generator declared its own knob: where each is now (``Knob``, which
#: this module uses, is still importable from here, as worldgen.generators.Knob itself).
_MOVED = {
    "KNOBS": "each generator's spec: worldgen.generators.get(name).knob",
    "NO_LEVELS": "each generator's spec: worldgen.generators.get(name).no_levels",
    "START": "worldgen.generators.cluttered.KNOB.start",
    "STEP": "worldgen.generators.cluttered.KNOB.step",
    "MAX_KNOB": "worldgen.generators.cluttered.KNOB.high",
}


def __getattr__(name: str) -> Any:
    """The names of :data:`_MOVED`, still answered with a DeprecationWarning (the tables are read off the specs)."""
    if name not in _MOVED:
        raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
    warnings.warn(f"worldgen.leveling.{name} is deprecated: use {_MOVED[name]}", DeprecationWarning, stacklevel=2)
    if name in ("KNOBS", "NO_LEVELS"):
        specs = all_specs()
        return {s.name: s.knob for s in specs if s.knob is not None} if name == "KNOBS" else \
            {s.name: s.no_levels for s in specs if s.knob is None}
    from worldgen.generators.cluttered import KNOB
    return {"START": KNOB.start, "STEP": KNOB.step, "MAX_KNOB": KNOB.high}[name]

