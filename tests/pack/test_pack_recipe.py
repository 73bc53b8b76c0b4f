"""Recipe parsing: grids, sampled ranges, seeds, presets, physics axes, and every one-line error."""

from __future__ import annotations

import textwrap

import pytest

from worldgen.errors import ParameterError, WorldgenError
from worldgen.pack.recipe import parse_recipe

BASE = """\
seeds: 3
worlds:
  - generator: cluttered
    params:
      size: [6, 6]
      n_obstacles: [3, 5]
      clearance: {min: 0.05, max: 0.1}
      box_size: [[0.3, 0.6], [0.5, 1.0]]
    physics:
      friction: [0.5, 1.0]
"""


def parse(text: str):
    return parse_recipe(textwrap.dedent(text), "r.yaml", "r")


def test_grid_ranges_and_seeds_make_the_product_in_a_fixed_order():
    r = parse(BASE)
    assert len(r) == 2 * 2 * 2 * 3  # box_size x friction x n_obstacles x seeds
    first = r.jobs[0].param_dict
    assert first["size"] == (6, 6) and first["box_size"] == (0.3, 0.6)
    assert first["friction"] == 0.5 and first["n_obstacles"] == 3
    assert [j.seed for j in r.jobs[:4]] == [0, 1, 2, 0]
    # Axes vary by sorted name, the last fastest: n_obstacles changes before friction.
    assert r.jobs[3].param_dict["n_obstacles"] == 5 and r.jobs[3].param_dict["friction"] == 0.5
    assert r.jobs[6].param_dict["friction"] == 1.0
    assert len({j.key for j in r.jobs}) == len(r)
    assert r.name == "r" and r.formats == ("sdf", "mjcf", "urdf") and r.preview is False


def test_sampled_values_depend_on_the_seed_only_and_stay_in_range():
    a, b = parse(BASE), parse(BASE)
    values = [j.param_dict["clearance"] for j in a.jobs]
    assert values == [j.param_dict["clearance"] for j in b.jobs]
    assert all(0.05 <= v <= 0.1 for v in values)
    by_seed = {}
    for j in a.jobs:  # the same seed in another grid point draws the same value
        by_seed.setdefault(j.seed, set()).add(j.param_dict["clearance"])
    assert all(len(v) == 1 for v in by_seed.values()) and len({min(v) for v in by_seed.values()}) == 3
    ints = parse("seeds: 20\nworlds:\n  - generator: cluttered\n    params: {n_obstacles: {min: 2, max: 4}}\n")
    drawn = {j.param_dict["n_obstacles"] for j in ints.jobs}
    assert drawn == {2, 3, 4}


@pytest.mark.parametrize("seeds, expected", [
    ("4", [0, 1, 2, 3]),
    ("{start: 10, count: 3}", [10, 11, 12]),
    ("{min: 5, max: 7}", [5, 6, 7]),
])
def test_seed_forms(seeds, expected):
    r = parse(f"seeds: {seeds}\nworlds:\n  - generator: minimal\n")
    assert [j.seed for j in r.jobs] == expected


def test_preset_entry_options_and_per_entry_seeds():
    r = parse("""\
        name: mixed-1
        formats: [mjcf]
        sdf_version: "1.6"
        preview: true
        seeds: 2
        worlds:
          - preset: narrow_corridor
            seeds: {start: 7, count: 1}
          - generator: minimal
        """)
    assert r.name == "mixed-1" and r.formats == ("mjcf",) and r.sdf_version == "1.6" and r.preview
    assert [(j.generator, j.seed, j.entry) for j in r.jobs] == [("corridor", 7, 0), ("minimal", 0, 1), ("minimal", 1, 1)]
    assert r.jobs[0].param_dict  # the preset's params come along


@pytest.mark.parametrize("text, line, words", [
    ("worlds:\n  - generator: cluttered\n    colour: red\n", 3, ["'colour'", "unknown key"]),
    ("seeds: 2\nfoo: 1\nworlds: []\n", 2, ["'foo'", "allowed"]),
    ("seeds: 2\nworlds: []\n", 2, ["'worlds'", "non-empty"]),
    ("seeds: 2\n", 1, ["'worlds'", "missing"]),
    ("seeds: 0\nworlds:\n  - generator: minimal\n", 1, ["'seeds'", "count"]),
    ("seeds: {start: -1, count: 2}\nworlds:\n  - generator: minimal\n", 1, ["'seeds'"]),
    ("seeds: abc\nworlds:\n  - generator: minimal\n", 1, ["'seeds'"]),
    ("worlds:\n  - generator: minimal\n", 2, ["no 'seeds'"]),
    ("seeds: 1\nworlds:\n  - generator: nosuch\n", 3, ["'generator'", "nosuch"]),
    ("seeds: 1\nworlds:\n  - preset: nosuch\n", 3, ["'preset'", "nosuch"]),
    ("seeds: 1\nworlds:\n  - generator: minimal\n    preset: drl_arena\n", 3, ["exactly one"]),
    ("seeds: 1\nworlds:\n  - generator: cluttered\n    params:\n      wobble: 3\n", 5, ["'wobble'", "unknown parameter"]),
    ("seeds: 1\nworlds:\n  - generator: cluttered\n    params:\n      n_obstacle: 3\n", 5,
     ["'n_obstacle'", "unknown parameter of generator 'cluttered' (did you mean 'n_obstacles'?); known: "]),
    ("sead: 2\nworlds: []\n", 1, ["'sead'", "unknown key in recipe (did you mean 'seeds'?); allowed: "]),
    ("seeds: 1\nworlds:\n  - generator: cluttered\n    params:\n      size: [6, 6]\n      n_obstacles: -4\n", 6,
     ["'n_obstacles'"]),
    ("seeds: 1\nworlds:\n  - generator: cluttered\n    params:\n      n_obstacles: [3, 9999999]\n", 5,
     ["'n_obstacles'"]),
    ("seeds: 1\nworlds:\n  - generator: cluttered\n    params:\n      clearance: {min: 0.2, max: 0.1}\n", 5,
     ["'clearance'", "min <= max"]),
    ("seeds: 1\nworlds:\n  - generator: cluttered\n    params:\n      n_obstacles: {min: 1.5, max: 3}\n", 5,
     ["'n_obstacles'", "integer"]),
    ("seeds: 1\nworlds:\n  - generator: cluttered\n    params:\n      clearance: {lo: 0.1}\n", 5, ["'clearance'", "min, max"]),
    ("seeds: 1\nworlds:\n  - generator: cluttered\n    params:\n      clearance: []\n", 5, ["'clearance'", "at least one"]),
    ("seeds: 1\nworlds:\n  - generator: cluttered\n    physics:\n      size: [4, 8]\n", 5, ["'size'", "allowed"]),
    ("seeds: 1\nworlds:\n  - generator: cluttered\n    physics:\n      friction: [1.0, -2]\n", 5, ["'friction'"]),
    ("seeds: 1\nformats: [sdf, obj]\nworlds:\n  - generator: minimal\n", 2, ["'formats'"]),
    ("seeds: 1\nsdf_version: '2.0'\nworlds:\n  - generator: minimal\n", 2, ["'sdf_version'"]),
    ("seeds: 1\npreview: maybe\nworlds:\n  - generator: minimal\n", 2, ["'preview'"]),
    ("seeds: 1\nname: 'a/b'\nworlds:\n  - generator: minimal\n", 2, ["'name'"]),
    ("seeds: 1\nworlds:\n  - generator: minimal\n  - generator: minimal\n    params: [1, 2]\n", 5, ["mapping"]),
    ("seeds: [1\nworlds: x\n", 2, ["not valid YAML"]),
    ("seeds: !!python/object:os.system 1\nworlds:\n  - generator: minimal\n", 1, ["python/object"]),
])
def test_each_mistake_is_one_line_naming_the_key_and_line(text, line, words):
    with pytest.raises(ParameterError) as info:
        parse(text)
    message = str(info.value)
    assert "\n" not in message
    assert message.startswith(f"r.yaml:{line}:"), message
    for w in words:
        assert w in message, message
    assert isinstance(info.value, WorldgenError)


# -- files that are not a readable text recipe: one line, exit 2, nothing written ------------

def _unreadable(tmp_path):
    """A path that exists but cannot be read: mode 000 for a normal user, a socket for root
    (root reads any file whatever its mode; no process reads a unix socket as a file)."""
    import os
    import socket

    path = tmp_path / "recipe.yaml"
    if os.geteuid() != 0:
        path.write_text("worlds: []\n")
        path.chmod(0)
        return path
    sock = socket.socket(socket.AF_UNIX)
    sock.bind(str(path))
    return path


@pytest.mark.parametrize("kind,message", [
    ("binary", r"recipe file '.*recipe.yaml' is not UTF-8 text \(byte 0x89 at offset 0\); is it a binary file\?$"),
    ("latin1", r"recipe file '.*recipe.yaml' is not UTF-8 text \(byte 0xe9 at offset 19\); is it a binary file\?$"),
    ("nul", r"recipe file '.*recipe.yaml' is not text \(it holds NUL bytes\); is it a binary file\?$"),
    ("directory", r"recipe file '.*recipe.yaml' is a directory, not a file$"),
    ("missing", r"recipe file '.*recipe.yaml' does not exist$"),
    ("unreadable", r"recipe file '.*recipe.yaml' cannot be read: .+$"),
])
def test_a_recipe_that_is_not_readable_text_is_one_line_and_exit_2(tmp_path, kind, message):
    import re

    from support.cli import run

    path = tmp_path / "recipe.yaml"
    if kind == "binary":
        path.write_bytes(b"\x89PNG\r\n\x1a\n" + bytes(range(256)))
    elif kind == "latin1":
        path.write_bytes("worlds:\n  - {n: caf\u00e9}\n".encode("latin-1"))
    elif kind == "nul":
        path.write_bytes(b"worlds: []\n\x00\x00")
    elif kind == "directory":
        path.mkdir()
    elif kind == "unreadable":
        path = _unreadable(tmp_path)
    out = tmp_path / "pack"
    result = run("pack", "build", path, "--out", out)
    assert result.returncode == 2, result.stderr
    lines = result.stderr.strip().splitlines()
    assert len(lines) == 1 and "Traceback" not in result.stderr, result.stderr
    assert re.search(message, lines[0]), lines[0]
    assert not out.exists()


def test_a_huge_quoted_value_is_cut_to_a_readable_length():
    huge = "x" * 100_000
    with pytest.raises(ParameterError) as err:
        parse_recipe(f"name: {huge}\nworlds:\n  - generator: minimal\n", "r.yaml")
    message = str(err.value)
    assert "\n" not in message and len(message) < 200
    assert message.endswith("got '" + "x" * 76 + "... (100002 characters)")
    with pytest.raises(ParameterError) as err:
        parse_recipe(f"worlds:\n  - generator: cluttered\n    params: {{size: [{', '.join(['1.0'] * 20000)}]}}\n", "r.yaml")
    assert len(str(err.value)) < 300, str(err.value)[:400]


def test_quoted_leaves_short_values_alone():
    from worldgen.errors import QUOTE_LIMIT, quoted

    assert quoted("short") == "'short'" and quoted([1, 2]) == "[1, 2]"
    long = quoted(list(range(1000)))
    assert long == repr(list(range(1000)))[:QUOTE_LIMIT - 3] + "... (4890 characters)"
