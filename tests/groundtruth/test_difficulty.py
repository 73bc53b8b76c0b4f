"""world.json's difficulty score (worldgen.groundtruth.difficulty): its inputs exactly, its model frozen."""

from __future__ import annotations

import json
import math

import pytest

import worldgen
from worldgen.groundtruth import difficulty


def test_path_turning_is_the_sum_of_the_absolute_heading_changes():
    assert difficulty.path_turning([[0, 0], [5, 0]]) == 0.0
    assert difficulty.path_turning([[0, 0], [1, 0], [1, 1]]) == pytest.approx(math.pi / 2)
    # A zigzag turns +45, -90, +90, -45 degrees: 270 in all, though its net heading change is 0.
    assert difficulty.path_turning([[0, 0], [1, 0], [2, 1], [3, 0], [4, 1], [5, 1]]) == pytest.approx(1.5 * math.pi)
    # Repeated points (an arc's zero-length pieces) do not count; a U-turn is pi.
    assert difficulty.path_turning([[0, 0], [1, 0], [1, 0], [0, 0]]) == pytest.approx(math.pi)
    assert difficulty.path_turning([[2, 2]]) == 0.0


def test_level_of_splits_the_unit_interval_in_tenths():
    assert [difficulty.level_of(d) for d in (0.0, 0.099999, 0.1, 0.55, 0.9, 0.999999, 1.0)] == [1, 1, 2, 6, 10, 10, 10]


def test_world_json_carries_the_score_of_its_own_figures():
    world = worldgen.generate("cluttered", 5)
    m = world.metadata["metrics"]
    assert m["difficulty_model"] == difficulty.MODEL_ID == "worldgen.difficulty/1"
    assert 0.0 <= m["difficulty"] <= 1.0 and m["difficulty_level"] == difficulty.level_of(m["difficulty"])
    # The score is a function of world.json alone: read back from the written file, the same figures.
    meta = json.loads(world.to_json())
    again = difficulty.assess(meta)
    assert again["difficulty"] == pytest.approx(m["difficulty"], abs=2e-6)
    f = difficulty.features(meta)
    r = meta["robot"]["radius"]
    assert f["passage_slack"] == pytest.approx(min(m["narrowest_passage"] - 2 * r, difficulty.SLACK_CAP))
    assert f["clearance_slack"] == pytest.approx(m["closest_obstacle_distance_mean"] - r)
    assert f["path_length"] == meta["tasks"][0]["path"]["length"] and f["doors"] == 0.0
    assert f["turning"] == pytest.approx(difficulty.path_turning(meta["tasks"][0]["path"]["waypoints"]))


def test_a_world_without_a_path_has_no_score():
    world = worldgen.generate("cluttered", 0, allow_infeasible=True, infeasible=True)
    m = world.metadata["metrics"]
    assert (m["difficulty"], m["difficulty_level"], m["difficulty_model"]) == (None, None, "worldgen.difficulty/1")


def test_the_frozen_model_orders_empty_rooms_dense_rooms_and_closed_doors():
    def scores(generator, **params):
        return [worldgen.generate(generator, seed, **params).metadata["metrics"]["difficulty"] for seed in range(4)]

    empty, dense = scores("cluttered", n_obstacles=0), scores("cluttered", n_obstacles=40)
    closed, opened = scores("door", state="closed"), scores("door", state="open")
    # Measured under worldgen.difficulty/1: means 0.095, 0.485 and 0.638.
    assert sum(empty) / 4 < sum(dense) / 4 < sum(closed) / 4
    # The same rooms with the doors closed are harder than with them open: the reactive probe cannot push a leaf.
    assert all(c > o for c, o in zip(closed, opened))
    model = difficulty.MODEL
    assert set(model) == {"reactive", "tracker"}
    for c in model.values():
        assert len(c["weight"]) == len(c["mean"]) == len(c["std"]) == len(difficulty.FEATURES)
        assert all(s > 0 for s in c["std"])


def test_sharpest_bend_adds_up_turning_within_the_window():
    square = [[0, 0], [2, 0], [2, 0.5], [0, 0.5]]  # two right angles 0.5 m apart
    assert difficulty.sharpest_bend(square) == pytest.approx(math.pi)
    assert difficulty.sharpest_bend(square, window=0.4) == pytest.approx(math.pi / 2)
    assert difficulty.sharpest_bend([[0, 0], [3, 0]]) == 0.0
