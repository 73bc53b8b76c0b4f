"""How each person reacts to the robot, and the space-time tube every reaction stays in (docs/people.md).

A person's behaviour is one of :data:`BEHAVIOURS`, after HuNavSim's (robotics-upo/hunav_sim: its
README and its agent manager's behaviour trees): ``impassive`` (the robot is a thing: the person
walks its recorded trajectory whatever the robot does, as every worldgen person did before),
``regular`` (the robot is one more pedestrian in the social force model), ``surprised`` (stops when
the robot comes close, then goes on), ``scared`` (keeps away from it) and ``curious`` (walks up to it,
then goes on). :mod:`worldgen.people.react` makes them move.

Every reaction is bounded by the person's **tube**: at every time t the person is within ``d`` m of
some position its recorded trajectory (world.json ``people[].trajectory``) has at a time in
``[t - tau, t + tau]``. The timed certificate (:mod:`worldgen.people.timed`) keeps the robot clear of
the whole tube, so a robot that follows its timed path never touches a person however the person
reacts. ``impassive`` has the tube ``d = tau = 0``: the recorded line itself.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any, Mapping

import numpy as np

__all__ = ["BEHAVIOURS", "Tube", "TUBES", "behaviours_of", "tube_of", "reaction_entry", "tube_distance", "widest_tube"]

#: The behaviours, HuNavSim's names (its ``threatening``, which walks in front of the robot to block it,
#: is left out: no tube that lets a person block the robot's certified path keeps the certificate).
BEHAVIOURS = ("impassive", "regular", "surprised", "scared", "curious")


@dataclass(frozen=True)
class Tube:
    """``d`` (m): how far a person may stray from its recorded positions; ``tau`` (s): how far behind or
    ahead of its recorded time it may be."""

    d: float
    tau: float


#: Each behaviour's tube: room for what it does. regular and scared step aside (0.6 m: a person of
#: 0.25 m beside a robot of up to 0.3 m standing on its line) and may slow down for 1.5 s; surprised
#: stops (up to 2 s) and barely steps aside; curious turns to the robot (up to 0.8 m) for up to 2 s.
TUBES = {
    "impassive": Tube(0.0, 0.0),
    "regular": Tube(0.6, 1.5),
    "surprised": Tube(0.2, 2.0),
    "scared": Tube(0.6, 1.5),
    "curious": Tube(0.8, 2.0),
}


def behaviours_of(params: Mapping[str, Any]) -> list[str]:
    """Each person's behaviour: ``people_behaviour`` (comma-separated words) cycled over the ``n_people``
    people (one word: everyone's); absent (the default, impassive, is not recorded): impassive."""
    n = int(params.get("n_people") or 0)
    words = str(params.get("people_behaviour") or "impassive").split(",")
    return [words[i % len(words)] for i in range(n)]


def widest_tube(params: Mapping[str, Any]) -> float:
    """The largest ``d`` (m) of the people of ``params`` (0 where all are impassive)."""
    return max((TUBES[b].d for b in behaviours_of(params)), default=0.0)


def tube_of(behaviour: str) -> Tube:
    """The tube of ``behaviour`` (:data:`TUBES`)."""
    return TUBES[behaviour]


def reaction_entry(behaviour: str) -> dict:
    """The fields a person's world.json entry gains when it reacts: ``behaviour`` and ``tube`` {d, tau};
    none for ``impassive``, so every world made before reactions keeps its bytes."""
    if behaviour == "impassive":
        return {}
    tube = TUBES[behaviour]
    return {"behaviour": behaviour, "tube": {"d": tube.d, "tau": tube.tau}}


def tube_distance(me: np.ndarray, t: np.ndarray, track: np.ndarray, half: float) -> np.ndarray:
    """(len(t),) the exact distance from ``me[i]`` to the track's positions at times within ``half`` of
    ``t[i]`` (straight between rows, standing before the first and after the last)."""
    far = 1e9
    rows = np.vstack([[-far, *track[0, 1:]], track, [far, *track[-1, 1:]]])
    times, xy = rows[:, 0], rows[:, 1:]
    lo = np.searchsorted(times, t - half, side="right") - 1
    hi = np.searchsorted(times, t + half, side="left")
    best = np.full(len(t), np.inf)
    for k in range(int((hi - lo).max(initial=1))):
        i = np.minimum(lo + k, hi - 1)
        t0, t1 = times[i], times[i + 1]
        span = np.maximum(t1 - t0, 1e-300)
        ta, tb = np.maximum(t0, t - half), np.minimum(t1, t + half)
        a = xy[i] + ((ta - t0) / span)[:, None] * (xy[i + 1] - xy[i])
        b = xy[i] + ((tb - t0) / span)[:, None] * (xy[i + 1] - xy[i])
        ab = b - a
        u = np.clip(np.einsum("ij,ij->i", me - a, ab) / np.maximum(np.einsum("ij,ij->i", ab, ab), 1e-300), 0.0, 1.0)
        q = a + u[:, None] * ab
        best = np.minimum(best, np.hypot(me[:, 0] - q[:, 0], me[:, 1] - q[:, 1]))
    return best
