"""The crowd's router (one tangent graph per configuration space) against the exact planner: the same
shortest lengths (within 1e-9) on random queries in people's configuration spaces of many worlds, routes
that keep the clearance and whose length is their legs' and arcs', and a crowd walk that is the same,
row for row, as with the planner."""

from __future__ import annotations

import math

import numpy as np
import pytest

import worldgen
from worldgen.feasibility.cspace import ConfigSpace
from worldgen.feasibility.geometry import Obstacles2D
from worldgen.feasibility.planner import Planner
from worldgen.feasibility.roadmap import Roadmap
from worldgen.people import crowd
from worldgen.people.places import SLACK, draw_people, people_footprints
from worldgen.scene.footprint import Footprint
from worldgen.seeding import people_rng

#: (generator, seed, params, person radius): people's worlds (the benchmark's among them), walls, doors.
WORLDS = [
    ("cluttered", 0, {"size": [20.0, 20.0], "n_obstacles": 50}, 0.25),
    ("cluttered", 1, {"size": [20.0, 20.0], "n_obstacles": 50}, 0.25),
    ("cluttered", 2, {"size": [12.0, 12.0], "n_obstacles": 30}, 0.4),
    ("cluttered", 3, {"size": [8.0, 8.0], "n_obstacles": 12}, 0.15),
    ("corridor", 4, {"shape": "zigzag"}, 0.25),
    ("door", 5, {"state": "open"}, 0.25),
    ("barn", 6, {}, 0.1),
]


def _space(generator, seed, params, radius):
    world = worldgen.generate(generator, seed, **params)
    obstacles = Obstacles2D.from_footprints(people_footprints(world.scene, world.tasks, world.robot))
    return ConfigSpace.build(obstacles, radius + SLACK, world.scene.bounds)


def _free_points(cs, rng, n):
    (x0, y0, x1, y1) = cs.box
    pts = np.column_stack([rng.uniform(x0, x1, 4 * n), rng.uniform(y0, y1, 4 * n)])
    return pts[cs.points_clearance(pts) > 0][:n]


def _route_length(cs, route) -> float:
    """Its straight legs (point 2k to 2k + 1) and its arcs."""
    pts = route.points
    legs = sum(math.dist(pts[2 * k], pts[2 * k + 1]) for k in range(len(route.contacts) + 1))
    return legs + sum(float(cs.rho[c.circle]) * c.sweep for c in route.contacts)


@pytest.mark.parametrize("generator,seed,params,radius", WORLDS, ids=[f"{w[0]}-{w[1]}" for w in WORLDS])
def test_the_same_shortest_lengths_as_the_planner(generator, seed, params, radius):
    cs = _space(generator, seed, params, radius)
    roadmap, planner = Roadmap(cs), Planner(cs)
    rng = np.random.default_rng(seed)
    pts = _free_points(cs, rng, 200)
    detours = 0
    for start, goal in zip(pts[::2], pts[1::2]):
        want, got = planner.shortest(start, goal), roadmap.shortest(start, goal)
        assert (want is None) == (got is None), (start, goal)
        if want is None or got is None:
            continue
        assert got.length == pytest.approx(want.length, abs=1e-9), (start, goal)
        detours += bool(got.contacts)
        # The route is what it says: its legs keep the clearance (each grazes only the circles it touches),
        # its length is its legs' and its arcs', its ends are the query's.
        assert np.array_equal(got.points[0], start) and np.array_equal(got.points[-1], goal)
        assert _route_length(cs, got) == pytest.approx(got.length, abs=1e-9)
        a, b = got.points[:-1:2], got.points[1::2]
        owners = [-1] + [int(cs.owner[c.circle]) for c in got.contacts]
        after = [int(cs.owner[c.circle]) for c in got.contacts] + [-1]
        assert cs.segments_clear(a, b, np.array(owners), np.array(after)).all()
        if got.contacts:
            arcs = [c for c in got.contacts if c.sweep > 0]
            circle = np.array([c.circle for c in arcs], dtype=np.int64)
            start_angle = np.array([c.start if c.side > 0 else c.start - c.sweep for c in arcs])
            assert (cs.arc_clearance(circle, start_angle, np.array([c.sweep for c in arcs])) >= -1e-9).all()
    assert detours >= 8, detours  # the queries exercise the graph, not only straight lines


def test_a_world_without_obstacles_and_one_of_discs_only():
    bounds = ((0.0, 0.0), (6.0, 4.0))
    empty = ConfigSpace.build(Obstacles2D.from_footprints([]), 0.25, bounds)
    route = Roadmap(empty).shortest([0.5, 0.5], [5.5, 3.5])
    assert route is not None and route.length == pytest.approx(math.hypot(5.0, 3.0), abs=1e-12)
    # A disc of radius 1 at the centre: round it from (0.5, 2) to (5.5, 2), the exact length by hand:
    # two tangents of length sqrt(2.5^2 - 1.25^2) and the arc between them, 1.25 (pi - 2 acos(1.25 / 2.5)).
    disc = Obstacles2D.from_footprints([Footprint("d", "obstacle", centre=(3.0, 2.0), radius=1.0)])
    cs = ConfigSpace.build(disc, 0.25, bounds)
    got = Roadmap(cs).shortest([0.5, 2.0], [5.5, 2.0])
    want = 2 * math.sqrt(2.5 ** 2 - 1.25 ** 2) + 1.25 * (math.pi - 2 * math.acos(1.25 / 2.5))
    assert got is not None and got.length == pytest.approx(want, abs=1e-9)
    assert got.length == pytest.approx(Planner(cs).shortest([0.5, 2.0], [5.5, 2.0]).length, abs=1e-12)


def test_a_crowd_walks_the_same_rows_as_with_the_planner(monkeypatch):
    world = worldgen.generate("cluttered", 7, size=[12.0, 12.0], n_obstacles=20, n_people=8, people_duration=20.0)
    obstacles = Obstacles2D.from_footprints(people_footprints(world.scene, world.tasks, world.robot))
    plan, _ = draw_people(world.scene.with_movers(()), world.tasks, world.robot, world.params,
                          people_rng(7, world.attempts - 1))
    assert len(plan.starts) == 8

    def walk(router):
        monkeypatch.setattr(crowd, "_route_finder", lambda cs, n, duration: router(cs))
        return crowd.simulate(obstacles, world.scene.bounds, plan.starts, plan.places, plan.speeds, plan.radius,
                              plan.duration, depart=plan.depart, groups=plan.groups)
    with_roadmap = walk(Roadmap)
    assert np.array_equal(walk(Planner), with_roadmap)
    assert np.abs(np.diff(with_roadmap, axis=0)).max() > 0.01  # people walk


def test_the_graph_is_built_for_many_legs_in_a_small_world_only():
    cs = _space("cluttered", 0, {"size": [20.0, 20.0], "n_obstacles": 50}, 0.25)  # the benchmark's world
    assert isinstance(crowd._route_finder(cs, 20, 60.0), Roadmap)
    assert isinstance(crowd._route_finder(cs, 1, 60.0), Planner)  # one person: a few queries
    big = _space("cluttered", 0, {"size": [40.0, 40.0], "n_obstacles": 200}, 0.25)
    assert big.n_circles > crowd.ROADMAP_MAX_CIRCLES
    assert isinstance(crowd._route_finder(big, 50, 60.0), Planner)
