"""Test oracles: a recorded run plus a world's ground truth in, navigation figures out.

    >>> from worldgen import oracles
    >>> oracles.path_efficiency(trajectory, world)      # recorded length / task path length
    >>> oracles.collisions(trajectory, "worlds/cluttered-s7-1f3a9c0b")
    >>> oracles.evaluate([(trajectory, world), ...], "criteria.yaml")   # many runs against criteria

The public face of two modules: :mod:`worldgen.testing.figures` (each figure of
one run: trajectories, worlds and tasks as accepted there) and
:mod:`worldgen.testing.evaluate` (many runs judged against acceptance criteria).
"""

from __future__ import annotations

from worldgen.testing.evaluate import evaluate
from worldgen.testing.figures import (
    Contact,
    Ground,
    Run,
    as_trajectory,
    barn_score,
    collisions,
    load,
    min_clearance,
    min_separation,
    path_efficiency,
    path_length,
    reached_goal,
    run,
    time_to_goal,
)

__all__ = [
    "Ground", "Contact", "Run", "load", "as_trajectory",
    "path_length", "path_efficiency", "time_to_goal", "reached_goal", "min_clearance",
    "collisions", "min_separation", "run", "evaluate", "barn_score",
]
