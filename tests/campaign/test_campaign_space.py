"""A point of a campaign's space: the strategy's answers to generation arguments, worlds that do not exist,
descriptors; and the strategies: seeded, resumable from records, and the adaptive one aiming at a corner."""

from __future__ import annotations

import json
import statistics

import optuna
import pytest

from worldgen.campaign.recipe import parse_campaign
from worldgen.campaign.space import Point, cell, descriptors, make_world, point_of, suggest
from worldgen.campaign.strategies import Strategy, value_of
from worldgen.seeding import campaign_seeds

SPACE = """\
space:
  - generator: cluttered
    params:
      size: [6, 6]
      n_obstacles: {min: 0, max: 30}
      n_people: {min: 0, max: 2}
      people_behaviour: [impassive, scared]
      robot_radius: {min: 0.15, max: 0.3}
  - generator: door
    params:
      state: [closed, open]
budget: {runs: 40}
"""
ENTRIES = parse_campaign(SPACE).entries


def test_answers_become_the_arguments_of_generation():
    answers = {"entry": 0, "e0.n_obstacles": 7, "e0.n_people": 1, "e0.people_behaviour": 1, "e0.robot_radius": 0.2}
    point = point_of(ENTRIES, answers, 3, 42)
    assert point == Point(3, 0, "cluttered", None, None, (("n_obstacles", 7), ("n_people", 1),
                          ("people_behaviour", "scared"), ("robot_radius", 0.2), ("size", (6, 6))), 42)
    assert Point.from_dict(json.loads(json.dumps(point.as_dict()))) == point
    # No people: the people's parameters go, since the generator refuses them without people.
    assert "people_behaviour" not in point_of(ENTRIES, dict(answers, **{"e0.n_people": 0}), 3, 42).param_dict
    # Optuna's own trial interface names every dimension.
    fixed = optuna.trial.FixedTrial({"entry": 1, "e1.state": 1})
    assert suggest(fixed, ENTRIES) == {"entry": 1, "e1.state": 1}
    assert point_of(ENTRIES, {"entry": 1, "e1.state": 1}, 0, 1).param_dict == {"state": "open"}


def test_a_world_that_does_not_exist_is_a_refusal_not_a_run():
    point = Point(0, 0, "cluttered", None, None, (("max_attempts", 1), ("n_obstacles", 400), ("size", (3, 3))), 5)
    world, why = make_world(point)
    assert world is None and why and "\n" not in why


def test_descriptors_come_from_the_world():
    point = point_of(ENTRIES, {"entry": 0, "e0.n_obstacles": 5, "e0.n_people": 1, "e0.robot_radius": 0.2}, 0, 9)
    world, _ = make_world(point)
    d = descriptors(point, world.metadata)
    assert d["people"] == 1 and d["door_state"] == "none" and d["robot_radius"] == 0.2 and d["obstacles"] == 5
    assert d["level"] == world.metadata["metrics"]["difficulty_level"]
    assert cell(d)[:4] == ("cluttered", d["level"], 1, "none")
    door = point_of(ENTRIES, {"entry": 1, "e1.state": 1}, 1, 9)
    assert descriptors(door, None)["door_state"] == "open"


def test_a_point_seed_depends_only_on_the_seed_and_its_number():
    assert campaign_seeds(1, 5) == campaign_seeds(1, 5)
    assert len({campaign_seeds(1, k) for k in range(50)} | {campaign_seeds(2, 5)}) == 51


def _corner(point: Point) -> bool:
    d = point.param_dict
    return point.entry == 0 and d["n_obstacles"] >= 24 and d.get("n_people", 0) >= 1 and d["robot_radius"] >= 0.26


def _search(name: str, seed: int, runs: int = 40):
    s = Strategy(name, seed, ENTRIES)
    asked = []
    for _ in range(runs):
        point, search = s.ask()
        failed = _corner(point)
        s.tell(point.index, search, "failed" if failed else "passed", (point.param_dict.get("n_obstacles", 0) // 3,))
        asked.append((point, search, failed))
    return s, asked


@pytest.mark.parametrize("name", ["random", "adaptive", "coverage"])
def test_a_sequential_search_is_the_same_for_a_seed_and_resumes_from_its_records(name):
    _, first = _search(name, 4, 20)
    _, again = _search(name, 4, 20)
    assert [p for p, _, _ in first] == [p for p, _, _ in again]
    _, other = _search(name, 5, 20)
    assert [p for p, _, _ in first] != [p for p, _, _ in other]
    # A new process told the first 12 records asks what the first one asked next.
    resumed = Strategy(name, 4, ENTRIES)
    records = [{"point": p.as_dict(), "search": json.loads(json.dumps(s)), "verdict": "failed" if f else "passed",
                "cell": [p.param_dict.get("n_obstacles", 0) // 3]} for p, s, f in first[:12]]
    resumed.restore(records, 12)
    for p, _, f in first[12:]:
        point, search = resumed.ask()
        assert point == p
        resumed.tell(point.index, search, "failed" if f else "passed", (p.param_dict.get("n_obstacles", 0) // 3,))
    state = resumed.state()
    assert state["strategy"] == name and len(state["trials"]) == 20 and json.dumps(state)


def test_the_adaptive_strategies_find_a_corner_that_uniform_sampling_mostly_misses():
    """The corner holds about 4 % of the space; in 40 runs, over seeds 0..4."""
    found = {name: [sum(f for _, _, f in _search(name, seed)[1]) for seed in range(5)]
             for name in ("random", "adaptive", "coverage")}
    assert statistics.median(found["random"]) <= 2, found
    assert statistics.median(found["adaptive"]) >= 3 * max(statistics.median(found["random"]), 1), found
    assert statistics.median(found["coverage"]) >= 3 * max(statistics.median(found["random"]), 1), found


def test_what_a_result_is_worth():
    assert value_of(None, 0, "adaptive") is None and value_of("unjudged", 0, "adaptive") is None
    assert value_of("passed", 3, "coverage") == 0.0
    assert value_of("failed", 3, "adaptive") == 1.0 and value_of("failed", 3, "coverage") == 0.25
