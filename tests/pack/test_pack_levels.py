"""Recipes by difficulty level: levels x worlds per level, in order, each world's level in the manifest."""

from __future__ import annotations

import json
import textwrap

import pytest

from worldgen.errors import ParameterError
from worldgen.pack import build_pack, parse_recipe, verify_pack

LADDER = """\
name: ladder
formats: [sdf]
worlds:
  - generator: cluttered
    params:
      size: [6, 6]
    difficulty:
      levels: [1, 4]
      worlds_per_level: 2
  - generator: corridor
    seeds: {start: 5, count: 1}
    difficulty:
      levels: {min: 6, max: 7}
"""


def parse(text: str):
    return parse_recipe(textwrap.dedent(text), "r.yaml", "r")


def test_levels_times_worlds_per_level_in_order_each_a_request():
    r = parse(LADDER)
    assert [(j.generator, j.level, j.seed) for j in r.jobs] == [
        ("cluttered", 1, 0), ("cluttered", 1, 1), ("cluttered", 4, 0), ("cluttered", 4, 1),
        ("corridor", 6, 5), ("corridor", 7, 5)]
    assert len({j.key for j in r.jobs}) == len(r)
    # A job without a level keeps the key it had before levels existed (resumed packs stay valid).
    plain = parse("seeds: 1\nworlds:\n  - generator: minimal\n").jobs[0]
    assert plain.level is None and len(plain.key) == 20


@pytest.mark.parametrize("text, line, words", [
    ("seeds: 1\nworlds:\n  - generator: cluttered\n    dificulty: {levels: [1]}\n", 4,
     ["'dificulty'", "did you mean 'difficulty'?"]),
    ("worlds:\n  - generator: cluttered\n    difficulty: {levels: [1], world_per_level: 3}\n", 3,
     ["'world_per_level'", "did you mean 'worlds_per_level'?", "allowed: levels, worlds_per_level"]),
    ("worlds:\n  - generator: cluttered\n    difficulty: {worlds_per_level: 3}\n", 3, ["needs 'levels'"]),
    ("worlds:\n  - generator: cluttered\n    difficulty:\n      levels: [0, 11]\n", 4,
     ["key 'levels'", "distinct levels 1..10"]),
    ("worlds:\n  - generator: cluttered\n    seeds: 2\n    difficulty:\n      levels: [1]\n      worlds_per_level: 3\n", 6,
     ["key 'worlds_per_level'", "give one or the other"]),
    ("worlds:\n  - generator: door\n    difficulty:\n      levels: [1, 2]\n      worlds_per_level: 1\n", 4,
     ["key 'difficulty'", "1/10 is out of reach of 'door': it reaches levels 2-10"]),
    ("worlds:\n  - generator: cluttered\n    params:\n      n_obstacles: 5\n    difficulty: {levels: [3], worlds_per_level: 1}\n",
     5, ["key 'difficulty'", "sets n_obstacles itself; leave out 'n_obstacles'"]),
    ("worlds:\n  - generator: minimal\n    difficulty: {levels: [3], worlds_per_level: 1}\n", 3,
     ["key 'difficulty'", "not by 'minimal'"]),
])
def test_each_mistake_is_one_line_naming_the_key_and_line(text, line, words):
    with pytest.raises(ParameterError) as info:
        parse(text)
    message = str(info.value)
    assert "\n" not in message and message.startswith(f"r.yaml:{line}:"), message
    for w in words:
        assert w in message, message


def test_the_manifest_records_each_worlds_level_and_the_pack_verifies(tmp_path):
    out = tmp_path / "ladder"
    summary = build_pack(parse(LADDER), out, jobs=1)
    assert summary.built == 6, summary
    manifest = json.loads((out / "manifest.json").read_text())
    assert [w["level"] for w in manifest["worlds"]] == [1, 1, 4, 4, 6, 7]
    for w in manifest["worlds"]:
        folder = f"L{w['level']}-r{w['request_seed']}--{w['world_id']}"  # the level and request seed, then the id
        meta = json.loads((out / "worlds" / folder / "world.json").read_text())
        assert meta["metrics"]["difficulty_level"] == w["level"]
        # The world's own seed is the draw that landed; the request's seed is kept beside it.
        assert meta["seed"] == w["seed"] and meta["difficulty_request"]["seed"] == w["request_seed"]
    assert all(ok for ok, _ in verify_pack(out, regenerate=True))


def test_a_pack_by_levels_filters_and_counts_by_level(tmp_path):
    """index.csv, `pack ls --where` and `pack info` know the level (was: 'difficulty_level' an unknown metric)."""
    import csv

    from support.cli import run

    out = tmp_path / "ladder"
    build_pack(parse(LADDER), out, jobs=1)
    with (out / "index.csv").open() as f:
        rows = list(csv.DictReader(f))
    assert [(r["level"], r["difficulty_level"]) for r in rows] == [(str(k), str(k)) for k in (1, 1, 4, 4, 6, 7)]
    manifest = json.loads((out / "manifest.json").read_text())
    assert [r["request_seed"] for r in rows] == [str(w["request_seed"]) for w in manifest["worlds"]]
    listed = run("pack", "ls", out, "--where", "difficulty_level >= 5")
    assert listed.returncode == 0, listed.stderr
    assert [line.split("\t")[1] for line in listed.stdout.splitlines()] == [w["world_id"] for w in manifest["worlds"][4:]]
    assert all(line.endswith(("difficulty_level=6", "difficulty_level=7")) for line in listed.stdout.splitlines())
    info = run("pack", "info", out)
    assert info.returncode == 0 and "difficulty levels: 1: 2, 4: 2, 6: 1, 7: 1" in info.stdout.splitlines()
    assert "asked for by level: 6 worlds at levels 1, 4, 6, 7" in info.stdout.splitlines()
    assert "  difficulty_level: min 1, max 7" in info.stdout.splitlines()
