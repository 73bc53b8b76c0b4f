"""The difficulty score in terrain worlds (worldgen.groundtruth.difficulty, docs/metrics.md): scored with the
terrain's terms and named for it, from world.json alone, the same figure a level request scores; flat worlds
keep the flat model (their bytes: tests/test_golden_bytes.py)."""

from __future__ import annotations

import json
import math

import pytest
from support.terrain import ramp_world

import worldgen
from worldgen import leveling
from worldgen.groundtruth import difficulty


@pytest.fixture(scope="module")
def world():
    return ramp_world()


def test_a_terrain_world_is_scored_with_the_terrain_terms_from_world_json_alone(world):
    meta = json.loads(world.to_json())
    m = meta["metrics"]
    assert m["difficulty_model"] == difficulty.TERRAIN_MODEL_ID
    f = difficulty.features(meta)
    (ramp,) = world.scene.terrain.elements
    # The straight path crosses the ramp: up, along the landing, down; a 7 x 3 m room.
    assert f["largest_incline"] == pytest.approx(math.atan2(ramp.rise, ramp.run), abs=1e-6)
    assert f["largest_step"] == meta["tasks"][0]["terrain"]["largest_step"]
    assert f["terrain_share"] == pytest.approx(ramp.length / meta["tasks"][0]["path"]["length"], abs=0.05)
    assert f["terrain_cover"] == pytest.approx(ramp.length * ramp.width / 21.0)
    assert m["difficulty"] == round(difficulty.score(f), 6) and m["difficulty_level"] == difficulty.level_of(m["difficulty"])
    # The terms count: the flat model alone gives another score.
    flat = sum(difficulty.probe_chance(f, c) for c in difficulty.MODEL.values()) / len(difficulty.MODEL)
    assert abs(flat - m["difficulty"]) > 1e-3
    assert leveling.score(world) == {k: m[k] for k in ("difficulty", "difficulty_level", "difficulty_model")}


def test_terrain_off_the_path_still_counts_and_a_flat_world_keeps_the_flat_model():
    flat = worldgen.generate("cluttered", 0, size=[8, 8], n_obstacles=4)
    assert flat.metadata["metrics"]["difficulty_model"] == difficulty.MODEL_ID
    assert not difficulty.has_terrain(difficulty.features(flat.metadata))
    rough = worldgen.generate("cluttered", 0, size=[8, 8], n_obstacles=4, terrain=True)
    assert rough.metadata["metrics"]["difficulty_model"] == difficulty.TERRAIN_MODEL_ID
    f = difficulty.features(rough.metadata)
    assert difficulty.has_terrain(f) and f["terrain_cover"] > 0
