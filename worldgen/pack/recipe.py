"""Pack recipes: a YAML file that names every world of a pack.

A recipe is read with PyYAML's composer only (plain data, no tags constructed
beyond YAML's safe scalars), so every value keeps the line it came from and
every mistake is one line ``RECIPE:LINE: key 'K': what is wrong``::

    name: small-clutter            # optional; default: the file's stem
    formats: [sdf, mjcf, urdf]     # optional; default: sdf, mjcf, urdf (usd, osc only when listed; osc needs ros)
    sdf_version: "1.9"             # optional
    preview: false                 # optional; default false (preview.png costs ~40 ms a world)
    ros: false                     # optional; true (or a Gazebo release: fortress, harmonic, ...) adds ros2/
    seeds: 10                      # a count (0..9), {start: 100, count: 10} or {min: 0, max: 9}
    worlds:                        # one entry per generator or preset
      - generator: cluttered       # or `preset: drl_arena`
        params:
          size: [6, 6]             # a fixed value
          n_obstacles: [5, 10]     # a list is a grid axis
          box_size: [[0.3, 0.6], [0.5, 1.0]]   # for list-valued parameters, a list of lists is the axis
          clearance: {min: 0.05, max: 0.1}     # sampled per world from that world's seed
        physics:
          friction: [0.5, 1.0]     # physics variations: one more grid axis each
        seeds: {start: 0, count: 4}   # optional per entry
      - generator: cluttered       # worlds asked for at difficulty levels (worldgen.leveling)
        difficulty:
          levels: [1, 5, 10]       # levels 1..10: a list, or {min: 1, max: 10}
          worlds_per_level: 30     # request seeds 0..29 per level (or give the entry 'seeds' instead)

Jobs are ordered entry by entry, then level (an entry with ``difficulty``),
then grid point (axes by sorted name), then seed; that order, not the order
workers finish in, is the order of the manifest. A level's world is
``generate(generator, seed, difficulty=level, **params)``: its parameters must
leave out what the level sets (the knob), and every level must be one the
generator reaches (``worldgen list GENERATOR``), else the recipe is refused.
"""

from __future__ import annotations

import hashlib
import itertools
import json
import re
from dataclasses import dataclass
from pathlib import Path
from typing import Any, NoReturn, Optional

import yaml

from worldgen.errors import InfeasibleError, ParameterError, WorldgenError, did_you_mean, quoted, read_user_text
from worldgen.export.formats import ALL_FORMATS, FORMATS, SDF_VERSIONS, normalise_formats
from worldgen.floats import round_float
from worldgen.seeding import MAX_SEED, recipe_rng

__all__ = ["Job", "Recipe", "load_recipe", "parse_recipe", "TOP_KEYS", "ENTRY_KEYS", "DIFFICULTY_KEYS", "PHYSICS_PARAMS",
           "RecipeReader"]

TOP_KEYS = ("name", "formats", "sdf_version", "preview", "ros", "seeds", "worlds")
ENTRY_KEYS = ("generator", "preset", "params", "physics", "seeds", "difficulty")
#: Keys of an entry's ``difficulty`` mapping.
DIFFICULTY_KEYS = ("levels", "worlds_per_level")
#: Parameters a recipe may vary under ``physics:`` (every generator has them).
PHYSICS_PARAMS = ("friction", "step_size", "real_time_factor")
#: List-valued parameter kinds: for these a list is a value, a list of lists an axis.
_LIST_KINDS = ("pair", "triple", "range", "list")
MAX_WORLDS = 1_000_000
_NAME = re.compile(r"^[A-Za-z0-9][A-Za-z0-9_.-]{0,63}$")


class RecipeError(ParameterError):
    """A mistake in a recipe file (a ParameterError, so the CLI shows one line and exits 2)."""


@dataclass(frozen=True)
class Job:
    """One world to build: ``generate(generator, seed, **params)``; ``key`` names it for resumption."""

    index: int
    entry: int
    generator: str
    seed: int
    params: tuple  # sorted (name, value) pairs: hashable and order-free
    preset: Optional[str] = None  # the entry's preset: world.json's `preset` and the folder's name
    level: Optional[int] = None  # the difficulty level asked for (seed is then the request's seed)

    @property
    def param_dict(self) -> dict[str, Any]:
        return dict(self.params)

    @property
    def key(self) -> str:
        what = [self.generator, self.seed, self.params] + ([self.preset] if self.preset else [])
        if self.level is not None:  # appended only then, so the keys of packs without levels stay as they were
            what.append({"level": self.level})
        text = json.dumps(what, sort_keys=True, separators=(",", ":"))
        return hashlib.sha256(text.encode()).hexdigest()[:20]


@dataclass(frozen=True)
class Recipe:
    name: str
    formats: tuple[str, ...]
    sdf_version: str
    preview: bool
    jobs: tuple[Job, ...]
    document: Any  # the recipe as plain data, recorded in the manifest
    ros: Any = False  # the ROS 2 bundle: False, or the Gazebo release it is written for

    def __len__(self) -> int:
        return len(self.jobs)


def load_recipe(path) -> Recipe:
    path = Path(path)
    try:
        text = read_user_text(path, "recipe file")
    except ParameterError as exc:
        raise RecipeError(str(exc)) from None
    return parse_recipe(text, str(path), path.stem)


def parse_recipe(text: str, source: str = "<recipe>", default_name: str = "pack") -> Recipe:
    try:
        root = yaml.compose(text, Loader=yaml.SafeLoader)
    except yaml.YAMLError as exc:
        mark = getattr(exc, "problem_mark", None)
        line = f":{mark.line + 1}" if mark is not None else ""
        what = " ".join(str(getattr(exc, "problem", None) or exc).split())
        raise RecipeError(f"{source}{line}: not valid YAML: {what}") from None
    r = RecipeReader(source)
    if root is None:
        raise RecipeError(f"{source}:1: the recipe is empty; it needs at least 'worlds'")
    top = r.mapping(root, "recipe", TOP_KEYS)
    if "worlds" not in top:
        raise RecipeError(f"{source}:{root.start_mark.line + 1}: key 'worlds' is missing (a list of generator entries)")
    name = default_name
    if "name" in top:
        name = r.value(top["name"])
        if not isinstance(name, str) or not _NAME.match(name):
            r.fail(top["name"], "name", f"must be 1-64 letters, digits, '_', '.', '-', got {quoted(name)}")
    formats = FORMATS
    if "formats" in top:
        value = r.value(top["formats"])
        try:
            formats = normalise_formats(value if isinstance(value, (list, str)) else [str(value)])
        except (ParameterError, AttributeError):
            r.fail(top["formats"], "formats", f"must list formats among {', '.join(ALL_FORMATS)}, got {quoted(value)}")
    sdf_version = SDF_VERSIONS[0]
    if "sdf_version" in top:
        sdf_version = str(r.value(top["sdf_version"]))
        if sdf_version not in SDF_VERSIONS:
            r.fail(top["sdf_version"], "sdf_version", f"must be one of {', '.join(SDF_VERSIONS)}, got {quoted(sdf_version)}")
    preview = False
    if "preview" in top:
        preview = r.value(top["preview"])
        if not isinstance(preview, bool):
            r.fail(top["preview"], "preview", f"must be true or false, got {quoted(preview)}")
    ros: Any = False
    if "ros" in top:
        from worldgen.export.contract import GZ_RELEASES
        from worldgen.export.ros2 import release_of

        value = r.value(top["ros"])
        try:
            ros = value and release_of(value)
        except ParameterError:
            r.fail(top["ros"], "ros", f"must be true, false or a Gazebo release among {', '.join(GZ_RELEASES)}, "
                                      f"got {quoted(value)}")
    _osc_needs_ros(r, top, formats, ros)
    default_seeds = r.seeds(top["seeds"]) if "seeds" in top else None
    worlds = top["worlds"]
    if not isinstance(worlds, yaml.SequenceNode) or not worlds.value:
        r.fail(worlds, "worlds", "must be a non-empty list of entries (each with 'generator' or 'preset')")
    jobs: list[Job] = []
    for e, node in enumerate(worlds.value):
        preset = next((Path(str(r.value(v))).stem for k, v in node.value if k.value == "preset"), None)
        for generator, seed, params, level in r.entry(node, e, default_seeds):
            jobs.append(Job(len(jobs), e, generator, seed, params, preset, level))
            if len(jobs) > MAX_WORLDS:
                r.fail(worlds, "worlds", f"describes more than {MAX_WORLDS} worlds")
    return Recipe(name, tuple(formats), sdf_version, preview, tuple(jobs), r.value(root), ros)


def _osc_needs_ros(r, top, formats, ros) -> None:
    """world.osc's scenarios start each world's ROS 2 bundle (docs/osc.md): osc without ``ros`` is refused."""
    if "osc" in formats and not ros:
        r.fail(top["formats"], "formats", "osc writes scenarios that start each world's ROS 2 bundle: add 'ros: true'")


class RecipeReader:
    """Walks composed YAML nodes; every complaint names the key and the node's line (pack recipes, and the
    campaign recipes built on it)."""

    def __init__(self, source: str):
        self.source = source
        self._constructor = yaml.SafeLoader("")

    def fail(self, node, key: str, message: str) -> NoReturn:
        raise RecipeError(f"{self.source}:{node.start_mark.line + 1}: key '{key}': {message}")

    def value(self, node) -> Any:
        try:
            return self._constructor.construct_object(node, deep=True)
        except yaml.YAMLError as exc:  # e.g. a !!python tag: safe loading refuses it
            what = " ".join(str(getattr(exc, "problem", None) or exc).split())
            raise RecipeError(f"{self.source}:{node.start_mark.line + 1}: {what}") from None

    def mapping(self, node, what: str, allowed) -> dict[str, Any]:
        if not isinstance(node, yaml.MappingNode):
            raise RecipeError(f"{self.source}:{node.start_mark.line + 1}: {what} must be a mapping of keys")
        out: dict[str, Any] = {}
        for k, v in node.value:
            key = self.value(k)
            if not isinstance(key, str):
                raise RecipeError(f"{self.source}:{k.start_mark.line + 1}: key {quoted(key)} in {what} is not a name")
            if allowed is not None and key not in allowed:
                self.fail(k, key, f"unknown key in {what}{did_you_mean(key, allowed)}; allowed: {', '.join(allowed)}")
            if key in out:
                self.fail(k, key, f"given twice in {what}")
            out[key] = v
            out.setdefault("__keynodes__", {})[key] = k
        out.pop("__keynodes__", None)
        return out

    def seeds(self, node) -> tuple[int, ...]:
        value = self.value(node)
        if _is_int(value):
            if not 1 <= value <= MAX_WORLDS:
                self.fail(node, "seeds", f"a count must be in [1, {MAX_WORLDS}], got {value}")
            return tuple(range(value))
        if isinstance(value, dict) and set(value) in ({"start", "count"}, {"min", "max"}):
            a, b = (value["start"], value["count"]) if "start" in value else (value["min"], value["max"])
            if not (_is_int(a) and _is_int(b)):
                self.fail(node, "seeds", f"needs integers, got {quoted(value)}")
            first, count = (a, b) if "start" in value else (a, b - a + 1)
            if not (0 <= first and 1 <= count <= MAX_WORLDS and first + count - 1 <= MAX_SEED):
                self.fail(node, "seeds", f"must give 1 to {MAX_WORLDS} seeds in [0, {MAX_SEED}], got {quoted(value)}")
            return tuple(range(first, first + count))
        self.fail(node, "seeds", f"must be a count, {{start, count}} or {{min, max}}, got {quoted(value)}")

    # long: one recipe entry's keys checked in order, each with its own message
    def entry(self, node, e: int, default_seeds):
        from worldgen.generators import get

        where = f"worlds[{e}]"
        m = self.mapping(node, where, ENTRY_KEYS)
        if ("generator" in m) == ("preset" in m):
            raise RecipeError(f"{self.source}:{node.start_mark.line + 1}: {where} needs exactly one of 'generator' or 'preset'")
        base: dict[str, Any] = {}
        if "preset" in m:
            from worldgen import presets

            try:
                preset = presets.load(str(self.value(m["preset"])))
            except WorldgenError as exc:
                self.fail(m["preset"], "preset", str(exc))
            generator, base = preset.generator, dict(preset.params)
        else:
            generator = self.value(m["generator"])
            try:
                spec = get(str(generator))
            except WorldgenError as exc:
                self.fail(m["generator"], "generator", str(exc))
        spec = get(str(generator))
        kinds = {p.name: p for p in spec.all_params}
        fixed, axes, ranges, lines = dict(base), {}, {}, {}
        for group in ("params", "physics"):
            if group not in m:
                continue
            allowed = PHYSICS_PARAMS if group == "physics" else None
            for key, vnode in self.mapping(m[group], f"{where}.{group}", allowed).items():
                if key not in kinds:
                    self.fail(vnode, key, f"unknown parameter of generator '{spec.name}'{did_you_mean(key, kinds)}; "
                                          f"known: {', '.join(sorted(kinds))}")
                if key == "seed":
                    self.fail(vnode, key, "the seed is set with 'seeds'")
                if key in lines:
                    self.fail(vnode, key, "given in both params and physics")
                lines[key] = vnode
                value = self.value(vnode)
                p = kinds[key]
                if isinstance(value, dict):
                    if set(value) != {"min", "max"} or p.kind not in ("int", "float"):
                        self.fail(vnode, key, f"a mapping must be {{min, max}} on an int or float parameter, got {quoted(value)}")
                    lo, hi = value["min"], value["max"]
                    if not all(isinstance(x, (int, float)) and not isinstance(x, bool) for x in (lo, hi)) or lo > hi:
                        self.fail(vnode, key, f"needs numbers min <= max, got {quoted(value)}")
                    if p.kind == "int" and not (_is_int(lo) and _is_int(hi)):
                        self.fail(vnode, key, f"is an integer parameter; min and max must be integers, got {quoted(value)}")
                    ranges[key] = (lo, hi)
                elif isinstance(value, list) and (
                        p.kind not in _LIST_KINDS or (value and all(isinstance(v, list) for v in value))):
                    if not value:
                        self.fail(vnode, key, "a grid axis needs at least one value")
                    axes[key] = value
                else:
                    fixed[key] = value
        seeds = self.seeds(m["seeds"]) if "seeds" in m else default_seeds
        levels: tuple = (None,)
        if "difficulty" in m:
            levels, per_level = self.difficulty(m["difficulty"], "seeds" in m)
            seeds = tuple(range(per_level)) if per_level is not None else seeds
        if seeds is None:
            raise RecipeError(f"{self.source}:{node.start_mark.line + 1}: {where} has no 'seeds' (give them here or at the top)")
        names = sorted(axes)
        for level in levels:
            for point in itertools.product(*(axes[n] for n in names)):
                grid = dict(fixed, **dict(zip(names, point)))
                # Check the grid point at both ends of every sampled range, before any world is built.
                for end in (0, 1):
                    trial = dict(grid, **{k: v[end] for k, v in ranges.items()})
                    self._check(spec, trial, lines, m, node)
                    if level is not None:
                        self._check_level(spec.name, level, trial, m["difficulty"])
                for seed in seeds:
                    params = dict(grid)
                    for k in sorted(ranges):
                        params[k] = _sample(kinds[k].kind, ranges[k], seed, e, k)
                    yield spec.name, seed, tuple(sorted((k, _freeze(v)) for k, v in params.items())), level

    def difficulty(self, node, has_seeds: bool) -> tuple[tuple[int, ...], Optional[int]]:
        """(levels, worlds per level or None) of an entry's ``difficulty`` mapping."""
        m = self.mapping(node, "difficulty", DIFFICULTY_KEYS)
        if "levels" not in m:
            self.fail(node, "difficulty", "needs 'levels': a list of levels 1..10 or {min, max}")
        value = self.value(m["levels"])
        if isinstance(value, dict) and set(value) == {"min", "max"} and _is_int(value["min"]) and _is_int(value["max"]):
            value = list(range(value["min"], value["max"] + 1))
        if not (isinstance(value, list) and value and all(_is_int(v) and 1 <= v <= 10 for v in value)
                and len(set(value)) == len(value)):
            self.fail(m["levels"], "levels", f"must be distinct levels 1..10 as a list or {{min, max}}, got {quoted(value)}")
        per_level = None
        if "worlds_per_level" in m:
            per_level = self.value(m["worlds_per_level"])
            if has_seeds:
                self.fail(m["worlds_per_level"], "worlds_per_level", "the entry gives 'seeds' too; give one or the other")
            if not (_is_int(per_level) and 1 <= per_level <= MAX_WORLDS):
                self.fail(m["worlds_per_level"], "worlds_per_level", f"must be an integer in [1, {MAX_WORLDS}], "
                                                                     f"got {quoted(per_level)}")
        return tuple(value), per_level

    def _check_level(self, generator: str, level: int, params, node) -> None:
        from worldgen.leveling import check_request

        try:
            check_request(generator, level, params)
        except ParameterError as exc:
            raise RecipeError(f"{self.source}:{node.start_mark.line + 1}: key 'difficulty': {exc}") from None

    def _check(self, spec, params, lines, m, node) -> None:
        try:
            spec.resolve(params)
        except (ParameterError, InfeasibleError) as exc:
            found = re.search(r"parameter '(\w+)'", str(exc))
            at = lines.get(found.group(1)) if found else None
            at = at or m.get("params") or node
            key = found.group(1) if found else spec.name
            raise RecipeError(f"{self.source}:{at.start_mark.line + 1}: key '{key}': {exc}") from None


def _sample(kind: str, bounds, seed: int, entry: int, name: str):
    """A value in ``bounds`` drawn from the world's own stream: seed, entry and parameter name."""
    rng = recipe_rng(seed, entry, name)
    lo, hi = bounds
    if kind == "int":
        return int(rng.integers(lo, hi, endpoint=True))
    return round_float(float(lo) + (float(hi) - float(lo)) * float(rng.random()))


def _freeze(value):
    return tuple(_freeze(v) for v in value) if isinstance(value, list) else value


def _is_int(x) -> bool:
    return isinstance(x, int) and not isinstance(x, bool)
