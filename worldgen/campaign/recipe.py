"""Campaign recipes: a YAML file that names the space to search, the system under test, the budget and the strategy.

Read as pack recipes are (:mod:`worldgen.pack.recipe`: PyYAML's safe composer, every mistake one line
``RECIPE:LINE: key 'K': what is wrong``, a :class:`~worldgen.errors.ParameterError`, exit status 2)::

    name: gap-heuristic            # optional; default: the file's stem
    space:                         # one entry per generator or preset, as a pack recipe's `worlds:`
      - generator: cluttered       # or `preset: drl_arena`
        params:
          size: [6, 6]             # a fixed value
          n_people: {min: 0, max: 2}          # a range the search draws within (int or float parameters)
          people_behaviour: [impassive, scared]   # a list: the choices (list-valued parameters: a list of lists)
          robot_radius: {min: 0.15, max: 0.3}
        difficulty: {levels: {min: 1, max: 10}}   # the levels the search may ask for (worldgen.leveling)
    system: {drive: {sim: mujoco}}  # passed to worldgen.campaign.systems.system_from_spec
    verdict: criteria.yaml         # optional: a criteria file as `worldgen judge` reads it (relative to the recipe)
    budget: {runs: 200, seconds: 3600}    # at least one of them
    strategy: {name: adaptive, seed: 0}   # random | adaptive | coverage; seed default 0

People, door states and robot sizes are parameters like any other (``n_people``, ``people_behaviour``,
``people_scenario``, the door generator's ``state``, ``robot_radius``), so the space holds them the same
way. Every choice and both ends of every range are checked against the generator when the recipe is read,
and every level against what the generator reaches.
"""

from __future__ import annotations

import hashlib
import json
from dataclasses import dataclass
from pathlib import Path
from typing import Any, Mapping, Optional

import yaml

from worldgen.errors import ParameterError, WorldgenError, did_you_mean, quoted, read_user_text
from worldgen.pack.recipe import _NAME, PHYSICS_PARAMS, RecipeError, RecipeReader
from worldgen.seeding import check_seed

__all__ = ["CampaignRecipe", "Entry", "Range", "load_campaign", "parse_campaign", "identity_of", "without_idle_people",
           "TOP_KEYS", "ENTRY_KEYS", "BUDGET_KEYS", "STRATEGY_KEYS", "STRATEGIES", "MAX_RUNS"]

TOP_KEYS = ("name", "space", "system", "verdict", "budget", "strategy")
ENTRY_KEYS = ("generator", "preset", "params", "physics", "difficulty")
BUDGET_KEYS = ("runs", "seconds")
STRATEGY_KEYS = ("name", "seed")
#: The strategies (worldgen.campaign.strategies): uniform sampling, Optuna's TPE, TPE rewarded for new cells.
STRATEGIES = ("random", "adaptive", "coverage")
MAX_RUNS = 1_000_000
_LIST_KINDS = ("pair", "triple", "range", "list")


@dataclass(frozen=True)
class Range:
    """A parameter the search draws within [low, high]; ``integer`` for an int parameter."""

    low: float
    high: float
    integer: bool


@dataclass(frozen=True)
class Entry:
    """One generator (or preset) of the space: what is fixed, what is chosen among, what is drawn in a range."""

    generator: str
    preset: Optional[str]
    fixed: tuple  # sorted (name, value) pairs
    choices: tuple  # sorted (name, (value, ...)) pairs
    ranges: tuple  # sorted (name, Range) pairs
    levels: tuple[int, ...]  # the levels asked for; () for plain generation


@dataclass(frozen=True)
class CampaignRecipe:
    name: str
    entries: tuple[Entry, ...]
    system: Optional[Mapping[str, Any]]  # the `system:` block, None when the caller gives a System itself
    verdict: Any  # a criteria file's path, or None: the default verdict
    runs: Optional[int]
    seconds: Optional[float]
    strategy: str
    seed: int
    document: Any  # the recipe as plain data

    @property
    def identity(self) -> str:
        """What makes two recipes the same campaign: everything but the budget (a rerun may extend it)."""
        return identity_of(self.document)


def identity_of(document: Any) -> str:
    """A campaign recipe's identity (plain data as read): everything but its budget, hashed."""
    doc = {k: v for k, v in document.items() if k != "budget"} if isinstance(document, dict) else document
    text = json.dumps(doc, sort_keys=True, separators=(",", ":"), default=str)
    return hashlib.sha256(text.encode()).hexdigest()[:20]


def load_campaign(path) -> CampaignRecipe:
    path = Path(path)
    try:
        text = read_user_text(path, "campaign recipe")
    except ParameterError as exc:
        raise RecipeError(str(exc)) from None
    return parse_campaign(text, str(path), path.stem, base=path.parent)


def parse_campaign(text: str, source: str = "<campaign>", default_name: str = "campaign", base=None) -> CampaignRecipe:
    """The campaign of ``text``; ``base`` is the folder a relative ``verdict`` path is read from."""
    try:
        root = yaml.compose(text, Loader=yaml.SafeLoader)
    except yaml.YAMLError as exc:
        mark = getattr(exc, "problem_mark", None)
        line = f":{mark.line + 1}" if mark is not None else ""
        raise RecipeError(f"{source}{line}: not valid YAML: {' '.join(str(getattr(exc, 'problem', None) or exc).split())}") \
            from None
    if root is None:
        raise RecipeError(f"{source}:1: the campaign recipe is empty; it needs 'space' and 'budget'")
    r = _Reader(source)
    top = r.mapping(root, "campaign recipe", TOP_KEYS)
    for key in ("space", "budget"):
        if key not in top:
            raise RecipeError(f"{source}:{root.start_mark.line + 1}: key '{key}' is missing")
    name = r.value(top["name"]) if "name" in top else default_name
    if not isinstance(name, str) or not _NAME.match(name):
        r.fail(top.get("name", root), "name", f"must be 1-64 letters, digits, '_', '.', '-', got {quoted(name)}")
    space = top["space"]
    if not isinstance(space, yaml.SequenceNode) or not space.value:
        r.fail(space, "space", "must be a non-empty list of entries (each with 'generator' or 'preset')")
    entries = tuple(r.space_entry(node, e) for e, node in enumerate(space.value))
    system = None
    if "system" in top:
        system = r.value(top["system"])
        if not isinstance(system, dict) or not system:
            r.fail(top["system"], "system", f"must be a mapping naming one system under test, got {quoted(system)}")
    verdict = None
    if "verdict" in top:
        verdict = r.verdict(top["verdict"], base)
    runs, seconds = r.budget(top["budget"])
    strategy, seed = r.strategy(top["strategy"]) if "strategy" in top else ("random", 0)
    return CampaignRecipe(name, entries, system, verdict, runs, seconds, strategy, seed, r.value(root))


class _Reader(RecipeReader):
    """The pack recipe's reader (mapping, value, fail, difficulty, _check, _check_level) with the campaign's keys."""

    # long: one space entry's keys checked in order, each with its own message (as a pack entry's)
    def space_entry(self, node, e: int) -> Entry:
        from worldgen.generators import get

        where = f"space[{e}]"
        m = self.mapping(node, where, ENTRY_KEYS)
        if ("generator" in m) == ("preset" in m):
            raise RecipeError(f"{self.source}:{node.start_mark.line + 1}: {where} needs exactly one of 'generator' or 'preset'")
        base: dict[str, Any] = {}
        preset = None
        if "preset" in m:
            from worldgen import presets

            try:
                loaded = presets.load(str(self.value(m["preset"])))
            except WorldgenError as exc:
                self.fail(m["preset"], "preset", str(exc))
            generator, base, preset = loaded.generator, dict(loaded.params), Path(str(self.value(m["preset"]))).stem
        else:
            generator = self.value(m["generator"])
            try:
                get(str(generator))
            except WorldgenError as exc:
                self.fail(m["generator"], "generator", str(exc))
        spec = get(str(generator))
        kinds = {p.name: p for p in spec.all_params}
        fixed, choices, ranges, lines = dict(base), {}, {}, {}
        for group in ("params", "physics"):
            if group not in m:
                continue
            allowed = PHYSICS_PARAMS if group == "physics" else None
            for key, vnode in self.mapping(m[group], f"{where}.{group}", allowed).items():
                if key == "seed":
                    self.fail(vnode, key, "the campaign draws every world's seed from the strategy's seed")
                if key not in kinds:
                    self.fail(vnode, key, f"unknown parameter of generator '{spec.name}'{did_you_mean(key, kinds)}; "
                                          f"known: {', '.join(sorted(kinds))}")
                if key in lines:
                    self.fail(vnode, key, "given in both params and physics")
                lines[key] = vnode
                value, p = self.value(vnode), kinds[key]
                if isinstance(value, dict):
                    ranges[key] = self.range(vnode, key, value, p.kind)
                elif isinstance(value, list) and (
                        p.kind not in _LIST_KINDS or (value and all(isinstance(v, list) for v in value))):
                    if not value:
                        self.fail(vnode, key, "a list of choices needs at least one value")
                    choices[key] = tuple(_freeze(v) for v in value)
                else:
                    fixed[key] = _freeze(value)
        levels: tuple[int, ...] = ()
        if "difficulty" in m:
            self.mapping(m["difficulty"], "difficulty", ("levels",))  # a level's worlds are the search's to choose
            levels, _ = self.difficulty(m["difficulty"], False)
        # Every choice and both ends of every range, each beside the others' first values, at every level.
        first = dict(fixed, **{k: v[0] for k, v in choices.items()}, **{k: _end(r, 0) for k, r in ranges.items()})
        trials = [first] + [dict(first, **{k: v}) for k, vs in choices.items() for v in vs[1:]] + \
            [dict(first, **{k: _end(r, 1)}) for k, r in ranges.items()]
        for trial in map(without_idle_people, trials):
            self._check(spec, trial, lines, m, node)
            for level in levels:
                self._check_level(spec.name, level, trial, m["difficulty"])
        return Entry(spec.name, preset, tuple(sorted(fixed.items())), tuple(sorted(choices.items())),
                     tuple(sorted(ranges.items())), tuple(levels))

    def range(self, vnode, key: str, value: dict, kind: str) -> Range:
        if set(value) != {"min", "max"} or kind not in ("int", "float"):
            self.fail(vnode, key, f"a mapping must be {{min, max}} on an int or float parameter, got {quoted(value)}")
        lo, hi = value["min"], value["max"]
        if not all(isinstance(x, (int, float)) and not isinstance(x, bool) for x in (lo, hi)):
            self.fail(vnode, key, f"needs numbers min <= max, got {quoted(value)}")
        if lo > hi:
            self.fail(vnode, key, f"is an empty range: min {lo} > max {hi}")
        if kind == "int" and not all(isinstance(x, int) for x in (lo, hi)):
            self.fail(vnode, key, f"is an integer parameter; min and max must be integers, got {quoted(value)}")
        return Range(lo, hi, kind == "int")

    def verdict(self, node, base) -> Any:
        value = self.value(node)
        if value is None:
            return None
        if not isinstance(value, str):
            self.fail(node, "verdict", f"must be the path of a criteria file (as `worldgen judge --criteria`), "
                                       f"got {quoted(value)}")
        path = Path(value) if base is None or Path(value).is_absolute() else Path(base) / value
        from worldgen.judge.criteria import load_criteria

        try:
            load_criteria(path)
        except WorldgenError as exc:
            self.fail(node, "verdict", str(exc))
        return str(path)

    def budget(self, node) -> tuple[Optional[int], Optional[float]]:
        m = self.mapping(node, "budget", BUDGET_KEYS)
        if not m:
            self.fail(node, "budget", "needs 'runs', 'seconds' or both")
        runs = self.value(m["runs"]) if "runs" in m else None
        if runs is not None and not (isinstance(runs, int) and not isinstance(runs, bool) and 1 <= runs <= MAX_RUNS):
            self.fail(m["runs"], "runs", f"must be an integer in [1, {MAX_RUNS}], got {quoted(runs)}")
        seconds = self.value(m["seconds"]) if "seconds" in m else None
        if seconds is not None and not (isinstance(seconds, (int, float)) and not isinstance(seconds, bool) and seconds > 0):
            self.fail(m["seconds"], "seconds", f"must be a number of seconds > 0, got {quoted(seconds)}")
        return runs, (float(seconds) if seconds is not None else None)

    def strategy(self, node) -> tuple[str, int]:
        m = self.mapping(node, "strategy", STRATEGY_KEYS)
        name = self.value(m["name"]) if "name" in m else "random"
        if name not in STRATEGIES:
            self.fail(m.get("name", node), "name", f"must be one of {', '.join(STRATEGIES)}, got {quoted(name)}")
        seed = self.value(m["seed"]) if "seed" in m else 0
        try:
            seed = check_seed(seed, "the strategy's seed")
        except ParameterError as exc:
            self.fail(m["seed"], "seed", str(exc))
        return name, seed


def without_idle_people(params: Mapping[str, Any]) -> dict[str, Any]:
    """``params`` without the people's parameters when they ask for no people: a space may draw ``n_people`` 0
    beside a people behaviour, and the generator refuses people's parameters without people."""
    from worldgen.params import MOTION_PARAMS, PEOPLE_PARAMS

    if params.get("n_people"):
        return dict(params)
    drop = PEOPLE_PARAMS + (() if params.get("n_movers") else MOTION_PARAMS)
    return {k: v for k, v in params.items() if k not in drop or k == "n_people"}


def _end(r: Range, end: int):
    return r.high if end else r.low


def _freeze(value):
    return tuple(_freeze(v) for v in value) if isinstance(value, list) else value
