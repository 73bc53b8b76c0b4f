"""People: where pedestrians start, the places they walk to, and how fast they like to walk.

Any generator gets them through the common parameters ``n_people``, ``person_radius``,
``person_speed`` and ``people_duration`` (docs/people.md). This module only draws, from the
people's own RNG stream (:func:`worldgen.seeding.people_rng`), so adding people never moves an
obstacle, a task or a mover:

- a start per person: free floor for the person's disc, at least ``2 x radius`` from every other
  start, and :data:`KEEP_OUT` off the robot's spawn and goal discs;
- a list of places per person, each leg between consecutive places between :data:`LEG_MIN` and
  :data:`LEG_MAX` metres long (straight-line), enough of them to keep walking for the whole
  duration at the fastest speed;
- a preferred speed per person, uniform in ``person_speed``.

Walking between the places, around the obstacles and each other, is the crowd model's
(:mod:`worldgen.feasibility.crowd`); the robot's spawn and goal discs are obstacles to it too
(:func:`people_footprints`), so nobody walks over a robot standing there.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any, Mapping, Optional, Sequence

import numpy as np

from worldgen.scene import Robot, Scene, Task
from worldgen.scene.footprint import Footprint, FootprintIndex, scene_footprints

__all__ = ["PeoplePlan", "draw_people", "people_footprints", "PERSON_HEIGHT", "SLACK", "KEEP_OUT", "LEG_MIN",
           "LEG_MAX"]

#: Height (m) of a person's cylinder in the exports, and of the slab whose obstacles they walk round.
PERSON_HEIGHT = 1.75
#: Extra distance (m) people keep from obstacles beyond their radius: far above the 6-decimal
#: rounding of the written rows, far below anything a person would notice.
SLACK = 1e-3
#: How much farther (m) than touching people keep from a robot standing at its spawn or goal: more than
#: the certificate's margin (worldgen.feasibility.timed: 0.01 m + (robot + person speed) x 0.025 s, 0.07 m
#: at 0.5 m/s) for robot speeds up to 1.7 m/s, so that a robot waiting at its spawn is in nobody's way.
KEEP_OUT = 0.1
#: Straight-line length (m) of a leg between two consecutive places: at least, at most.
LEG_MIN, LEG_MAX = 2.0, 8.0
#: Most places per person (the walk ends at the last one if the duration is not over).
MAX_PLACES = 64
#: Candidate points drawn at once, and the most batches drawn for one point.
_BATCH, _ROUNDS = 512, 40


@dataclass(frozen=True, eq=False)
class PeoplePlan:
    """What the crowd model needs: ``starts`` (n, 2), ``places`` (n, k, 2), ``speeds`` (n,) m/s."""

    starts: np.ndarray
    places: np.ndarray
    speeds: np.ndarray
    radius: float
    duration: float


def people_footprints(scene: Scene, tasks: Sequence[Task], robot: Robot) -> list[Footprint]:
    """What people walk round: every collider's floor shadow below :data:`PERSON_HEIGHT`, and a disc of
    radius ``robot.inflation + KEEP_OUT`` at every task's spawn and goal."""
    prints = scene_footprints(scene, PERSON_HEIGHT)
    keep_out = [Footprint(f"{task.id}_{which}", "keep_out", centre=(p.x, p.y),
                          radius=robot.inflation + KEEP_OUT)
                for task in tasks for which, p in (("spawn", task.spawn), ("goal", task.goal))]
    return prints + keep_out


def draw_people(scene: Scene, tasks: Sequence[Task], robot: Robot, params: Mapping[str, Any],
                rng: np.random.Generator) -> tuple[Optional[PeoplePlan], Optional[str]]:
    """(plan, None) for ``params['n_people']`` people, or (None, reason) when they do not fit."""
    n, r = params["n_people"], params["person_radius"]
    lo, hi = params["person_speed"]
    duration = params["people_duration"]
    clear_r = r + 2 * SLACK
    (x0, y0), (x1, y1) = scene.bounds
    if x1 - x0 <= 2 * clear_r or y1 - y0 <= 2 * clear_r:
        return None, f"the floor is too small for people of radius {r:g} m"
    pool = _Pool(rng, FootprintIndex(people_footprints(scene, tasks, robot)), scene.bounds, clear_r)
    speeds = np.round(rng.uniform(lo, hi, n), 6)
    k = min(MAX_PLACES, math.ceil(duration * hi * 1.3 / LEG_MIN) + 1)
    starts: list[np.ndarray] = []
    places = np.zeros((n, k, 2))
    for i in range(n):
        start = pool.take(lambda q: np.all(np.hypot(*(q[:, None] - np.array(starts).reshape(1, -1, 2)).transpose(
            2, 0, 1)) >= 2 * r + SLACK, axis=1))
        if start is None:
            return None, f"could not place {n} people of radius {r:g} m on free floor (placed {i})"
        starts.append(start)
        last = start
        for j in range(k):
            nxt = pool.take(lambda q, last=last: (np.hypot(*(q - last).T) >= LEG_MIN) & (np.hypot(*(q - last).T) <= LEG_MAX))
            if nxt is None:
                return None, f"could not find places {LEG_MIN:g}-{LEG_MAX:g} m apart for a person of radius {r:g} m"
            places[i, j] = last = nxt
    return PeoplePlan(np.array(starts).reshape(-1, 2), places, speeds, float(r), float(duration)), None


class _Pool:
    """Free points (6 decimals) for a disc of ``radius``, drawn and screened in large batches and handed
    out in the order drawn: :meth:`take` gives the next one ``accept`` takes, passing over the others."""

    def __init__(self, rng, index: FootprintIndex, bounds, radius: float):
        self.rng, self.index, self.bounds, self.radius = rng, index, bounds, radius
        self.points = np.zeros((0, 2))
        self.used = np.zeros(0, dtype=bool)

    def _more(self) -> None:
        (x0, y0), (x1, y1) = self.bounds
        r = self.radius
        xy = np.round(np.column_stack([self.rng.uniform(x0 + r, x1 - r, _BATCH),
                                       self.rng.uniform(y0 + r, y1 - r, _BATCH)]), 6)
        xy = xy[~self.index.blocked(xy, r)]
        self.points = np.vstack([self.points, xy])
        self.used = np.r_[self.used, np.zeros(len(xy), dtype=bool)]

    def take(self, accept) -> Optional[np.ndarray]:
        """The first unused point that ``accept`` ((m, 2) points -> (m,) bool) takes, drawing more as needed."""
        start = 0
        for _ in range(_ROUNDS):
            rest = np.flatnonzero(~self.used[start:]) + start
            if len(rest):
                ok = np.flatnonzero(accept(self.points[rest]))
                if len(ok):
                    self.used[rest[ok[0]]] = True
                    return self.points[rest[ok[0]]]
            start = len(self.points)
            self._more()
        return None
