"""The difficulty score of world.json: ``metrics.difficulty`` in [0, 1] and ``metrics.difficulty_level`` 1..10.

A frozen model (:data:`MODEL`, named by :data:`MODEL_ID`) of the share of the
reference probes of the navigation environment (``worldgen.envs.probes``: the
lidar-only reactive policy and the corner-cutting tracker, default settings)
expected to fail in the world: one logistic model per probe, ``difficulty`` the
mean of their two failure chances. Its inputs are figures world.json already
holds or that follow from it (:func:`features` reads them from a world.json dict, :func:`features_from`
from the figures themselves, as a level request scores a world before any world.json is built):

- the five BARN-style figures along the reference paths (docs/metrics.md);
- ``turning``: the reference path's total turning (rad, the sum of the
  absolute heading changes between its segments), mean over tasks;
- ``sharpest_bend``: the most turning (rad) within any :data:`BEND_WINDOW` m
  of the first task's path (a corner taken tightly);
- ``passage_slack``: ``narrowest_passage`` minus the footprint's diameter (m),
  the room to spare at the tightest point (capped at :data:`SLACK_CAP`);
- ``clearance_slack``: ``closest_obstacle_distance_mean`` minus the robot's
  radius (m), the room to spare on average along the path;
- ``path_length``: the first task's reference path length (m);
- ``doors``: the share of tasks whose path needs a door leaf moved (world.json
  ``tasks[].requires_door_open``).

In a world with terrain (world.json ``terrain``; docs/terrain.md) four more inputs, of the first task's path
and of the room: ``terrain_share`` (the share of its incline profile's samples off the flat floor),
``largest_incline`` (rad) and ``largest_step`` (m) along it, and ``terrain_cover`` (the elements' area over the
room's); their terms (:data:`TERRAIN_MODEL`) are added to each probe's logit, and the score is named
:data:`TERRAIN_MODEL_ID`. A flat world's score, and its name, are the flat model's.

Per probe, ``p = sigmoid(b + sum_i w_i (g_i(f_i) - mean_i) / std_i)`` with each
``g_i`` a fixed transform (log for lengths, identity else); the level is
``min(10, 1 + floor(10 * difficulty))``. The coefficients were fitted once on
worlds from seeds the validation never uses (benchmarks/bench_difficulty.py
``--fit``) and are frozen here: a new fit is a new :data:`MODEL_ID`, so a score
always means the same thing. A world without a reference path (infeasible on
purpose) has no score (None).
"""

from __future__ import annotations

import math
from typing import Any, Mapping, Optional, Sequence

import numpy as np

__all__ = ["MODEL_ID", "MODEL", "FEATURES", "TERRAIN_MODEL_ID", "TERRAIN_MODEL", "TERRAIN_FEATURES", "SLACK_CAP",
           "BEND_WINDOW", "features", "features_from", "terrain_features", "path_turning", "sharpest_bend", "logit",
           "probe_chance", "has_terrain", "score", "level_of", "rating", "assess"]

#: The name and version of the frozen model, written as world.json ``metrics.difficulty_model``.
MODEL_ID = "worldgen.difficulty/1"
#: m: a passage wider than the footprint by more than this counts as this wide (an open room's is unbounded).
SLACK_CAP = 2.0
#: m: the stretch of path over which :func:`sharpest_bend` adds up turning.
BEND_WINDOW = 1.0
#: The model's inputs, in order, with their transform: "log" (natural log of max(value, 1e-3)) or "linear".
FEATURES: tuple[tuple[str, str], ...] = (
    ("closest_obstacle_distance_mean", "log"),
    ("average_visibility", "log"),
    ("dispersion", "linear"),
    ("characteristic_dimension", "log"),
    ("tortuosity", "log"),
    ("turning", "linear"),
    ("sharpest_bend", "linear"),
    ("passage_slack", "linear"),
    ("clearance_slack", "log"),
    ("path_length", "log"),
    ("doors", "linear"),
)
#: The name of the model a world with terrain is scored by: the flat model plus :data:`TERRAIN_MODEL`'s terms.
TERRAIN_MODEL_ID = "worldgen.difficulty/1+terrain/1"
#: The terrain inputs, in order, with their transform (as :data:`FEATURES`).
TERRAIN_FEATURES: tuple[tuple[str, str], ...] = (
    ("terrain_share", "linear"),
    ("largest_incline", "linear"),
    ("largest_step", "linear"),
    ("terrain_cover", "linear"),
)
#: The frozen coefficients, per probe: ``bias``, and per feature (in :data:`FEATURES` order) ``mean``, ``std``
#: (of the transformed feature over the fitting worlds) and ``weight``.
MODEL: dict = {
    "reactive": {
        "bias": -1.615081,
        "mean": [-0.551539, 0.655359, 3.044437, 0.678062, 0.108568, 1.222404, 0.738877, 0.510191, -1.037841, 1.865826, 0.125],
        "std": [0.39208, 0.414436, 1.332583, 0.523841, 0.139655, 1.29474, 0.606091, 0.322884, 0.59335, 0.599325, 0.330719],
        "weight": [0.213592, 0.682135, 2.052104, 1.469636, 0.711466, -0.367792,
                   1.223347, -0.719357, 0.463076, 0.488343, 2.376044],
    },
    "tracker": {
        "bias": 1.220174,
        "mean": [-0.551539, 0.655359, 3.044437, 0.678062, 0.108568, 1.222404, 0.738877, 0.510191, -1.037841, 1.865826, 0.125],
        "std": [0.39208, 0.414436, 1.332583, 0.523841, 0.139655, 1.29474, 0.606091, 0.322884, 0.59335, 0.599325, 0.330719],
        "weight": [-0.809079, 0.196711, 0.08333, 0.778586, -0.555414, 1.624086,
                   1.28988, 0.333105, -0.852249, 0.588956, -0.37402],
    },
}

#: The terrain's frozen coefficients, per probe (as :data:`MODEL`'s, over :data:`TERRAIN_FEATURES`): fitted with the
#: flat model's logit as an offset on 600 terrain worlds (benchmarks/bench_terrain_difficulty.py --fit --seeds 50).
#: The reactive probe's positive bias: its lidar does not see kerbs, potholes and a ramp's side edges below its
#: scan plane, and it drives into them (19 of its 22 failures in 40 such worlds were its chassis on the terrain).
TERRAIN_MODEL: dict = {
    "reactive": {
        "bias": 0.88973,
        "mean": [0.096181, 0.030658, 0.005281, 0.132001],
        "std": [0.163685, 0.055002, 0.006562, 0.074438],
        "weight": [-0.331336, 0.322028, 0.513393, 0.064224],
    },
    "tracker": {
        "bias": -0.389677,
        "mean": [0.096181, 0.030658, 0.005281, 0.132001],
        "std": [0.163685, 0.055002, 0.006562, 0.074438],
        "weight": [-0.372344, 0.055414, 0.037486, 0.007481],
    },
}


def _turns(waypoints) -> tuple[np.ndarray, np.ndarray]:
    """(absolute heading change at each inner vertex, arc length at that vertex) of a polyline."""
    w = np.asarray(waypoints, dtype=float).reshape(-1, 2)
    d = np.diff(w, axis=0)
    length = np.hypot(d[:, 0], d[:, 1])
    keep = length > 1e-9
    d, length = d[keep], length[keep]
    if len(d) < 2:
        return np.zeros(0), np.zeros(0)
    heading = np.arctan2(d[:, 1], d[:, 0])
    turn = np.abs((np.diff(heading) + math.pi) % (2.0 * math.pi) - math.pi)
    return turn, np.cumsum(length)[:-1]


def path_turning(waypoints) -> float:
    """Total turning (rad) of a polyline: the sum of the absolute heading changes between its segments."""
    return float(_turns(waypoints)[0].sum())


def sharpest_bend(waypoints, window: float = BEND_WINDOW) -> float:
    """The most turning (rad) at the vertices within any stretch of ``window`` m of arc length of a polyline."""
    turn, at = _turns(waypoints)
    if not len(turn):
        return 0.0
    total = np.r_[0.0, np.cumsum(turn)]
    # For each vertex i, the vertices from i up to arc length at[i] + window.
    end = np.searchsorted(at, at + window, side="right")
    return float((total[end] - total[:-1]).max())


def features(meta: Mapping) -> Optional[dict[str, float]]:
    """The model's inputs from a world.json dict (its ``metrics``, ``robot`` and ``tasks``, and in a world with
    terrain its ``terrain`` and ``bounds``); None without a path."""
    metrics, tasks = meta["metrics"], meta["tasks"]
    f = features_from(metrics, metrics.get("narrowest_passage"), float(meta["robot"]["radius"]),
                      [(t["path"]["waypoints"], t["path"]["length"]) for t in tasks if t.get("path")],
                      [bool(t.get("requires_door_open")) for t in tasks])
    if f is not None and meta.get("terrain"):
        from worldgen.scene.terrain import Terrain

        first = next((t.get("terrain") for t in tasks if t.get("path")), None)
        b = meta["bounds"]
        f.update(terrain_features(Terrain.from_canonical(meta["terrain"]["elements"]), (b["min"], b["max"]),
                                  None if first is None else first["incline_profile"],
                                  None if first is None else (first["largest_incline"], first["largest_step"])))
    return f


def terrain_features(terrain, bounds, profile, largest: Optional[tuple[float, float]]) -> dict[str, float]:
    """The terrain inputs: ``terrain`` a :class:`~worldgen.scene.terrain.Terrain`, ``bounds`` the room's
    ((x0, y0), (x1, y1)); ``profile`` the first task's incline profile (rows s, z, incline; None: no terrain
    figures) and ``largest`` its (largest incline rad, largest step m)."""
    (x0, y0), (x1, y1) = bounds
    rows = np.asarray(profile if profile is not None else np.zeros((0, 3)), dtype=float).reshape(-1, 3)
    off_floor = (rows[:, 1] != 0.0) | (rows[:, 2] != 0.0)
    incline, step = largest if largest is not None else (0.0, 0.0)
    return {"terrain_share": float(off_floor.mean()) if len(rows) else 0.0, "largest_incline": float(incline),
            "largest_step": float(step),
            "terrain_cover": sum(e.length * e.width for e in terrain.elements) / max((x1 - x0) * (y1 - y0), 1e-9)}


def features_from(figures: Mapping[str, Any], narrowest: Optional[float], radius: float,
                  paths: Sequence[tuple[Any, float]], doors: Sequence[bool]) -> Optional[dict[str, float]]:
    """The model's inputs from the figures themselves; None without a path.

    ``figures``: the five exact figures along the reference paths (:func:`worldgen.groundtruth.metrics.difficulty`,
    world.json ``metrics``); ``narrowest``: the narrowest passage (m, None for none); ``radius``: the robot's;
    ``paths``: (waypoints (n, 2), length m) of each task's reference path, tasks without one left out;
    ``doors``: per task, whether its path needs a door leaf moved.
    """
    if not paths or figures.get("tortuosity") is None:
        return None
    slack = SLACK_CAP if narrowest is None else min(float(narrowest) - 2.0 * radius, SLACK_CAP)
    out = {name: float(figures[name]) for name in ("closest_obstacle_distance_mean", "average_visibility",
                                                    "dispersion", "characteristic_dimension", "tortuosity")}
    out.update(
        turning=float(np.mean([path_turning(waypoints) for waypoints, _ in paths])),
        sharpest_bend=sharpest_bend(paths[0][0]),
        passage_slack=max(slack, 0.0),
        clearance_slack=max(out["closest_obstacle_distance_mean"] - radius, 0.0),
        path_length=float(paths[0][1]),
        doors=float(np.mean([bool(d) for d in doors])),
    )
    return out


def _vector(f: Mapping[str, float], inputs: Sequence[tuple[str, str]] = FEATURES) -> np.ndarray:
    return np.array([math.log(max(f[name], 1e-3)) if kind == "log" else float(f[name]) for name, kind in inputs])


def logit(f: Mapping[str, float], coefficients: Mapping, inputs: Sequence[tuple[str, str]] = FEATURES) -> float:
    """One probe's logit for features ``f`` under ``coefficients`` over ``inputs`` (:data:`FEATURES` or
    :data:`TERRAIN_FEATURES`)."""
    z = (_vector(f, inputs) - np.asarray(coefficients["mean"])) / np.asarray(coefficients["std"])
    return float(coefficients["bias"] + np.dot(np.asarray(coefficients["weight"]), z))


def probe_chance(f: Mapping[str, float], coefficients: Mapping, terrain: Optional[Mapping] = None) -> float:
    """One probe's logistic failure chance in [0, 1] for features ``f`` (:func:`features`); ``terrain``: the
    probe's :data:`TERRAIN_MODEL` coefficients, whose terms are added (a world with terrain)."""
    z = logit(f, coefficients) + (logit(f, terrain, TERRAIN_FEATURES) if terrain is not None else 0.0)
    return 1.0 / (1.0 + math.exp(-z)) if z > -700 else 0.0


def has_terrain(f: Mapping[str, float]) -> bool:
    """Whether features ``f`` are a terrain world's (they carry the terrain inputs)."""
    return all(name in f for name, _ in TERRAIN_FEATURES)


def score(f: Mapping[str, float], model: Optional[Mapping] = None) -> float:
    """The difficulty in [0, 1] of features ``f``: the mean failure chance of the probes of ``model`` (:data:`MODEL`),
    with :data:`TERRAIN_MODEL`'s terms where ``f`` is a terrain world's."""
    model = MODEL if model is None else model
    return float(np.mean([probe_chance(f, c, TERRAIN_MODEL[probe] if has_terrain(f) else None)
                          for probe, c in model.items()]))


def level_of(difficulty: float) -> int:
    """The level 1..10 of a difficulty in [0, 1]: ``min(10, 1 + floor(10 * difficulty))``."""
    return min(10, 1 + int(math.floor(10.0 * difficulty)))


def assess(meta: Mapping) -> dict:
    """world.json's ``metrics.difficulty``, ``difficulty_level`` and ``difficulty_model`` of a world.json dict."""
    return rating(features(meta))


def rating(f: Optional[Mapping[str, float]]) -> dict:
    """world.json's ``metrics.difficulty``, ``difficulty_level`` and ``difficulty_model`` of features ``f``
    (:func:`features`, :func:`features_from`; None: no score)."""
    if f is None:
        return {"difficulty": None, "difficulty_level": None, "difficulty_model": MODEL_ID}
    d = round(score(f), 6)  # rounded as world.json writes it, so the level is the written figure's
    return {"difficulty": d, "difficulty_level": level_of(d),
            "difficulty_model": TERRAIN_MODEL_ID if has_terrain(f) else MODEL_ID}
