"""A point of a campaign's space: what the strategy chose, turned into worldgen's generation and back into descriptors.

A strategy asks through an object with Optuna's trial interface (``suggest_categorical``, ``suggest_int``,
``suggest_float``); :func:`suggest` names every dimension (``entry``, then ``e<entry>.level`` and
``e<entry>.<parameter>``; a list of choices is chosen by its index) and :func:`point_of` turns the answers into
a :class:`Point`. The world's seed is not a dimension: it is point ``k``'s own (:func:`worldgen.seeding.campaign_seeds`),
so the search decides where in the space to look and the seed how that place is drawn.

A point whose world does not exist (the generator refuses the combination, or finds no feasible draw) is
recorded with the refusal's line and never counted as a run of the robot.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any, Mapping, Optional, Sequence

from worldgen.campaign.recipe import Entry, without_idle_people
from worldgen.errors import InfeasibleError, ParameterError

__all__ = ["Point", "suggest", "point_of", "make_world", "descriptors", "cell", "DESCRIPTORS", "PASSAGE_BIN"]

#: The descriptors of a point's world, in the failure map's and the coverage's order.
DESCRIPTORS = ("generator", "level", "people", "door_state", "robot_radius", "narrowest_passage", "obstacles")
#: Width (m) of a narrowest-passage bin in a coverage cell.
PASSAGE_BIN = 0.25


@dataclass(frozen=True)
class Point:
    """One place of the space: ``generate(generator, seed, difficulty=level, **params)``."""

    index: int
    entry: int
    generator: str
    preset: Optional[str]
    level: Optional[int]
    params: tuple  # sorted (name, value) pairs: the entry's fixed values and the strategy's choices
    seed: int

    @property
    def param_dict(self) -> dict[str, Any]:
        return {k: (list(v) if isinstance(v, tuple) else v) for k, v in self.params}

    def as_dict(self) -> dict[str, Any]:
        return {"index": self.index, "entry": self.entry, "generator": self.generator, "preset": self.preset,
                "level": self.level, "params": self.param_dict, "seed": self.seed}

    @classmethod
    def from_dict(cls, d: Mapping[str, Any]) -> "Point":
        params = tuple(sorted((k, _freeze(v)) for k, v in d["params"].items()))
        return cls(d["index"], d["entry"], d["generator"], d.get("preset"), d.get("level"), params, d["seed"])


def suggest(trial, entries: Sequence[Entry]) -> dict[str, Any]:
    """Ask ``trial`` (Optuna's trial interface) for every dimension of the space; returns name -> answer."""
    e = trial.suggest_categorical("entry", list(range(len(entries)))) if len(entries) > 1 else 0
    entry = entries[e]
    out: dict[str, Any] = {"entry": e}
    if len(entry.levels) > 1:
        lo, hi = min(entry.levels), max(entry.levels)
        name = f"e{e}.level"
        contiguous = sorted(entry.levels) == list(range(lo, hi + 1))
        out[name] = trial.suggest_int(name, lo, hi) if contiguous else trial.suggest_categorical(name, sorted(entry.levels))
    for key, values in entry.choices:
        if len(values) > 1:
            out[f"e{e}.{key}"] = trial.suggest_categorical(f"e{e}.{key}", list(range(len(values))))
    for key, r in entry.ranges:
        name = f"e{e}.{key}"
        if r.low == r.high:
            continue
        out[name] = trial.suggest_int(name, int(r.low), int(r.high)) if r.integer else \
            trial.suggest_float(name, float(r.low), float(r.high))
    return out


def point_of(entries: Sequence[Entry], answers: Mapping[str, Any], index: int, seed: int) -> Point:
    """The point ``answers`` (from :func:`suggest`) name, with the world seed ``seed``."""
    e = int(answers.get("entry", 0))
    entry = entries[e]
    params = dict(entry.fixed)
    for key, values in entry.choices:
        params[key] = values[int(answers.get(f"e{e}.{key}", 0))]
    for key, r in entry.ranges:
        value = answers.get(f"e{e}.{key}", r.low)
        params[key] = int(value) if r.integer else round(float(value), 6)
    level = int(answers.get(f"e{e}.level", entry.levels[0])) if entry.levels else None
    return Point(index, e, entry.generator, entry.preset, level, tuple(sorted(without_idle_people(params).items())), seed)


def make_world(point: Point):
    """(World, "") for ``point``, or (None, the refusal's line) when no such world exists."""
    from worldgen.api import generate

    try:
        world = generate(point.generator, point.seed, difficulty=None if point.level is None else f"{point.level}/10",
                         **point.param_dict)
    except (InfeasibleError, ParameterError) as exc:
        return None, " ".join(str(exc).split())
    return world, ""


def descriptors(point: Point, meta: Optional[Mapping[str, Any]]) -> dict[str, Any]:
    """What the failure map and the coverage read of a point: from its world's world.json where it has one."""
    params = dict((meta or {}).get("params") or point.param_dict)
    metrics = (meta or {}).get("metrics") or {}
    level = point.level if point.level is not None else metrics.get("difficulty_level")
    passage = metrics.get("narrowest_passage")
    return {
        "generator": point.preset or point.generator,
        "level": level,
        "people": int(params.get("n_people") or 0),
        "door_state": str(params["state"]) if "state" in params else "none",
        "robot_radius": params.get("robot_radius"),
        "narrowest_passage": passage if isinstance(passage, (int, float)) and math.isfinite(passage) else None,
        "obstacles": metrics.get("obstacle_count"),
    }


def cell(desc: Mapping[str, Any]) -> tuple:
    """The coverage cell of a point's descriptors: generator, level, people, door state, narrowest passage bin."""
    passage = desc.get("narrowest_passage")
    band = None if passage is None else int(passage // PASSAGE_BIN)
    return (desc.get("generator"), desc.get("level"), desc.get("people"), desc.get("door_state"), band)


def _freeze(value):
    return tuple(_freeze(v) for v in value) if isinstance(value, list) else value
