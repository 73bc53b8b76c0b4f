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
- a preferred speed per person, uniform in ``person_speed``;
- with ``people_scenario`` ``head_on`` or ``crossing``, the first person instead walks the
  human-encounter scenario of that name against the first task (:func:`_scripted`).

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
           "LEG_MAX", "HEAD_ON_SHORT", "HEAD_ON_BEHIND", "CROSSING_HALF", "LAG"]

#: Height (m) of a person's cylinder in the exports, and of the slab whose obstacles they walk round.
PERSON_HEIGHT = 1.75
#: Extra distance (m) people keep from obstacles beyond their radius: far above the 6-decimal
#: rounding of the written rows, far below anything a person would notice.
SLACK = 1e-3
#: How much farther (m) than touching people keep from a robot standing at its spawn or goal: more than
#: the certificate's margin (worldgen.feasibility.timed: 0.01 m + (robot + person speed) x 0.025 s, 0.07 m
#: at 0.5 m/s) for robot speeds up to 1.7 m/s, so that a robot waiting at its spawn is in nobody's way.
KEEP_OUT = 0.1
#: The human-encounter scenarios (``people_scenario``; see :func:`_scripted`): head-on, the person
#: starts this far short of the goal (m), walks along the path to this far short of the spawn (m), then
#: round the robot to as far behind it
HEAD_ON_SHORT, HEAD_ON_BEHIND = 1.0, 1.5
#: crossing, the person walks from this far right of the path's midpoint to as far left (m)
CROSSING_HALF = 3.0
#: how far behind a steady walker (s) a person starting from rest falls: the crowd model's tau (0.5 s)
#: less one step (0.1 s) of its semi-implicit integration, which moves with the velocity just updated
LAG = 0.4
#: Straight-line length (m) of a leg between two consecutive places: at least, at most.
LEG_MIN, LEG_MAX = 2.0, 8.0
#: Most places per person (the walk ends at the last one if the duration is not over).
MAX_PLACES = 64
#: Candidate points drawn at once, and the most batches drawn for one point.
_BATCH, _ROUNDS = 512, 40
#: Unused points screened at once when looking for the next acceptable one.
_CHUNK = 64


@dataclass(frozen=True, eq=False)
class PeoplePlan:
    """What the crowd model needs: ``starts`` (n, 2), ``places`` (n, k, 2) (NaN rows end a shorter list),
    ``speeds`` (n,) m/s, ``depart`` (n,) s: when each sets off."""

    starts: np.ndarray
    places: np.ndarray
    speeds: np.ndarray
    radius: float
    duration: float
    depart: np.ndarray


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
    depart = np.zeros(n)
    scenario = params.get("people_scenario", "walk")
    if scenario != "walk":
        scripted, reason = _scripted(scenario, tasks[0], float(speeds[0]), params["robot_speed"], pool.index, clear_r,
                                     scene.bounds)
        if scripted is None:
            return None, reason
        (start, route, depart[0]) = scripted
        starts.append(start)
        places[0] = np.nan
        places[0, : len(route)] = route
    for i in range(len(starts), n):
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
    return PeoplePlan(np.array(starts).reshape(-1, 2), places, speeds, float(r), float(duration), depart), None


def _scripted(scenario: str, task: Task, speed: float, robot_speed: float, index: FootprintIndex, radius: float,
              bounds) -> tuple[Optional[tuple[np.ndarray, np.ndarray, float]], Optional[str]]:
    """((start, places (k, 2), departure time), None) of the first person in a human-encounter scenario, set
    against the first task's straight line from spawn S to goal G (u its direction, n its left normal,
    L its length); or (None, reason) when its start or place is not free floor.

    - ``head_on``: starts on the line :data:`HEAD_ON_SHORT` m short of G and walks along it toward the
      robot to :data:`HEAD_ON_BEHIND` m short of S, then round the robot's disc at S to as far behind
      it: it sets off at once.
    - ``crossing``: starts :data:`CROSSING_HALF` m to the right of the line's midpoint M and walks to as
      far to the left, across the line at right angles; it sets off so as to reach M when a robot
      driving the line at ``robot_speed`` would, ``L / 2 / robot_speed`` s (:data:`LAG`: a person starting
      from rest falls behind a steady walker by its speed times the crowd model's tau).
    """
    s = np.array([task.spawn.x, task.spawn.y])
    g = np.array([task.goal.x, task.goal.y])
    length = float(np.hypot(*(g - s)))
    u = (g - s) / length
    n = np.array([-u[1], u[0]])
    if scenario == "head_on":
        start, route, depart = g - HEAD_ON_SHORT * u, [s + HEAD_ON_BEHIND * u, s - HEAD_ON_BEHIND * u], 0.0
    else:
        mid = s + u * length / 2
        start, route = mid - CROSSING_HALF * n, [mid + CROSSING_HALF * n]
        depart = max(0.0, length / 2 / robot_speed - CROSSING_HALF / speed - LAG)
    start, route = np.round(start, 6), np.round(np.array(route), 6)
    (x0, y0), (x1, y1) = bounds
    for label, p in (("start", start), *(("place", q) for q in route)):
        inside = x0 + radius <= p[0] <= x1 - radius and y0 + radius <= p[1] <= y1 - radius
        if not inside or index.blocked(p[None], radius)[0]:
            return None, f"the {scenario} person's {label} ({p[0]:.3f}, {p[1]:.3f}) is not free floor"
    return (start, route, round(depart, 6)), None


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
            for chunk in range(0, len(rest), _CHUNK):  # in chunks: the first acceptable one is usually near
                part = rest[chunk:chunk + _CHUNK]
                ok = np.flatnonzero(accept(self.points[part]))
                if len(ok):
                    self.used[part[ok[0]]] = True
                    return self.points[part[ok[0]]]
            start = len(self.points)
            self._more()
        return None
