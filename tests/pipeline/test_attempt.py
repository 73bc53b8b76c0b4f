"""One attempt at a world (worldgen.pipeline): the body generate and a level request share."""

from __future__ import annotations

import pytest

import worldgen
from worldgen.errors import InfeasibleError
from worldgen.generators import get
from worldgen.pipeline import attempt, first_feasible, prepare

#: A crowded small room whose first world is at its fourth attempt (the first three fail a check).
CROWDED = {"n_obstacles": 25, "size": [6, 6]}


def test_an_attempt_made_alone_is_the_attempt_generate_kept():
    world = worldgen.generate("cluttered", seed=0, **CROWDED)
    assert world.attempts == 4
    request = prepare(get("cluttered"), 0, CROWDED)
    kept = attempt(request, world.attempts - 1)
    assert kept.kept and kept.failed == () and kept.world is not None
    assert kept.world.content_hash == world.content_hash and kept.world.attempts == world.attempts
    earlier = [attempt(request, k) for k in range(world.attempts - 1)]
    assert not any(a.kept for a in earlier) and all(a.failed for a in earlier)
    assert [a.number for a in earlier] == [0, 1, 2]


def test_a_refused_draft_makes_no_world_and_names_the_check():
    got = attempt(prepare(get("cluttered"), 5, {"n_obstacles": 400, "size": [5, 5]}), 0)
    assert got.world is None and not got.kept
    assert [check for check, _ in got.failed] == ["obstacle_placement"] and "400" in got.failed[0][1]


def test_the_budget_counts_every_failed_check_and_allow_infeasible_returns_the_last_world():
    spec = get("cluttered")
    with pytest.raises(InfeasibleError, match=r"within max_attempts=3: .*failed 3x"):
        first_feasible(prepare(spec, 0, {**CROWDED, "max_attempts": 3}))
    last = first_feasible(prepare(spec, 0, {**CROWDED, "max_attempts": 3}, allow_infeasible=True))
    assert last.attempts <= 3 and not last.feasibility.feasible and last.allow_infeasible


def test_a_proven_world_of_the_same_scene_is_not_proven_again(monkeypatch):
    """A level request adds people to a draw judged without them: the static checks, which never read the
    people, are the draw's own; feasibility runs again only where the scene differs."""
    from worldgen import feasibility

    spec = get("cluttered")
    bare = worldgen.generate("cluttered", seed=2, n_obstacles=5)
    calls = []
    check = feasibility.check
    monkeypatch.setattr(feasibility, "check", lambda *a, **k: calls.append(1) or check(*a, **k))
    people = {"n_obstacles": 5, "n_people": 2, "people_duration": 10.0}
    got = attempt(prepare(spec, 2, people), bare.attempts - 1, proven=bare)
    assert calls == [] and got.kept and got.world is not None and len(got.world.metadata["people"]) == 2
    assert got.world.content_hash == worldgen.generate("cluttered", seed=2, **people).content_hash
    other = worldgen.generate("cluttered", seed=3, n_obstacles=5)  # another scene: proven afresh
    calls.clear()
    attempt(prepare(spec, 2, people), bare.attempts - 1, proven=other)
    assert calls == [1]
