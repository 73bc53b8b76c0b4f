"""Pockets: a place it proves out of reach is out of the exact planner's reach, and a walk that uses the proof is
the walk that asks the planner every time (same rows), in the crowded rooms where it matters."""

from __future__ import annotations

import numpy as np
import pytest

import worldgen
from worldgen.feasibility.cspace import ConfigSpace
from worldgen.feasibility.geometry import Obstacles2D
from worldgen.feasibility.planner import Planner
from worldgen.people.places import SLACK, people_footprints
from worldgen.people.reach import Pockets


def _space(seed: int, n_obstacles: int) -> ConfigSpace:
    world = worldgen.generate("cluttered", seed=seed, n_obstacles=n_obstacles)
    obstacles = Obstacles2D.from_footprints(people_footprints(world.scene, world.tasks, world.robot))
    return ConfigSpace.build(obstacles, 0.25 + SLACK, world.scene.bounds)


@pytest.mark.parametrize("seed,n_obstacles", [(5, 65), (1, 60), (2, 70)])
def test_apart_means_the_planner_finds_no_path(seed, n_obstacles):
    cs = _space(seed, n_obstacles)
    pockets, planner = Pockets(cs), Planner(cs)
    rng = np.random.default_rng(seed)
    x0, y0, x1, y1 = cs.box
    pts = rng.uniform([x0, y0], [x1, y1], size=(400, 2))
    pts = pts[cs.points_clearance(pts) > 1e-3][:40]
    proven = asked = 0
    for a, b in zip(pts[:-1], pts[1:]):
        if pockets.apart(a, b):
            proven += 1
            assert planner.shortest(a, b) is None, (a, b)
        elif asked < 6:  # the superset joins them: the planner decides (and often finds a path)
            asked += 1
            planner.shortest(a, b)
    assert proven >= 3, proven  # these rooms do fall apart into pockets, so the proof is used


def test_a_walk_with_the_proof_is_the_walk_without_it(monkeypatch):
    kw = {"n_obstacles": 65, "n_people": 10}
    proven = []
    apart = Pockets.apart
    monkeypatch.setattr(Pockets, "apart", lambda self, a, b: proven.append(apart(self, a, b)) or proven[-1])
    fast = worldgen.generate("cluttered", seed=5, **kw)
    assert sum(proven) >= 100, sum(proven)  # most queries of this walk were places in another pocket
    monkeypatch.setattr(Pockets, "apart", lambda self, a, b: False)
    slow = worldgen.generate("cluttered", seed=5, **kw)
    assert fast.content_hash == slow.content_hash and any(m.person for m in fast.scene.movers)
    assert [np.asarray(m.trajectory).tolist() for m in fast.scene.movers] == \
        [np.asarray(m.trajectory).tolist() for m in slow.scene.movers]
