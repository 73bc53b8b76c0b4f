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
- with ``group_size`` G > 1, people walk in groups of G (consecutive people; the last may be
  smaller): a group shares its speed and its places (each member's place beside the group's, side by
  side across the leg, :data:`GROUP_SPACING` apart where the floor is free), and its members start
  within :data:`GROUP_START` of the first one; the crowd model holds them together
  (:func:`worldgen.people.crowd.group_force`);
- with ``people_scenario`` other than ``walk``, the first person (``group_passing``: the first G)
  instead walks the human-encounter scenario of that name against the first task (:func:`_scripted`).

Walking between the places, around the obstacles and each other, is the crowd model's
(:mod:`worldgen.people.crowd`); the robot's spawn and goal discs are obstacles to it too
(:func:`people_footprints`), so nobody walks over a robot standing there.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any, Mapping, Optional, Sequence

import numpy as np

from worldgen.errors import ParameterError
from worldgen.people.behaviours import widest_tube
from worldgen.scene import Robot, Scene, Task
from worldgen.scene.doors import door_records
from worldgen.scene.footprint import Footprint, FootprintIndex, scene_footprints

__all__ = ["PeoplePlan", "draw_people", "group_ids", "people_footprints", "PERSON_HEIGHT", "SLACK", "KEEP_OUT", "LEG_MIN",
           "LEG_MAX", "HEAD_ON_SHORT", "HEAD_ON_BEHIND", "HEAD_ON_STEP", "HEAD_ON_ARC", "CROSSING_HALF", "LAG",
           "GROUP_SPACING", "GROUP_START",
           "OVERTAKE_BEHIND", "OVERTAKE_SIDE", "OVERTAKE_BEYOND", "GROUP_SHORT", "GROUP_SIDE", "GROUP_BEHIND", "DOOR_WAIT",
           "ASIDE_AHEAD", "ASIDE_SIDE"]

#: Height (m) of a person's cylinder in the exports, and of the slab whose obstacles they walk round.
PERSON_HEIGHT = 1.75
#: Extra distance (m) people keep from obstacles beyond their radius: far above the 6-decimal
#: rounding of the written rows, far below anything a person would notice.
SLACK = 1e-3
#: How much farther (m) than touching people keep from a robot standing at its spawn or goal: more than
#: the certificate's margin (worldgen.people.timed: 0.01 m + the 0.03 m tracking margin + (robot + person
#: speed) x 0.025 s, 0.0875 m at 0.5 and 1.4 m/s) while the two speeds add up to less than 2.4 m/s, so
#: that a robot waiting at its spawn is in nobody's way.
KEEP_OUT = 0.1
#: The human-encounter scenarios (``people_scenario``; see :func:`_scripted`): head-on, the person
#: starts this far short of the goal (m), walks along the path to this far short of the spawn (m), then
#: round the robot to as far behind it
HEAD_ON_SHORT, HEAD_ON_BEHIND = 1.0, 1.5
#: head-on, where a reacting person's tube keeps it off HEAD_ON_SHORT: the start moves back in steps of (m)
HEAD_ON_STEP = 0.05
#: head-on, the arc round the robot is walked in steps of this many degrees (every chord within 1.5 %
#: of the arc's radius)
HEAD_ON_ARC = 20.0
#: crossing, the person walks from this far right of the path's midpoint to as far left (m)
CROSSING_HALF = 3.0
#: how far behind a steady walker (s) a person starting from rest falls: the crowd model's tau (0.5 s)
#: less one step (0.1 s) of its semi-implicit integration, which moves with the velocity just updated
LAG = 0.4
#: overtaking, the person starts this far behind the spawn (m), this far to the left of the path's line
#: (m), and walks parallel to it to as far beyond the goal as it started behind the spawn
OVERTAKE_BEHIND, OVERTAKE_SIDE, OVERTAKE_BEYOND = 2.0, 1.0, 2.0
#: group_passing, the group starts abreast this far short of the goal (m), its centre this far to the left
#: of the path's line (m: its own lane, so the robot can keep to its path), and walks to as far behind
#: the spawn (m), in the same formation
GROUP_SHORT, GROUP_SIDE, GROUP_BEHIND = 1.0, 2.0, 1.0
#: doorway, the person stands in the first door's doorway for this long (s), then steps aside to this far
#: ahead (m, along the robot's line) and as far to the right of the doorway's centre (m)
DOOR_WAIT, ASIDE_AHEAD, ASIDE_SIDE = 8.0, 1.0, 1.5
#: Groups: members' centres this far apart side by side (m), and starting within this distance (m) of the
#: first member. 1 m is about where the person-person repulsion (Helbing & Molnar's, between discs) and
#: the group's attraction balance for people walking abreast: closer, they push apart within a second.
GROUP_SPACING, GROUP_START = 1.0, 1.5
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
    ``speeds`` (n,) m/s, ``depart`` (n,) s: when each sets off; ``groups`` (n,) each one's group (-1:
    alone), or None when nobody walks in a group."""

    starts: np.ndarray
    places: np.ndarray
    speeds: np.ndarray
    radius: float
    duration: float
    depart: np.ndarray
    groups: Optional[np.ndarray] = None


def people_footprints(scene: Scene, tasks: Sequence[Task], robot: Robot, reach: float = 0.0) -> list[Footprint]:
    """What people walk round: every collider's floor shadow below :data:`PERSON_HEIGHT`, and a disc of
    radius ``robot.inflation + KEEP_OUT + reach`` at every task's spawn and goal (``reach``: the widest
    tube a reacting person may stray in, so that a robot waiting there is outside every tube too)."""
    prints = scene_footprints(scene, PERSON_HEIGHT)
    keep_out = [Footprint(f"{task.id}_{which}", "keep_out", centre=(p.x, p.y),
                          radius=robot.inflation + KEEP_OUT + reach)
                for task in tasks for which, p in (("spawn", task.spawn), ("goal", task.goal))]
    return prints + keep_out


def group_ids(params: Mapping[str, Any]) -> Optional[np.ndarray]:
    """(n,) each person's group, the index of its first member (-1: alone), or None when nobody walks in one.

    A pure function of the parameters, so a world's groups can be read off its ``params`` (the HuNavSim
    export does): a scenario's scripted people come first (``group_passing``: ``group_size`` of them, one
    group, 0; another scenario: one person), then the rest in consecutive groups of ``group_size``, the last
    one smaller, a group of one alone."""
    n, size = int(params.get("n_people") or 0), params.get("group_size", 1)
    scenario = params.get("people_scenario", "walk")
    if not (size > 1 or scenario == "group_passing"):
        return None
    groups = np.full(n, -1)
    first = 0 if scenario == "walk" else size if scenario == "group_passing" else 1
    groups[:first] = 0 if scenario == "group_passing" else -1
    for i in range(first, n):
        lead = first + (i - first) // size * size
        if size > 1 and min(lead + size, n) - lead > 1:
            groups[i] = lead
    return groups


# long: each person's start, goal and stay drawn in turn from one stream; the order is the stream's
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
    pool = _Pool(rng, FootprintIndex(people_footprints(scene, tasks, robot, widest_tube(params))), scene.bounds,
                 clear_r)
    speeds = np.round(rng.uniform(lo, hi, n), 6)
    k = min(MAX_PLACES, math.ceil(duration * hi * 1.3 / LEG_MIN) + 1)
    starts: list[np.ndarray] = []
    places = np.zeros((n, k, 2))
    depart = np.zeros(n)
    size = params.get("group_size", 1)
    groups = group_ids(params)
    scenario = params.get("people_scenario", "walk")
    if scenario != "walk":
        scripted, reason = _scripted(scenario, scene, tasks[0], float(speeds[0]), params, pool.index, clear_r)
        if scripted is None:
            return None, reason
        for j, (point, route, leave) in enumerate(scripted):
            starts.append(point)
            places[j] = np.nan
            places[j, : len(route)] = route
            depart[j] = leave
        if scenario == "group_passing":
            speeds[: len(scripted)] = speeds[0]
    first = len(starts)
    for i in range(first, n):
        lead = first + (i - first) // size * size  # the first member of i's group
        def apart(q):
            return np.all(np.hypot(*(q[:, None] - np.array(starts).reshape(1, -1, 2)).transpose(2, 0, 1))
                          >= 2 * r + SLACK, axis=1)
        if i == lead:
            start = pool.take(apart)
        else:
            speeds[i] = speeds[lead]
            start = pool.take(lambda q, c=starts[lead]: apart(q) & (np.hypot(*(q - c).T) <= GROUP_START))
        if start is None:
            return None, f"could not place {n} people of radius {r:g} m on free floor (placed {i})"
        starts.append(start)
        if i != lead:
            places[i] = _beside(places[lead], starts[lead], i - lead, min(lead + size, n) - lead, pool.index, clear_r,
                                scene.bounds)
            continue
        last = start
        for j in range(k):
            nxt = pool.take(lambda q, last=last: (np.hypot(*(q - last).T) >= LEG_MIN) & (np.hypot(*(q - last).T) <= LEG_MAX))
            if nxt is None:
                return None, f"could not find places {LEG_MIN:g}-{LEG_MAX:g} m apart for a person of radius {r:g} m"
            places[i, j] = last = nxt
    if groups is not None and size > 1:
        # The first member's places were the group's centre line: it takes its own slot beside them too.
        for lead in range(first, n, size):
            if min(lead + size, n) - lead > 1:
                places[lead] = _beside(places[lead], starts[lead], 0, min(lead + size, n) - lead, pool.index, clear_r,
                                       scene.bounds)
    return PeoplePlan(np.array(starts).reshape(-1, 2), places, speeds, float(r), float(duration), depart, groups), None


def _beside(centre: np.ndarray, start: np.ndarray, slot: int, size: int, index: FootprintIndex, radius: float,
            bounds) -> np.ndarray:
    """(k, 2) a group member's places: each of the group's places ``centre`` moved across its leg (from the
    place before; the first from ``start``) by ``(slot - (size - 1) / 2) x GROUP_SPACING``, else by half
    that, else not moved, whichever is first free floor for the disc of ``radius``."""
    out = centre.copy()
    offset = (slot - (size - 1) / 2) * GROUP_SPACING
    if offset == 0:
        return out
    (x0, y0), (x1, y1) = bounds
    before = start
    for j, q in enumerate(centre):
        if np.isnan(q[0]):
            break
        leg = q - before
        length = float(np.hypot(*leg))
        before = q
        if length < 1e-9:
            continue
        normal = np.array([-leg[1], leg[0]]) / length
        for share in (1.0, 0.5):
            p = np.round(q + share * offset * normal, 6)
            inside = x0 + radius <= p[0] <= x1 - radius and y0 + radius <= p[1] <= y1 - radius
            if inside and not index.blocked(p[None], radius)[0]:
                out[j] = p
                break
    return out


def _scripted(scenario: str, scene: Scene, task: Task, speed: float, params: Mapping[str, Any], index: FootprintIndex,
              radius: float) -> tuple[Optional[list[tuple[np.ndarray, np.ndarray, float]]], Optional[str]]:
    """([(start, places (k, 2), departure time)] of the first people, None) in a human-encounter scenario, set
    against the first task's straight line from spawn S to goal G (u its direction, n its left normal,
    L its length); or (None, reason) when a start or place is not free floor.

    - ``head_on``: starts on the line :data:`HEAD_ON_SHORT` m short of G (or farther, by
      :data:`HEAD_ON_STEP`, as near as it fits: a reacting person's tube keeps off G) and walks along it toward the
      robot to :data:`HEAD_ON_BEHIND` m short of S, then round the robot at S, on an arc of that radius to
      its left (:data:`HEAD_ON_ARC` degree steps), to as far behind it: it sets off at once.
    - ``crossing``: starts :data:`CROSSING_HALF` m to the right of the line's midpoint M and walks to as
      far to the left, across the line at right angles; it sets off so as to reach M when a robot
      driving the line at ``robot_speed`` would, ``L / 2 / robot_speed`` s (:data:`LAG`: a person starting
      from rest falls behind a steady walker by its speed times the crowd model's tau).
    - ``overtaking``: starts :data:`OVERTAKE_BEHIND` m behind S and :data:`OVERTAKE_SIDE` m to the left of
      the line, and walks parallel to it, the robot's way, to :data:`OVERTAKE_BEYOND` m beyond G: faster
      than the robot, it passes it.
    - ``group_passing``: the first ``group_size`` people, abreast across the line :data:`GROUP_SPACING`
      apart and centred :data:`GROUP_SIDE` m to its left, start :data:`GROUP_SHORT` m short of G and walk
      toward the robot, in the same formation, to :data:`GROUP_BEHIND` m behind S: past the robot.
    - ``doorway``: stands in the first door's doorway (its centre) for :data:`DOOR_WAIT` s, then steps
      aside to :data:`ASIDE_AHEAD` m ahead (along u) and :data:`ASIDE_SIDE` m to the right of it.
    """
    s = np.array([task.spawn.x, task.spawn.y])
    g = np.array([task.goal.x, task.goal.y])
    length = float(np.hypot(*(g - s)))
    u = (g - s) / length
    n = np.array([-u[1], u[0]])
    people: list[tuple[np.ndarray, list[np.ndarray], float]]
    if scenario == "head_on":
        people = [_head_on(s, g, u, n, length, index, radius)]
    elif scenario == "crossing":
        mid = s + u * length / 2
        depart = max(0.0, length / 2 / params["robot_speed"] - CROSSING_HALF / speed - LAG)
        people = [(mid - CROSSING_HALF * n, [mid + CROSSING_HALF * n], depart)]
    elif scenario == "overtaking":
        people = [(s - OVERTAKE_BEHIND * u + OVERTAKE_SIDE * n, [g + OVERTAKE_BEYOND * u + OVERTAKE_SIDE * n], 0.0)]
    elif scenario == "group_passing":
        size = params.get("group_size", 1)
        if size < 2 or size > params["n_people"]:
            raise ParameterError(f"people_scenario 'group_passing' needs group_size from 2 to n_people "
                                 f"({params['n_people']}), got {size}")
        across = [(GROUP_SIDE + (k - (size - 1) / 2) * GROUP_SPACING) * n for k in range(size)]
        people = [(g - GROUP_SHORT * u + a, [s - GROUP_BEHIND * u + a], 0.0) for a in across]
    else:
        doors = [d for d in door_records(scene) if d.get("passage")]
        if not doors:
            raise ParameterError("people_scenario 'doorway' needs a world with a door (generator 'door')")
        c = np.array(doors[0]["passage"]["center"], dtype=float)
        people = [(c, [c + ASIDE_AHEAD * u - ASIDE_SIDE * n], DOOR_WAIT)]
    out = []
    (x0, y0), (x1, y1) = scene.bounds
    for start, route, depart in people:
        start, places = np.round(start, 6), np.round(np.array(route), 6)
        for label, p in (("start", start), *(("place", q) for q in places)):
            inside = x0 + radius <= p[0] <= x1 - radius and y0 + radius <= p[1] <= y1 - radius
            if not inside or index.blocked(p[None], radius)[0]:
                return None, f"the {scenario} person's {label} ({p[0]:.3f}, {p[1]:.3f}) is not free floor"
        out.append((start, places, round(depart, 6)))
    return out, None


def _head_on(s, g, u, n, length: float, index: FootprintIndex,
             radius: float) -> tuple[np.ndarray, list[np.ndarray], float]:
    """(start, places, departure) of the head-on person (:func:`_scripted`)."""
    # As near the goal as the person fits: farther back where a reacting person's tube, kept off the
    # goal, would not let it stand HEAD_ON_SHORT short of it.
    short = next((d for d in HEAD_ON_SHORT + HEAD_ON_STEP * np.arange(int(length / 2 / HEAD_ON_STEP))
                  if not index.blocked(np.round(g - d * u, 6)[None], radius)[0]), HEAD_ON_SHORT)
    # Round the robot along an arc of HEAD_ON_BEHIND about S (on its left), in steps short enough that every
    # chord keeps outside the robot's keep-out disc: a person walking straight at that disc can stall
    # against it, the wider the tube the sooner.
    arc = np.radians(np.arange(0.0, 180.0 + HEAD_ON_ARC / 2, HEAD_ON_ARC))
    return g - short * u, [s + HEAD_ON_BEHIND * (np.cos(a) * u + np.sin(a) * n) for a in arc], 0.0


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
