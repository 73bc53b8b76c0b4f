"""Worlds at a requested difficulty level (worldgen.leveling): in the level, deterministic, recorded, regenerable."""

from __future__ import annotations

import json

import pytest
from support.cli import run, world_dirs

import worldgen
from worldgen.errors import ParameterError
from worldgen.export import metadata
from worldgen.generators.registry import all_specs
from worldgen.leveling import reachable
from worldgen.seeding import level_seed


def test_a_world_asked_for_at_a_level_is_at_that_level_and_says_how_it_got_there():
    world = worldgen.generate("cluttered", seed=3, difficulty="7/10")
    meta = world.metadata
    assert meta["metrics"]["difficulty_level"] == 7 and 0.6 <= meta["metrics"]["difficulty"] < 0.7
    req = meta["difficulty_request"]
    assert (req["level"], req["seed"], req["knob"]) == ("7/10", 3, "n_obstacles")
    draws = req["draws"]
    assert [d["seed"] for d in draws] == [level_seed(3, k) for k in range(len(draws))]
    assert [d["level"] for d in draws][-1] == 7 and 7 not in [d["level"] for d in draws[:-1]]
    last = draws[-1]
    assert (world.seed, world.params["n_obstacles"], meta["metrics"]["difficulty"]) == \
        (last["seed"], last["n_obstacles"], last["difficulty"])
    metadata.validate(meta)
    # An ordinary world: its seed and params regenerate it without the request.
    again = worldgen.generate("cluttered", world.seed, **{k: world.params[k] for k in ("n_obstacles",)})
    assert again.content_hash == world.content_hash and "difficulty_request" not in again.metadata


@pytest.mark.parametrize("level", [1, 4, 9])
def test_levels_across_the_range_land(level):
    world = worldgen.generate("cluttered", seed=0, difficulty=f"{level}/10")
    assert world.metadata["metrics"]["difficulty_level"] == level


def test_the_same_request_gives_the_same_world_from_the_cli_in_another_process(tmp_path):
    done = run("generate", "cluttered", "--difficulty", "7/10", "--seed", "3", "--out", tmp_path)
    assert done.returncode == 0, done.stderr
    (folder,) = world_dirs(tmp_path)
    meta = json.loads((folder / "world.json").read_text())
    assert meta["world_id"] == worldgen.generate("cluttered", seed=3, difficulty="7/10").world_id
    # The folder and the summary line say the level and the request's seed (the world's own seed is the
    # draw that landed, 19 digits), and every draw the request took (was 'attempts 1' after 9 draws).
    draws = len(meta["difficulty_request"]["draws"])
    assert folder.name == f"L7-r3--{meta['world_id']}"
    assert done.stdout == f"{folder}\tpath {meta['tasks'][0]['path']['length']:.3f} m\tlevel 7/10, request seed 3" \
                          f"\tdraws {draws}\tattempts 1\n"  # and the attempts of the draw that landed
    assert meta["metrics"]["difficulty_level"] == 7 and meta["difficulty_request"]["level"] == "7/10"
    checked = run("check", folder)  # a received world at a level re-verifies, its request included
    assert checked.returncode == 0, checked.stdout + checked.stderr


PEOPLE = {"n_people": 4, "people_duration": 20.0}


def test_a_level_with_people_walks_them_once_per_landed_draw_and_is_the_same_in_another_process(tmp_path, monkeypatch):
    from worldgen.people import crowd

    walks = []
    walk_plan = crowd.walk_plan
    monkeypatch.setattr(crowd, "walk_plan", lambda *a, **k: walks.append(1) or walk_plan(*a, **k))
    world = worldgen.generate("cluttered", seed=3, difficulty="6/10", **PEOPLE)
    draws = world.metadata["difficulty_request"]["draws"]
    assert len(draws) == 9 and len(walks) == 1  # nine draws judged without people, the people walked on the last
    assert world.metadata["metrics"]["difficulty_level"] == 6 and len(world.metadata["people"]) == 4
    # Regenerable like any world: its own seed and params (people included) give it without the request.
    assert worldgen.generate("cluttered", world.seed, **world.params).content_hash == world.content_hash
    done = run("generate", "cluttered", "--difficulty", "6/10", "--seed", "3", *(f"--set={k}={v}" for k, v in
                                                                                  PEOPLE.items()), "--out", tmp_path)
    assert done.returncode == 0, done.stderr
    assert done.stdout.rstrip().endswith("level 6/10, request seed 3\tdraws 9\tattempts 1"), done.stdout
    (folder,) = world_dirs(tmp_path)
    assert (folder / "world.json").read_bytes() == world.read("world.json")
    checked = run("check", folder)
    assert checked.returncode == 0, checked.stdout + checked.stderr


@pytest.mark.parametrize("generator, params, message", [
    ("cluttered", {"difficulty": "11/10"}, "parameter 'difficulty' must be a level 'k/10' with k in 1..10 (or the integer k), got '11/10'"),
    ("cluttered", {"difficulty": "3/5"}, "parameter 'difficulty' must be a level 'k/10'"),
    ("cluttered", {"difficulty": "7/10", "n_obstacles": 5}, "parameter 'difficulty' sets n_obstacles itself; leave out 'n_obstacles'"),
    ("minimal", {"difficulty": "2/10"}, "parameter 'difficulty' is offered by the generators barn, cluttered, corridor, door, terrain, "
     "not by 'minimal' (it has no random draws"),
    ("door", {"difficulty": "1/10"}, "parameter 'difficulty' 1/10 is out of reach of 'door': it reaches levels 2-10"),
    ("corridor", {"difficulty": "7/10", "shape": "U"}, "parameter 'difficulty' sets n_obstacles and shape itself; "
     "leave out 'shape'"),
    ("door", {"difficulty": "7/10", "state": "open"}, "parameter 'difficulty' sets n_doors and state itself"),
])
def test_bad_requests_are_one_line(generator, params, message):
    with pytest.raises(ParameterError) as err:
        worldgen.generate(generator, 0, **params)
    assert message in str(err.value) and "\n" not in str(err.value)


def test_the_cli_refuses_a_bad_level_with_exit_2(tmp_path):
    done = run("generate", "cluttered", "--difficulty", "0/10", "--out", tmp_path)
    assert done.returncode == 2 and done.stderr.strip().splitlines()[-1].startswith("error: parameter 'difficulty'")
    assert world_dirs(tmp_path) == []


@pytest.mark.parametrize("generator, level, knob, sets", [
    ("corridor", 2, "n_obstacles", {"shape": "straight"}),
    ("corridor", 7, "n_obstacles", {"shape": "L"}),
    ("corridor", 10, "n_obstacles", {"shape": "U"}),
    ("door", 3, "n_doors", {"state": "open"}),
    ("door", 10, "n_doors", {"state": "closed"}),
])
def test_other_generators_land_in_the_level_with_what_the_level_sets(generator, level, knob, sets):
    world = worldgen.generate(generator, seed=1, difficulty=level)
    assert world.metadata["metrics"]["difficulty_level"] == level
    assert world.difficulty_request["knob"] == knob and world.params[knob] == world.difficulty_request["draws"][-1][knob]
    assert {k: world.params[k] for k in sets} == sets


def test_every_generator_has_its_levels_or_says_why_not():
    for spec in all_specs():
        assert (spec.knob is not None) != bool(spec.no_levels), spec.name
    assert reachable("cluttered") == tuple(range(1, 11)) and reachable("door") == tuple(range(2, 11))
    assert reachable("minimal") == ()


@pytest.mark.parametrize("generator, line", [
    ("cluttered", "difficulty: levels 1-10 of 10 (--difficulty K/10 turns n_obstacles)"),
    ("door", "difficulty: levels 2-10 of 10 (--difficulty K/10 turns n_doors; sets state by level)"),
    ("minimal", "difficulty: no levels (it has no random draws"),
])
def test_list_says_which_levels_a_generator_reaches(generator, line):
    done = run("list", generator)
    assert done.returncode == 0 and line in " ".join(done.stdout.split())  # wrapped to the terminal


def test_a_level_with_reacting_people_is_certified_against_their_tubes(monkeypatch):
    """The people added to a landed draw are certified as generate certifies them, against their tubes (they were
    certified against the recorded lines only)."""
    from worldgen.people import timed

    seen = []
    certify = timed.certify
    monkeypatch.setattr(timed, "certify", lambda *a, **k: seen.append(a[5:] + tuple(k.values())) or certify(*a, **k))
    world = worldgen.generate("cluttered", seed=3, difficulty="4/10", n_people=3, people_duration=20.0,
                              people_behaviour="regular")
    assert {p.get("behaviour") for p in world.metadata["people"]} == {"regular"}
    assert seen and all(args and list(args[-1]) == ["regular"] * 3 for args in seen), seen  # behaviours given
    again = worldgen.generate("cluttered", world.seed, **world.params)
    assert again.metadata["tasks"] == world.metadata["tasks"]
