"""The same worlds, byte for byte: every file of 49 worlds across generators, presets, movers and SDF
versions, pinned by digest. A refactor must leave them alone; a change that alters a world on purpose
updates the pins in the same commit, saying why (``WORLDGEN_UPDATE_GOLDEN=1 pytest tests/test_golden_bytes.py``)."""

from __future__ import annotations

import hashlib
import json
import os
from pathlib import Path

import pytest

import worldgen

PINS = Path(__file__).resolve().parent / "support" / "golden_worlds.json"
SMALL = {"cluttered": {"size": [8.0, 8.0], "n_obstacles": 10}, "corridor": {"length": 8.0},
         "door": {}, "minimal": {}}
#: (label, generator or preset, seed, params, write options)
CASES = [(f"{g}-s{s}", g, s, SMALL[g], {}) for g in SMALL for s in range(9)]
CASES += [
    ("cluttered-movers", "cluttered", 3, dict(SMALL["cluttered"], n_movers=2), {}),
    ("cluttered-movers-no-actors", "cluttered", 3, dict(SMALL["cluttered"], n_movers=2, sdf_actors=False), {}),
    ("corridor-sdf16", "corridor", 1, {"shape": "L"}, {"sdf_version": "1.6"}),
    ("door-mjcf-only", "door", 4, {}, {"formats": ["mjcf"]}),
    ("preset-empty_room", "@empty_room", 0, {}, {}),
    ("preset-narrow_corridor", "@narrow_corridor", 2, {}, {}),
    ("preset-lidar_wall", "@lidar_wall", 0, {}, {}),
    ("cluttered-infeasible", "cluttered", 5, dict(SMALL["cluttered"], infeasible=True), {}),
    ("door-ajar", "door", 6, {"state": "ajar"}, {}),
    ("corridor-zigzag", "corridor", 7, {"shape": "zigzag"}, {}),
    ("minimal-cylinder", "minimal", 0, {"target": "cylinder"}, {}),
    ("cluttered-many", "cluttered", 11, {"n_obstacles": 40}, {}),
    ("barn-s0", "barn", 0, {}, {}),
]


def world_of(name: str, seed: int, params: dict):
    if name.startswith("@"):
        from worldgen.presets import generate_preset
        return generate_preset(name[1:], seed=seed, **params)
    return worldgen.generate(name, seed, **params)


def digest(case) -> dict[str, str]:
    _, name, seed, params, options = case
    world = world_of(name, seed, params)
    blobs = world.folder_blobs(**options)
    return {world.folder_name + "/" + rel: hashlib.sha256(data).hexdigest()[:16] for rel, data in sorted(blobs.items())}


def test_the_pinned_worlds_are_byte_for_byte_the_same():
    assert len(CASES) >= 40
    got = {case[0]: digest(case) for case in CASES}
    if os.environ.get("WORLDGEN_UPDATE_GOLDEN"):
        PINS.write_text(json.dumps(got, indent=1, sort_keys=True) + "\n")
        pytest.skip("pins rewritten")
    pinned = json.loads(PINS.read_text())
    changed = {label: sorted(set(files.items()) ^ set(pinned.get(label, {}).items())) for label, files in got.items()
               if files != pinned.get(label)}
    assert not changed, f"{len(changed)} of {len(CASES)} worlds changed; first: {next(iter(changed.items()))}"
