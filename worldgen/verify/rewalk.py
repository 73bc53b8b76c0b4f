"""The people of an edited world walked again, as generation walks them, and certified anew.

A world with people carries a timed certificate per task (``tasks[].timed_path``) made against the
people's walk, and that walk was made in the world's static scene: the crowd model walks each person
round the obstacles and round the others. An edit that removes an obstacle, a scripted mover or a
person (``remove``, ``remove_mover``, ``remove_person``: what :func:`worldgen.shrink` records) would leave
both stale, so a world with people is settled after its edits:

1. the plan the generator drew for its people (:func:`worldgen.people.places.draw_people`: starts, places,
   speeds, departures, groups) is drawn again from the same stream, ``people_rng(seed, attempts - 1)``, on
   the generated world's scene without its people, the very scene the generator drew it on (the draw is
   checked against the people's first rows: a world that is not its generator's draw is refused);
2. the plan's rows of the people still there (``person_<i>`` is row ``i``) are walked by the crowd model
   (:func:`worldgen.people.crowd.walk_plan`) through the edited scene with the world's own parameters, and
   keep their names, so each keeps its behaviour and tube (world.json reads them off the name);
3. every task is certified among them and the scripted movers still there
   (:func:`worldgen.people.timed.certify`), each person with its behaviour, off the static path where no
   timed path keeps to it (:func:`worldgen.people.offpath.certify_off_path`, as generation does); a world
   with movers and no people is certified among its movers alone.

Removing a person changes the others' walk (nobody steps round it any more), and removing an obstacle
changes the walk and the reference paths: the re-walk is the truth, and what is certified. With nobody
and no mover left the world has no certificate, as a world generated without them. The settled world
depends only on the edited static scene and on who is left, never on the order of the edits, so
:func:`~worldgen.verify.edits.with_edits` and :func:`~worldgen.verify.edits.replay_edits` make the same one.
"""

from __future__ import annotations

from dataclasses import replace
from typing import Optional

import numpy as np

from worldgen.errors import ParameterError
from worldgen.people.behaviours import behaviours_of
from worldgen.people.crowd import walk_plan
from worldgen.people.offpath import certify_off_path
from worldgen.people.places import PeoplePlan, draw_people
from worldgen.people.timed import certify, limits_of
from worldgen.scene import Scene
from worldgen.seeding import people_rng

__all__ = ["people_plan", "settle", "without_people", "person_index"]


def without_people(scene: Scene) -> Scene:
    """``scene`` with its people left out (its scripted movers kept): the scene the people are walked in."""
    return scene.with_movers(m for m in scene.movers if not m.person)


def person_index(name: str) -> int:
    """The row of the people's plan that person ``name`` (``person_<i>``) was walked from."""
    return int(name.rsplit("_", 1)[1])


def people_plan(world) -> Optional[PeoplePlan]:
    """The plan the generator drew for ``world``'s people (an edited world's: the one it carries), or None
    for a world generated without people."""
    carried = getattr(world, "people_plan", None)
    if carried is not None or not world.params.get("n_people"):
        return carried
    plan, _ = draw_people(without_people(world.scene), world.tasks, world.robot, world.params,
                          people_rng(world.seed, world.attempts - 1))
    people = [m for m in world.scene.movers if m.person]
    if plan is None or not _drew(plan, people):
        raise ParameterError(f"the people of world {world.world_id} are not the draw of its generator, seed and "
                             "attempt: they cannot be walked again after an edit")
    return plan


def settle(world, plan: Optional[PeoplePlan], scene: Scene, tasks, report):
    """(``scene`` with the people still in it walked again, ``report`` with the timed certificate among
    everything in it that moves): the people of ``world``'s ``plan`` (None: a world without people) that
    ``scene`` keeps, walked through its static part; ``report`` is the static proof of ``scene`` and ``tasks``.
    With nobody and no mover left: the scene without people and ``report`` as it is."""
    kept = sorted((m for m in scene.movers if m.person), key=lambda m: person_index(m.name))
    static = without_people(scene)
    if not kept or plan is None:
        if not static.movers:
            return static, report
        return static, _certified(report, static, tasks, world.robot, limits_of(world.params), None)
    rows = np.array([person_index(m.name) for m in kept])
    some = PeoplePlan(plan.starts[rows], plan.places[rows], plan.speeds[rows], plan.radius, plan.duration,
                      plan.depart[rows], None if plan.groups is None else plan.groups[rows])
    walked = walk_plan(static, tasks, world.robot, world.params, some)
    people = tuple(replace(m, name=k.name) for m, k in zip(walked, kept))
    scene = static.with_movers(static.movers + people)
    behaviours = behaviours_of(world.params)
    return scene, _certified(report, scene, tasks, world.robot, limits_of(world.params),
                             [behaviours[i] for i in rows])


def _certified(report, scene: Scene, tasks, robot, limits, behaviours):
    """``report`` with every task's certificate, as generation makes it: along the static path, and off it for
    a task that has none along it (:mod:`worldgen.people.offpath`)."""
    certified = certify(report, scene, tasks, robot, limits, behaviours)
    if certified.feasible or any(c.name != "timed_path" for c in certified.failed()):
        return certified
    return certify_off_path(certified, scene, tasks, robot, limits, behaviours)


def _drew(plan: PeoplePlan, people) -> bool:
    """Whether ``plan`` is the draw ``people`` were walked from: each one's first row is its start."""
    try:
        rows = [person_index(m.name) for m in people]
    except (ValueError, IndexError):
        return False
    if any(not 0 <= i < len(plan.starts) for i in rows):
        return False
    firsts = np.array([m.trajectory[0][1:] for m in people], dtype=float).reshape(-1, 2)
    return bool(np.array_equal(firsts, np.round(plan.starts[rows], 6)))
