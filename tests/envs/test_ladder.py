"""The difficulty ladder (issue 19): the reactive probe's success falls with the level worlds are asked for at.

BARN-sized 5 x 5 m cluttered rooms (examples/recipes/barn_like.yaml's), levels 1..10, request seeds
0..SEEDS-1: one world per level and seed (worldgen.leveling), the reactive probe driving its first task.
The table these figures come from is in docs/metrics.md (benchmarks/bench_ladder.py prints it).
"""

from __future__ import annotations

import pytest

from worldgen.envs.ladder import ladder_figures, success_by_level

#: The room of examples/recipes/barn_like.yaml.
BARN_ROOM = {"size": [5, 5], "box_size": [0.2, 0.6], "cylinder_radius": [0.1, 0.25], "min_spawn_goal_distance": 3.0}
SEEDS = 16
#: The generators on the ladder and what is asked of them. Corridors are not here: the reactive probe succeeds
#: in every corridor of levels 1-7 (docs/metrics.md). ``barn`` joins once it has a leveling.KNOBS row.
LADDERS = {"cluttered": BARN_ROOM}


@pytest.fixture(scope="module", params=sorted(LADDERS))
def ladder(request):
    name = request.param
    return ladder_figures(success_by_level(name, range(1, 11), range(SEEDS), LADDERS[name]))


def _disjoint(a, b) -> bool:
    return a["wilson"][1] < b["wilson"][0] or b["wilson"][1] < a["wilson"][0]


@pytest.mark.slow
def test_the_reactive_probe_fails_more_the_higher_the_level(ladder):
    rows = ladder["levels"]
    assert all(rows[k]["worlds"] >= SEEDS - 3 for k in rows), rows  # requests land (a few may give up)
    assert ladder["spearman"] <= -0.9, ladder
    assert rows[1]["rate"] >= 0.9 and rows[10]["rate"] <= 0.2, rows
    assert _disjoint(rows[1], rows[10]), rows


@pytest.mark.slow
@pytest.mark.xfail(strict=True, reason="issue 19 asks level 5's interval to be apart from levels 1 and 10; with "
                   "worldgen.difficulty/1 the reactive probe still succeeds in about 0.75-0.8 of level-5 rooms "
                   "(the score averages the two probes and the tracker's failures rise first): docs/metrics.md")
def test_level_5_is_apart_from_levels_1_and_10(ladder):
    rows = ladder["levels"]
    assert _disjoint(rows[1], rows[5]) and _disjoint(rows[5], rows[10]), rows
