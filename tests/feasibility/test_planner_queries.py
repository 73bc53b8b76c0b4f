"""The exact planners against the stored answers: 338 queries over 11 worlds (data/planner_queries.json,
written by tests/support/planner_queries.py with the planner as it was before it was made faster). Every exact planner
(the lazy search and the prebuilt graph) gives the stored length within 1e-9, and no path where there
was none."""

from __future__ import annotations

import json

import numpy as np
import pytest
from support.planner_queries import DATA, space

from worldgen.feasibility.exact import GRAPH_MAX_CIRCLES, ExactPlanner, exact_planner
from worldgen.feasibility.planner import Planner
from worldgen.feasibility.roadmap import Roadmap

_STORED = json.loads(DATA.read_text())
_WORLDS = _STORED["worlds"]


def _ids(w):
    generator, seed, _, which = w
    return f"{generator}-{seed}-{which}"


@pytest.mark.parametrize("w", range(len(_WORLDS)), ids=[_ids(w) for w in _WORLDS])
@pytest.mark.parametrize("kind", [Planner, Roadmap], ids=["lazy", "graph"])
def test_stored_lengths(w, kind):
    generator, seed, params, which = _WORLDS[w]
    cs, _ = space(generator, seed, params, which)
    planner = kind(cs)
    rows = [q for q in _STORED["queries"] if q[0] == w]
    assert len(rows) >= 10
    for _, start, goal, length, _contacts in rows:
        route = planner.shortest(np.array(start), np.array(goal))
        if length is None:
            assert route is None, (start, goal)
        else:
            assert route is not None, (start, goal)
            assert abs(route.length - length) <= 1e-9, (start, goal, route.length, length)


def test_the_set_has_detours_and_dead_ends():
    rows = _STORED["queries"]
    assert len(rows) >= 300
    assert sum(1 for q in rows if q[4]) >= 150  # most go round obstacles
    assert any(q[3] is None for q in rows)  # and some have no path


def test_one_interface_and_the_choice_by_queries_coming():
    generator, seed, params, which = _WORLDS[2]  # a person's space among 50 obstacles
    cs, _ = space(generator, seed, params, which)
    few, many = exact_planner(cs, 1), exact_planner(cs, 1000)
    assert isinstance(few, Planner) and isinstance(many, Roadmap)
    assert isinstance(few, ExactPlanner) and isinstance(many, ExactPlanner)
    generator, seed, params, which = _WORLDS[3]  # 200 obstacles: too many circles for the graph
    big, _ = space(generator, seed, params, which)
    assert big.n_circles > GRAPH_MAX_CIRCLES
    assert isinstance(exact_planner(big, 10 ** 6), Planner)
