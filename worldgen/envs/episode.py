"""One episode's record, and its figures under the oracles' names once it ends.

The record is the run as the judge takes it (:mod:`worldgen.judge.figures`): ``t, x, y, yaw``
rows, one at the reset and one after every env step, plus every MuJoCo contact
of the robot (one :class:`~worldgen.judge.figures.Contact` per contact that begins,
naming the entity touched, as :func:`worldgen.judge.figures.collisions` reports them).

:meth:`Episode.figures` gives the keys of :class:`worldgen.judge.figures.Run`
(``world_id``, ``task``, ``reached_goal``, ``time_to_goal``, ``duration``,
``path_length``, ``path_efficiency``, ``min_clearance``, ``collisions``,
``min_separation``, ``max_velocity``; ``collisions`` as ``Run.as_dict`` writes
them) plus ``success`` (evaluate's rule: goal reached within the time limit, no
collision), ``spl`` (success weighted by path length: ``success * L / max(P, L)``
with ``L`` the task's optimal path length and ``P`` the path travelled) and
``reference_path_length`` (``L``). Every figure but ``collisions`` is computed by
the oracles' own functions from the recorded trajectory; ``min_clearance`` is
their FCL distance from the footprint to every collider along it (negative: a
contact's depth). ``collisions`` are MuJoCo's contacts, which also ended the
episode.

A door leaf (the world's ``door_leaves``) is a hinged body the robot may push
open, as the world's truth plans through doors at their open limit: a contact
with a leaf is no collision; it goes to ``door_contacts`` instead (the same
``{time, entity}`` records), and it neither ends the episode nor fails it. One push is one door contact:
MuJoCo makes and breaks the contact many times while a leaf gives way, so a touch of a leaf that begins
within :data:`~worldgen.judge.figures.DOOR_DEBOUNCE` (2 s of simulated time) of the last physics step
touching that leaf continues the same door contact, as the oracles count them. ``doors_opened`` lists the
automatic doors the robot triggered (:mod:`worldgen.envs.doors`), ``{time, entity}`` with the leaf's name.
"""

from __future__ import annotations

from typing import Optional

import numpy as np

from worldgen.envs.reacting import Walkers
from worldgen.judge.figures import DOOR_DEBOUNCE, Contact

__all__ = ["Episode", "spl"]


def spl(success: bool, reference_length: float, path_length: float) -> float:
    """Success weighted by (normalised inverse) path length: ``success * L / max(P, L)``, in [0, 1]."""
    if not success:
        return 0.0
    longest = max(path_length, reference_length)
    return 1.0 if longest <= 0.0 else float(reference_length / longest)


class Episode:
    """The record of one episode in ``world`` (an :class:`~worldgen.envs.source.EpisodeWorld`)."""

    def __init__(self, world, x: float, y: float, yaw: float):
        self.world = world
        self.rows: list[tuple[float, float, float, float]] = [(0.0, x, y, yaw)]
        self.contacts: list[Contact] = []
        #: Contacts with door leaves (pushed open, not collisions).
        self.door_contacts: list[Contact] = []
        self._leaves: frozenset = getattr(world, "door_leaves", frozenset())
        #: When each leaf was last touched (s): a touch soon after continues the same door contact.
        self._leaf_last: dict[str, float] = {}
        #: Whether the robot touched a door leaf since :meth:`new_step` (the env's per-step ``door_contact``).
        self.door_touched = False
        #: The automatic doors triggered, when (the leaf's name).
        self.door_openings: list[Contact] = []
        #: The entities the robot touched at the last physics step checked.
        self.touching: frozenset = frozenset()
        self.done = False
        #: The world's movers and people (:class:`~worldgen.envs.reacting.Walkers`), set by the environment.
        self.walkers: Optional[Walkers] = None

    def record(self, t: float, x: float, y: float, yaw: float) -> None:
        self.rows.append((t, x, y, yaw))

    def touch(self, t: float, entities: frozenset) -> bool:
        """Note the entities the robot touches at time ``t``; True when a collision (not a door leaf) begins."""
        new = sorted(entities - self.touching)
        self.touching = entities
        hits = [name for name in new if name not in self._leaves]
        self.contacts.extend(Contact(float(t), name) for name in hits)
        for name in new:
            if name in self._leaves and t - self._leaf_last.get(name, -np.inf) > DOOR_DEBOUNCE:
                self.door_contacts.append(Contact(float(t), name))
        for name in entities & self._leaves:
            self._leaf_last[name] = float(t)
            self.door_touched = True
        return bool(hits)

    def new_step(self) -> None:
        """Start an env step: clear the per-step door flag."""
        self.door_touched = False

    @property
    def trajectory(self) -> np.ndarray:
        """(n, 4) ``t, x, y, yaw`` rows: the run as the oracles take it."""
        return np.array(self.rows, dtype=float)

    def figures(self) -> dict:
        """The figures of the run so far, under the oracles' names (see the module's docstring)."""
        from worldgen.judge import figures as oracles

        ground = self._as_walked(self.world.ground())
        traj = self.trajectory
        task = self.world.task
        length = oracles.path_length(traj)
        ref = self.world.reference_path_length
        dt = np.diff(traj[:, 0])
        step = np.hypot(*np.diff(traj[:, 1:3], axis=0).T)
        moving = dt > 0
        run = oracles.Run(
            world_id=self.world.world_id, task=str(task["id"]),
            reached_goal=oracles.reached_goal(traj, ground), time_to_goal=oracles.time_to_goal(traj, ground),
            duration=float(traj[-1, 0] - traj[0, 0]), path_length=length,
            path_efficiency=length / ref if ref > 0 else None,
            min_clearance=oracles.min_clearance(traj, ground), collisions=tuple(self.contacts),
            min_separation=oracles.min_separation(traj, ground),
            max_velocity=float((step[moving] / dt[moving]).max()) if np.any(moving) else 0.0,
            door_contacts=tuple(self.door_contacts))
        limit: Optional[float] = task.get("time_limit")
        # evaluate's rule (worldgen.judge.evaluate): the goal, within the scenario's max_time, and no collision.
        ok = bool(run.reached_goal and not run.collisions
                  and (limit is None or (run.time_to_goal is not None and run.time_to_goal <= limit)))
        out = run.as_dict()
        out.update(success=ok, spl=spl(ok, ref, length), reference_path_length=ref,
                   doors_opened=[{"time": c.time, "entity": c.entity} for c in self.door_openings])
        if ground.meta.get("people"):
            from worldgen.judge.proxemics import social_split

            out["social"] = social_split(traj, ground)
            out["people_clips"] = dict(self.walkers.clips) if self.walkers is not None else {}
        return out

    def _as_walked(self, ground):
        """``ground`` with each reacting person's trajectory the one it walked in this episode (its
        world.json trajectory kept as ``recorded_trajectory``): the run is judged against the people as
        they moved."""
        reacted = self.walkers.reacted if self.walkers is not None else {}
        if not reacted:
            return ground
        import copy

        walked = copy.copy(ground)
        people = []
        for p in ground.meta.get("people") or []:
            rows = reacted.get(str(p["name"]))
            people.append(p if rows is None or len(rows) < 2 else
                          dict(p, trajectory=rows.tolist(), recorded_trajectory=p["trajectory"]))
        walked.meta = dict(ground.meta, people=people)
        return walked

