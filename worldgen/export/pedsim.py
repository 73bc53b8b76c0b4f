"""Scene -> ``pedsim.xml``: the world's crowd as the scenario file pedsim_simulator loads (docs/pedsim.md).

Written by what pedsim_ros's scenario reader reads (``pedsim_simulator/src/scenarioreader.cpp``, the same
in srl-freiburg/pedsim_ros and in ignc-research's fork that the Arena stack runs): a ``<scenario>`` root
holding

* ``<obstacle x1 y1 x2 y2>``: a wall segment, m. The floor's four edges, and each edge of the floor shadow
  of every collider a person meets (below :data:`~worldgen.people.places.PERSON_HEIGHT`); a disc as the
  :data:`DISC_SIDES`-gon round it.
* ``<waypoint id x y r b>``: a goal, m; ``r`` how near counts as reached (the person's radius); ``b="0"``,
  pedsim's ``SIMPLE`` (neither a source nor a sink of agents).
* ``<agent x y n dx dy type>`` with its ``<addwaypoint id>``s in order: one agent (``n="1"``) exactly at its
  start (``dx = dy = 0``: the reader spreads a cluster only over a nonzero ``dx``, ``dy``), ``type="0"``
  (``ADULT``, 0 in both forks), its goals the corners of world.json's walk (:mod:`worldgen.export.crowd`).

Every waypoint comes before the agents, because the reader looks an ``<addwaypoint>``'s id up the moment
it reads it. The robot is not an agent here: its ``type`` is 2 in srl-freiburg's enum and 5 in
ignc-research's (where 2 is ``ELDER``), and both simulators run without one.
"""

from __future__ import annotations

import math

import numpy as np

from worldgen.export.crowd import agents
from worldgen.floats import fmt
from worldgen.scene import Scene

__all__ = ["to_pedsim", "DISC_SIDES", "ADULT", "SIMPLE"]

#: Sides of the polygon written round a disc-shaped footprint (its corners on a circle of r / cos(pi / n),
#: so the polygon holds the disc, 2 % wider at most).
DISC_SIDES = 16
#: pedsim's Ped::Tagent::AgentType ADULT and Ped::Twaypoint::Behavior SIMPLE.
ADULT = 0
SIMPLE = 0


def _outline(footprint) -> np.ndarray:
    """(k, 2) the corners of a footprint, closed (the first repeated last)."""
    if footprint.is_disc:
        r = footprint.radius / math.cos(math.pi / DISC_SIDES)
        a = np.arange(DISC_SIDES + 1) * (2 * math.pi / DISC_SIDES)
        return np.column_stack([footprint.centre[0] + r * np.cos(a), footprint.centre[1] + r * np.sin(a)])
    return np.asarray(footprint.polygon.exterior.coords, dtype=float)


def _obstacles(scene: Scene) -> list[str]:
    from worldgen.people.places import PERSON_HEIGHT
    from worldgen.scene.footprint import scene_footprints

    (x0, y0), (x1, y1) = scene.bounds
    rings = [np.array([(x0, y0), (x1, y0), (x1, y1), (x0, y1), (x0, y0)])]
    rings += [_outline(f) for f in scene_footprints(scene, PERSON_HEIGHT)]
    lines = []
    for ring in rings:
        for (ax, ay), (bx, by) in zip(ring[:-1].tolist(), ring[1:].tolist()):
            if (fmt(ax), fmt(ay)) != (fmt(bx), fmt(by)):  # a side too short to write is no wall
                lines.append(f'  <obstacle x1="{fmt(ax)}" y1="{fmt(ay)}" x2="{fmt(bx)}" y2="{fmt(by)}"/>')
    return lines


def to_pedsim(scene: Scene, name: str = "default") -> bytes:
    """The pedsim scenario of ``scene``'s people and movers (UTF-8 bytes); see the module docstring. Nothing
    but the scene is read: pedsim has no behaviours, and forms its own groups. A scene without people is a
    ParameterError."""
    crowd = agents(scene, "pedsim")
    lines = ['<?xml version="1.0" encoding="UTF-8"?>',
             f"<!-- worldgen world {name.replace('--', '-')}: its people and movers for pedsim_simulator "
             "(docs/pedsim.md) -->",
             "<scenario>"]
    lines += _obstacles(scene)
    for agent in crowd:
        r = fmt(agent.radius)
        for k, (x, y) in enumerate(agent.goals.tolist()):
            lines.append(f'  <waypoint id="{agent.name}_g{k}" x="{fmt(x)}" y="{fmt(y)}" r="{r}" b="{SIMPLE}"/>')
    for agent in crowd:
        lines.append(f'  <agent x="{fmt(agent.start[0])}" y="{fmt(agent.start[1])}" n="1" dx="0" dy="0" '
                     f'type="{ADULT}">')
        lines += [f'    <addwaypoint id="{agent.name}_g{k}"/>' for k in range(len(agent.goals))]
        lines.append("  </agent>")
    lines.append("</scenario>")
    return ("\n".join(lines) + "\n").encode()
