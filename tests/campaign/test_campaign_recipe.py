"""Campaign recipes: what a good one reads as, and every bad input as one line naming the key and its line."""

from __future__ import annotations

import pytest

from worldgen.campaign.recipe import Range, parse_campaign, without_idle_people
from worldgen.errors import ParameterError

GOOD = """\
name: planted
space:
  - generator: cluttered
    params:
      size: [6, 6]
      n_people: {min: 0, max: 2}
      people_behaviour: [impassive, scared]
      robot_radius: {min: 0.15, max: 0.3}
    difficulty: {levels: {min: 1, max: 8}}
  - generator: door
    params:
      state: [closed, open, ajar]
system: {drive: {sim: mujoco}}
budget: {runs: 50, seconds: 600}
strategy: {name: coverage, seed: 3}
"""


def test_a_good_recipe_reads_as_its_space_budget_and_strategy():
    r = parse_campaign(GOOD)
    assert r.name == "planted" and r.strategy == "coverage" and r.seed == 3
    assert (r.runs, r.seconds) == (50, 600.0)
    assert r.system == {"drive": {"sim": "mujoco"}} and r.verdict is None
    clutter, door = r.entries
    assert clutter.generator == "cluttered" and clutter.levels == tuple(range(1, 9))
    assert dict(clutter.fixed) == {"size": (6, 6)}
    assert dict(clutter.choices) == {"people_behaviour": ("impassive", "scared")}
    assert dict(clutter.ranges) == {"n_people": Range(0, 2, True), "robot_radius": Range(0.15, 0.3, False)}
    assert door.generator == "door" and door.levels == () and dict(door.choices) == {"state": ("closed", "open", "ajar")}


def test_the_identity_leaves_out_the_budget_so_a_rerun_may_extend_it():
    a = parse_campaign(GOOD)
    assert parse_campaign(GOOD.replace("runs: 50", "runs: 80")).identity == a.identity
    assert parse_campaign(GOOD.replace("seed: 3", "seed: 4")).identity != a.identity


def test_people_parameters_go_when_a_point_has_no_people():
    assert without_idle_people({"n_people": 0, "people_behaviour": "scared", "size": 1}) == {"n_people": 0, "size": 1}
    assert without_idle_people({"n_people": 2, "people_behaviour": "scared"}) == {"n_people": 2, "people_behaviour": "scared"}


BAD = [
    ("unknown top key", GOOD.replace("budget:", "budgett: {runs: 1}\nbudget:"), ":14: key 'budgett': unknown key in campaign recipe"),
    ("unknown entry key", GOOD.replace("    difficulty:", "    seeds: 3\n    difficulty:"), ":9: key 'seeds': unknown key in space[0]"),
    ("empty range", GOOD.replace("{min: 0, max: 2}", "{min: 2, max: 0}"), ":6: key 'n_people': is an empty range: min 2 > max 0"),
    ("empty choices", GOOD.replace("[impassive, scared]", "[]"), ":7: key 'people_behaviour': a list of choices needs at least one value"),
    ("range on a choice", GOOD.replace("[impassive, scared]", "{min: 0, max: 1}"), "key 'people_behaviour': a mapping must be {min, max}"),
    ("unknown parameter", GOOD.replace("size: [6, 6]", "sise: [6, 6]"), ":5: key 'sise': unknown parameter of generator 'cluttered'"),
    ("the seed", GOOD.replace("size: [6, 6]", "seed: 3"), "key 'seed': the campaign draws every world's seed"),
    ("a choice the generator refuses", GOOD.replace("[closed, open, ajar]", "[closed, shut]"), "key 'state':"),
    ("a range end the generator refuses", GOOD.replace("max: 0.3", "max: 9.0"), "key 'robot_radius':"),
    ("a level out of reach", GOOD.replace("state: [closed, open, ajar]", "state: closed\n    difficulty: {levels: [1]}"),
     "key 'difficulty':"),
    ("worlds per level", GOOD.replace("{levels: {min: 1, max: 8}}", "{levels: [1], worlds_per_level: 3}"),
     "key 'worlds_per_level': unknown key in difficulty"),
    ("no space", "budget: {runs: 3}\n", ":1: key 'space' is missing"),
    ("empty space", GOOD.replace("space:\n", "space: []\nx:\n"), "key 'x': unknown key"),
    ("no budget", GOOD.replace("budget: {runs: 50, seconds: 600}\n", ""), "key 'budget' is missing"),
    ("empty budget", GOOD.replace("{runs: 50, seconds: 600}", "{}"), "key 'budget': needs 'runs', 'seconds' or both"),
    ("zero runs", GOOD.replace("runs: 50", "runs: 0"), ":14: key 'runs': must be an integer in [1, 1000000], got 0"),
    ("negative seconds", GOOD.replace("seconds: 600", "seconds: -1"), "key 'seconds': must be a number of seconds > 0"),
    ("unknown strategy", GOOD.replace("name: coverage", "name: bayes"), ":15: key 'name': must be one of random, adaptive, coverage"),
    ("bad seed", GOOD.replace("seed: 3", "seed: -3"), "key 'seed': the strategy's seed must be an integer"),
    ("system not a mapping", GOOD.replace("{drive: {sim: mujoco}}", "mujoco"), "key 'system': must be a mapping"),
    ("verdict file missing", GOOD.replace("budget:", "verdict: nowhere.yaml\nbudget:"), "key 'verdict':"),
    ("not yaml", "space: [\n", "not valid YAML"),
    ("empty file", "", ":1: the campaign recipe is empty"),
    ("python tag", GOOD.replace("name: planted", "name: !!python/object:os.system x"), "could not determine a constructor"),
]


@pytest.mark.parametrize("what, text, message", BAD, ids=[b[0] for b in BAD])
def test_a_bad_recipe_is_one_line_naming_what_is_wrong(what, text, message):
    with pytest.raises(ParameterError) as info:
        parse_campaign(text, "c.yaml")
    line = str(info.value)
    assert "\n" not in line and line.startswith("c.yaml") and message in line, line


def test_the_shipped_campaign_recipe_reads():
    from pathlib import Path

    from worldgen.campaign.recipe import load_campaign

    r = load_campaign(Path(__file__).resolve().parents[2] / "examples" / "recipes" / "campaign_gap_heuristic.yaml")
    assert r.name == "gap-heuristic" and r.strategy == "adaptive" and r.runs == 200
    assert r.entries[0].levels == tuple(range(1, 11)) and dict(r.entries[0].choices)["n_people"] == (0, 2)
    assert r.system == {"policy": "worldgen.envs.policies:GapHeuristic.for_env"}
