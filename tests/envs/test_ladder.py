"""The difficulty ladder (issue 19): the reactive probe's success falls with the level worlds are asked for at.

Two generators: BARN-sized 5 x 5 m cluttered rooms (examples/recipes/barn_like.yaml's) and barn's default
cellular-automaton field, levels 1..10: one world per level and
request seed (worldgen.leveling), the reactive probe driving its first task. Every level has request seeds
0..SEEDS-1 (the rank correlation); levels 1 and 5, whose Wilson intervals must be apart, have 0..END_SEEDS-1
(at 16 worlds level 1's interval at 16/16 is [0.81, 1] and overlaps level 5's, whose rate is about 0.8; level
10's, 0 of 16, is [0, 0.19], far below level 5's).
The table these figures come from is in docs/metrics.md (benchmarks/bench_ladder.py prints it, barn's too).
"""

from __future__ import annotations

import os

import pytest

from worldgen.envs.ladder import ladder_figures, success_by_level

#: The room of examples/recipes/barn_like.yaml.
BARN_ROOM = {"size": [5, 5], "box_size": [0.2, 0.6], "cylinder_radius": [0.1, 0.25], "min_spawn_goal_distance": 3.0}
#: Request seeds at every level: with 12 the rank correlation of some seed windows misses -0.9, with 16 none
#: of 0-15 ... 24-39 does (measured 2026-11-25, docs/metrics.md).
SEEDS = 16
#: Request seeds at levels 1 and 5. Measured with 0..n-1 for n = 30..80: levels 1 and 5 are apart from
#: n = 33 on; at 44 they are apart by 0.03, so one more level-5 success would still leave them apart.
END_SEEDS = 44
#: The generators on the ladder: the parameters asked of them, and request seeds per level where not SEEDS.
#: Corridors are not here: the reactive probe succeeds in every corridor of levels 1-7 (docs/metrics.md).
#: barn's ladder is measured by the benchmark (`benchmarks/bench_ladder.py --only barn`, `make bench`), not
#: here: its level 9-10 requests take seconds each (dense fields, many draws, each proved exactly), and its
#: 42 s were what the suite could not keep within its 10 minutes once campaigns, Harmonic and terrain came.
LADDERS = {
    "cluttered": (BARN_ROOM, {1: END_SEEDS, 5: END_SEEDS}),
}


@pytest.fixture(scope="module", params=sorted(LADDERS))
def ladder(request):
    """One table per generator, shared by the tests below (its worlds are generated once)."""
    params, seeds = LADDERS[request.param]
    table = {}
    for level in range(1, 11):
        table.update(success_by_level(request.param, [level], range(seeds.get(level, SEEDS)), params))
    return {"seeds": seeds, **ladder_figures(table)}


def _disjoint(a, b) -> bool:
    return a["wilson"][1] < b["wilson"][0] or b["wilson"][1] < a["wilson"][0]


#: The ladder's sweep (22 s: 10 levels, 16 to 44 worlds each, every one driven) runs with WORLDGEN_SWEEPS=1 (and
#: in `make bench`), left out of the suite's run otherwise: the suite could not keep within its 10 minutes.
SWEEPS = os.environ.get("WORLDGEN_SWEEPS") == "1"


if SWEEPS:  # else left out of the run, not skipped
    @pytest.mark.slow
    def test_the_reactive_probe_fails_more_the_higher_the_level(ladder):
        rows = ladder["levels"]
        # Requests land (a few may give up).
        assert all(rows[k]["worlds"] >= ladder["seeds"].get(k, SEEDS) - 3 for k in rows), rows
        assert ladder["spearman"] <= -0.9, ladder
        assert rows[1]["rate"] >= 0.9 and rows[10]["rate"] <= 0.2, rows
        assert _disjoint(rows[1], rows[10]), rows

    @pytest.mark.slow
    def test_level_5_is_apart_from_levels_1_and_10(ladder):
        rows = ladder["levels"]
        assert _disjoint(rows[1], rows[5]) and _disjoint(rows[5], rows[10]), rows
