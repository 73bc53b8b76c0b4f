"""Test oracles: a recorded run plus a world's ground truth in, navigation figures out.

    >>> import worldgen
    >>> from worldgen import oracles
    >>> world = worldgen.generate("cluttered", seed=7, size=[8, 8], n_obstacles=6)
    >>> path = world.metadata["tasks"][0]["path"]["waypoints"]
    >>> trajectory = [(2.0 * i, x, y) for i, (x, y) in enumerate(path)]      # rows t, x, y
    >>> round(oracles.path_efficiency(trajectory, world), 3)     # recorded length / task path length
    1.0
    >>> oracles.reached_goal(trajectory, world), oracles.collisions(trajectory, world)
    (True, [])
    >>> folder = world.write("worlds")                 # a world folder serves as well as the World
    >>> report = oracles.evaluate([(trajectory, folder)], {"navigation": {"success_rate": 1.0}})
    >>> report.passed
    True

The public face of two modules: :mod:`worldgen.judge.figures` (each figure of
one run: trajectories, worlds and tasks as accepted there) and
:mod:`worldgen.judge.evaluate` (many runs judged against acceptance criteria).
"""

from __future__ import annotations

from worldgen.groundtruth.ground import Ground, as_trajectory, load
from worldgen.judge.evaluate import evaluate
from worldgen.judge.figures import (
    DOOR_DEBOUNCE,
    Contact,
    Run,
    barn_score,
    collisions,
    door_contacts,
    min_clearance,
    min_separation,
    path_efficiency,
    path_length,
    reached_goal,
    run,
    time_to_goal,
)
from worldgen.judge.proxemics import ZONES, social_split
from worldgen.judge.social import PERSONAL_SPACE, min_person_distance, min_time_to_collision, personal_space_time

__all__ = [
    "Ground", "Contact", "Run", "load", "as_trajectory",
    "path_length", "path_efficiency", "time_to_goal", "reached_goal", "min_clearance",
    "collisions", "door_contacts", "DOOR_DEBOUNCE", "min_separation", "run", "evaluate", "barn_score",
    "min_person_distance", "personal_space_time", "min_time_to_collision", "PERSONAL_SPACE",
    "social_split", "ZONES",
]
