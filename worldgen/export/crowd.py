"""A world's people (and scripted movers) as the agents of a crowd simulator: what the pedsim and HuNavSim
exports share (:mod:`worldgen.export.pedsim`, :mod:`worldgen.export.hunav`; docs/pedsim.md, docs/hunav.md).

Both tools walk an agent from its start toward one goal after another, straight at each, turning away
from walls only by a local force; neither plans round an obstacle. So an agent's goals are the corners
of the walk world.json records, not the places it was heading for: the trajectory's rows with the rows
where it stands merged (consecutive equal positions), cut down by Douglas and Peucker's line
simplification to the rows the straight legs between kept rows pass within :data:`ROUTE_TOLERANCE` of.
Every start and goal is a row of world.json, so each position reads back exactly (to the 6 decimals
world.json has). An agent's speed is the median speed of the legs it walks (:data:`MOVING` and faster),
the steady pace of the walk; neither tool takes a schedule, so the times of the rows are not carried.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Sequence

import numpy as np

from worldgen.errors import ParameterError
from worldgen.floats import round_float
from worldgen.scene.mover import Mover

__all__ = ["ROUTE_TOLERANCE", "MOVING", "Agent", "route", "walking_speed", "agents", "behaviours_args"]

#: How far (m) a walk may stray from the straight legs between the corners kept as goals: well under a
#: person's radius (0.25 m), so the legs keep about the clearance the walk kept, and the agents' own forces
#: smooth the rest.
ROUTE_TOLERANCE = 0.05
#: Legs slower than this (m/s) are a person standing (or shuffling in a crowd), not its pace.
MOVING = 0.05


@dataclass(frozen=True)
class Agent:
    """One agent: ``start`` (x, y) m, ``heading`` rad (of its first leg; 0 for one that never moves),
    ``goals`` (k, 2) m, ``speed`` m/s, ``behaviour`` (worldgen's name), ``loop`` (a scripted mover: its
    goals repeat)."""

    name: str
    radius: float
    start: tuple[float, float]
    heading: float
    goals: np.ndarray
    speed: float
    behaviour: str
    loop: bool
    person: bool


def _positions(trajectory) -> np.ndarray:
    """(k, 2) the rows' positions, each run of equal positions (a stay) kept once."""
    xy = np.asarray(trajectory, dtype=float)[:, 1:3]
    keep = np.ones(len(xy), dtype=bool)
    keep[1:] = np.any(xy[1:] != xy[:-1], axis=1)
    return xy[keep]


def route(trajectory, tolerance: float = ROUTE_TOLERANCE) -> np.ndarray:
    """(k, 2) the corners of a trajectory's walk, the first row first and the last last (one point for a
    walk that never moves): Douglas-Peucker over its positions, on a stack, no recursion."""
    xy = _positions(trajectory)
    if len(xy) <= 2:
        return xy
    keep = np.zeros(len(xy), dtype=bool)
    keep[[0, -1]] = True
    stack = [(0, len(xy) - 1)]
    while stack:
        a, b = stack.pop()
        if b - a < 2:
            continue
        inner = xy[a + 1:b]
        d = xy[b] - xy[a]
        length = math.hypot(*d)
        rel = inner - xy[a]
        if length > 0:
            off = np.abs(rel[:, 0] * d[1] - rel[:, 1] * d[0]) / length
            # Beyond either end of the leg the distance is to that end, not to the line through it.
            along = (rel @ d) / (length * length)
            off = np.where(along < 0, np.hypot(*rel.T), off)
            off = np.where(along > 1, np.hypot(*(inner - xy[b]).T), off)
        else:  # a walk that returns to where it was: the distance to that point
            off = np.hypot(*rel.T)
        k = int(np.argmax(off))
        if off[k] > tolerance:
            keep[a + 1 + k] = True
            stack += [(a, a + 1 + k), (a + 1 + k, b)]
    return xy[keep]


def walking_speed(trajectory) -> float:
    """The median speed (m/s) of a trajectory's legs at :data:`MOVING` or faster, weighted by their
    duration (0 for a walk that never moves)."""
    rows = np.asarray(trajectory, dtype=float)
    dt = np.diff(rows[:, 0])
    speed = np.hypot(*np.diff(rows[:, 1:3], axis=0).T) / dt
    moving = speed >= MOVING
    if not moving.any():
        return 0.0
    speed, dt = speed[moving], dt[moving]
    order = np.argsort(speed, kind="stable")
    cumulative = np.cumsum(dt[order])
    return round_float(float(speed[order][int(np.searchsorted(cumulative, cumulative[-1] / 2))]))


def _agent(mover: Mover, behaviour: str) -> Agent:
    corners = route(mover.trajectory)
    start = corners[0]
    goals = corners[1:] if len(corners) > 1 else corners
    step = goals[0] - start
    heading = round_float(math.atan2(step[1], step[0])) if np.any(step != 0) else 0.0
    return Agent(mover.name, mover.radius, (float(start[0]), float(start[1])), heading, goals,
                 walking_speed(mover.trajectory), behaviour, mover.loop and not mover.person, mover.person)


def agents(movers: Sequence[Mover], behaviours: Sequence[str], fmt: str) -> list[Agent]:
    """Every person, then every scripted mover, as an agent; a ParameterError (one line) where there is no
    person: a crowd file of a world without people is a mistake, not an empty file.

    ``behaviours``: each person's, by its index (``person_<i>``), as world.json gives them; a person past
    the list, and every scripted mover, is ``impassive`` (it walks its script whatever the robot does)."""
    people = [m for m in movers if m.person]
    if not people:
        raise ParameterError(f"format {fmt!r} writes a world's people, and this world has none: set n_people "
                             f"(--set n_people=N) or leave {fmt} out of the formats")

    def behaviour(m: Mover) -> str:
        index = int(m.name.rsplit("_", 1)[1])
        return behaviours[index] if index < len(behaviours) else "impassive"

    return [_agent(m, behaviour(m)) for m in people] + [_agent(m, "impassive") for m in movers if not m.person]


def behaviours_args(world) -> dict:
    """The writers' arguments read off a World besides its scene: each person's behaviour."""
    from worldgen.people.behaviours import behaviours_of

    return {"behaviours": tuple(behaviours_of(world.params))}
