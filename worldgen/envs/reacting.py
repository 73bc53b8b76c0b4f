"""Movers and people in the environment, the people reacting to the robot (docs/people.md).

Scripted movers and impassive people walk their world.json tracks (:class:`~worldgen.envs.movers.MoverScript`).
A person with a ``behaviour`` (world.json ``people[].behaviour`` and ``tube``) is moved by
:class:`worldgen.people.react.Reactions`: once per control period, from the robot's position and
velocity at the period's start, its position at the period's end; at each physics step between, the
phase and offset interpolated (inside its tube at every step). The positions each reacting person
actually had are recorded (a ``t, x, y`` row per control period) for the oracles, with the count of
clips the tube made.
"""

from __future__ import annotations

from typing import Optional

import numpy as np

from worldgen.envs.movers import MoverScript
from worldgen.people.behaviours import Tube

__all__ = ["Walkers", "walkers_of"]


class Walkers:
    """All the movers of one world (world.json ``dynamic_obstacles`` then ``people`` entries, the MJCF's
    order); ``wall_gap`` as :class:`~worldgen.people.react.Reactions` takes it."""

    def __init__(self, movers: list, wall_gap=None):
        from worldgen.people.react import Reactions

        self.script = MoverScript(movers)  # everyone on its world.json track: the reset's and the picture's
        self.z = self.script.z
        self.names = [str(m["name"]) for m in movers]
        loops = np.array([bool(m.get("loop", False)) for m in movers], dtype=bool)
        self.loopers, self.people = np.flatnonzero(loops), np.flatnonzero(~loops)
        self._loop_script = MoverScript([movers[i] for i in self.loopers])
        # Every person (impassive ones walk their tracks exactly) goes through one Reactions: one look-up
        # for all of them a period, where np.interp took two calls a person.
        who = [movers[i] for i in self.people]
        #: Each reacting person's place among ``people``.
        self.reacting = np.array([k for k, m in enumerate(who) if m.get("behaviour")], dtype=np.int64)
        self.reactions: Optional[Reactions] = None
        if len(who):
            self.reactions = Reactions(
                [np.asarray(m["trajectory"], dtype=float) for m in who], [float(m["radius"]) for m in who],
                [str(m.get("behaviour", "impassive")) for m in who],
                [Tube(float(m["tube"]["d"]), float(m["tube"]["tau"])) if m.get("tube") else Tube(0.0, 0.0)
                 for m in who], wall_gap if len(self.reacting) else None)
        self.rows: list[list[tuple[float, float, float]]] = []
        self._rows: slice | np.ndarray | None = None  # where place() writes: a slice when the indices run on
        self._rows_of: Optional[np.ndarray] = None
        self.reset()

    def __len__(self) -> int:
        return len(self.script)

    def reset(self) -> None:
        """Everyone back on its start, the records cleared."""
        if self.reactions is not None:
            self.reactions.reset()
            self.rows = [[(0.0, float(x), float(y))] for x, y in self.reactions.p[self.reacting]]

    def positions(self, times: np.ndarray) -> np.ndarray:
        """(len(times), movers, 2) where the scripts have everyone (reacting people: where they are now)."""
        xy = self.script.positions(times)
        if self.reactions is not None and len(self.reacting):
            xy[:, self.people[self.reacting]] = self.reactions.p[self.reacting]
        return xy

    def period(self, t0: float, h: float, n: int, robot_xy, robot_v, robot_radius: float) -> np.ndarray:
        """(n, movers, 2) everyone at the start of each of the ``n`` physics steps of ``h`` s from ``t0``,
        the people stepped once to the period's end against the robot."""
        xy = np.empty((n, len(self.names), 2))
        if len(self.loopers):
            xy[:, self.loopers] = self._loop_script.positions(t0 + h * np.arange(n))
        r = self.reactions
        if r is not None:
            r.step(n * h, robot_xy, robot_v, robot_radius)
            xy[:, self.people] = r.positions(np.arange(n) / n)
            for rows, (x, y) in zip(self.rows, r.p[self.reacting]):
                rows.append((round(r.t, 9), float(x), float(y)))
        return xy

    def place(self, data, mocap: np.ndarray, xy: np.ndarray) -> None:
        """Write positions ``xy`` (movers, 2) into ``data.mocap_pos`` for the mocap indices ``mocap``: one
        assignment, to a slice where the indices run on (the MJCF's movers are in a row)."""
        if self._rows is None or self._rows_of is not mocap:
            self._rows_of = mocap
            run = len(mocap) and np.array_equal(mocap, np.arange(mocap[0], mocap[0] + len(mocap)))
            self._rows = slice(int(mocap[0]), int(mocap[0]) + len(mocap)) if run else mocap
            self._xyz = np.empty((len(mocap), 3))
            self._xyz[:, 2] = self.z
        self._xyz[:, :2] = xy
        data.mocap_pos[self._rows] = self._xyz

    @property
    def clips(self) -> dict:
        """{person's name: steps its tube clipped a reaction} of the reacting people."""
        if self.reactions is None:
            return {}
        return {self.names[self.people[k]]: int(self.reactions.clips[k]) for k in self.reacting}

    @property
    def reacted(self) -> dict:
        """{person's name: (k, 3) ``t, x, y`` rows it actually walked} of the reacting people."""
        return {self.names[self.people[k]]: np.array(rows) for k, rows in zip(self.reacting, self.rows)}


def walkers_of(world) -> Walkers:
    """The :class:`Walkers` of an :class:`~worldgen.envs.source.EpisodeWorld`: where someone reacts, kept
    off the world's footprints (below a person's height) and the floor's edge."""
    gap = None
    if any(m.get("behaviour") for m in world.movers):
        from worldgen.feasibility.geometry import Obstacles2D
        from worldgen.people.places import PERSON_HEIGHT
        from worldgen.people.react import wall_gap_of
        from worldgen.scene.footprint import scene_footprints

        scene = world.scene()
        gap = wall_gap_of(Obstacles2D.from_footprints(scene_footprints(scene, PERSON_HEIGHT)), scene.bounds)
    return Walkers(world.movers, gap)
