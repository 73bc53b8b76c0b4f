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

__all__ = ["MODEL_ID", "MODEL", "FEATURES", "SLACK_CAP", "BEND_WINDOW", "features", "features_from", "path_turning",
           "sharpest_bend", "probe_chance", "score", "level_of", "rating", "assess"]

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
    """The model's inputs from a world.json dict (its ``metrics``, ``robot`` and ``tasks``); None without a path."""
    metrics, tasks = meta["metrics"], meta["tasks"]
    return features_from(metrics, metrics.get("narrowest_passage"), float(meta["robot"]["radius"]),
                         [(t["path"]["waypoints"], t["path"]["length"]) for t in tasks if t.get("path")],
                         [bool(t.get("requires_door_open")) for t in tasks])


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


def _vector(f: Mapping[str, float]) -> np.ndarray:
    return np.array([math.log(max(f[name], 1e-3)) if kind == "log" else float(f[name]) for name, kind in FEATURES])


def probe_chance(f: Mapping[str, float], coefficients: Mapping) -> float:
    """One probe's logistic failure chance in [0, 1] for features ``f`` (:func:`features`)."""
    z = (_vector(f) - np.asarray(coefficients["mean"])) / np.asarray(coefficients["std"])
    logit = float(coefficients["bias"] + np.dot(np.asarray(coefficients["weight"]), z))
    return 1.0 / (1.0 + math.exp(-logit)) if logit > -700 else 0.0


def score(f: Mapping[str, float], model: Optional[Mapping] = None) -> float:
    """The difficulty in [0, 1] of features ``f``: the mean failure chance of the probes of ``model`` (:data:`MODEL`)."""
    model = MODEL if model is None else model
    return float(np.mean([probe_chance(f, c) for c in model.values()]))


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
    return {"difficulty": d, "difficulty_level": level_of(d), "difficulty_model": MODEL_ID}
