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
import weakref
from dataclasses import dataclass
from typing import Sequence

import numpy as np

from worldgen.errors import ParameterError
from worldgen.floats import round_float
from worldgen.scene.graph import Scene
from worldgen.scene.mover import Mover

__all__ = ["ROUTE_TOLERANCE", "MOVING", "Agent", "route", "routes", "walking_speed", "agents", "people_args"]

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
    goals repeat), ``group`` (the index of its group's first member; -1: alone)."""

    name: str
    radius: float
    start: tuple[float, float]
    heading: float
    goals: np.ndarray
    speed: float
    behaviour: str
    loop: bool
    person: bool
    group: int = -1


def _positions(trajectory) -> np.ndarray:
    """(k, 2) the rows' positions, each run of equal positions (a stay) kept once."""
    xy = np.asarray(trajectory, dtype=float)[:, 1:3]
    keep = np.ones(len(xy), dtype=bool)
    keep[1:] = np.any(xy[1:] != xy[:-1], axis=1)
    return xy[keep]


def route(trajectory, tolerance: float = ROUTE_TOLERANCE) -> np.ndarray:
    """(k, 2) the corners of a trajectory's walk, the first row first and the last last (one point for a
    walk that never moves); :func:`routes` of one."""
    return routes([trajectory], tolerance)[0]


def routes(trajectories: Sequence, tolerance: float = ROUTE_TOLERANCE) -> list[np.ndarray]:
    """The corners of each trajectory's walk (:func:`route`): Douglas-Peucker, every walk at once.

    Douglas-Peucker splits a leg at its row farthest from it (the first of equals) while that row is
    farther than ``tolerance``; which leg is split first changes nothing, so every leg of every walk is
    split in the same pass, a few array operations over the rows of the legs split last (the passes are the
    depth of the splitting, 14 for the benchmark's 20 people walking 60 s, where splitting leg by leg took a
    Python step a corner: 2,000 there)."""
    parts = [_positions(t) for t in trajectories]
    sizes = np.array([len(p) for p in parts])
    xy = np.concatenate(parts)
    keep = np.zeros(len(xy), dtype=bool)
    first, last = np.cumsum(sizes) - sizes, np.cumsum(sizes) - 1
    keep[first] = keep[last] = True  # no leg runs from one walk into the next
    legs = np.column_stack([first, last])  # the legs still to look at: (first row, last row)
    while True:
        legs = legs[legs[:, 1] - legs[:, 0] > 1]
        if not len(legs):
            break
        counts = legs[:, 1] - legs[:, 0] - 1
        runs = np.cumsum(counts) - counts
        leg = np.repeat(np.arange(len(legs)), counts)
        rows = legs[leg, 0] + 1 + np.arange(counts.sum()) - runs[leg]
        a, d = xy[legs[:, 0]][leg], (xy[legs[:, 1]] - xy[legs[:, 0]])[leg]
        length2 = (d * d).sum(axis=1)
        along = np.clip(((xy[rows] - a) * d).sum(axis=1) / np.where(length2 > 0, length2, 1.0), 0.0, 1.0)
        off = np.hypot(*(xy[rows] - a - along[:, None] * d).T)  # to the leg (its nearer end past either end)
        far = np.flatnonzero((off == np.maximum.reduceat(off, runs)[leg]) & (off > tolerance))
        if not len(far):
            break
        far = far[np.r_[True, leg[far][1:] != leg[far][:-1]]]  # the first row of equals
        split, cut = rows[far], legs[leg[far]]
        keep[split] = True
        legs = np.concatenate([np.column_stack([cut[:, 0], split]), np.column_stack([split, cut[:, 1]])])
    return [xy[lo:hi + 1][keep[lo:hi + 1]] for lo, hi in zip(first, last)]


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


def _agent(mover: Mover, corners: np.ndarray, speed: float, behaviour: str, group: int) -> Agent:
    start = corners[0]
    goals = corners[1:] if len(corners) > 1 else corners
    step = goals[0] - start
    heading = round_float(math.atan2(step[1], step[0])) if np.any(step != 0) else 0.0
    return Agent(mover.name, mover.radius, (float(start[0]), float(start[1])), heading, goals, speed, behaviour,
                 mover.loop and not mover.person, mover.person, group)


#: Each scene's walkers, their corners and their paces, found once for both files (a Scene never changes).
_ROUTES: "weakref.WeakKeyDictionary[Scene, tuple[list[Mover], list[np.ndarray], list[float]]]" = \
    weakref.WeakKeyDictionary()


def agents(scene: Scene, fmt: str, behaviours: Sequence[str] = (), groups: Sequence[int] = ()) -> list[Agent]:
    """Every person, then every scripted mover, of ``scene`` as an agent; a ParameterError (one line) where
    there is no person: a crowd file of a world without people is a mistake, not an empty file.

    ``behaviours``, ``groups``: each person's, by its index (``person_<i>``), as world.json and the params
    give them; a person past a list, and every scripted mover, is ``impassive`` (it walks its script whatever
    the robot does) and alone."""
    people = [m for m in scene.movers if m.person]
    if not people:
        raise ParameterError(f"format {fmt!r} writes a world's people, and this world has none: set n_people "
                             f"(--set n_people=N) or leave {fmt} out of the formats")
    if scene not in _ROUTES:
        walkers = people + [m for m in scene.movers if not m.person]
        tracks = [np.asarray(m.trajectory, dtype=float) for m in walkers]
        _ROUTES[scene] = (walkers, routes(tracks), [walking_speed(t) for t in tracks])
    walkers, corners, speeds = _ROUTES[scene]

    def of(m: Mover, values: Sequence, alone):
        index = int(m.name.rsplit("_", 1)[1]) if m.person else len(values)
        return values[index] if index < len(values) else alone

    return [_agent(m, c, v, of(m, behaviours, "impassive"), of(m, groups, -1)) for m, c, v in zip(walkers, corners, speeds)]


def people_args(world) -> dict:
    """What the writers read off a World besides its scene: each person's behaviour and group."""
    from worldgen.people.behaviours import behaviours_of
    from worldgen.people.places import group_ids

    groups = group_ids(world.params)
    return {"behaviours": tuple(behaviours_of(world.params)), "groups": () if groups is None else tuple(groups.tolist())}
