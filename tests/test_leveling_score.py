"""A level request scores a draw from the figures the model reads (worldgen.leveling.score), with no world.json
built, and gets what the world's world.json then says."""

from __future__ import annotations

import pytest

import worldgen
from worldgen.leveling import score

KEYS = ("difficulty", "difficulty_level", "difficulty_model")


@pytest.mark.parametrize("generator, params", [
    ("cluttered", {"n_obstacles": 20, "n_tasks": 3}),
    ("door", {"n_doors": 2, "state": "closed", "n_tasks": 2}),  # every path needs a leaf moved
    ("door", {"n_doors": 1, "state": "open"}),
    ("corridor", {"shape": "U", "n_obstacles": 2}),
    ("barn", {"fill_fraction": 0.2}),
    ("cluttered", {"n_obstacles": 5, "infeasible": True}),  # no path: no score
])
def test_the_score_of_a_world_is_its_world_json_s(generator, params, monkeypatch):
    world = worldgen.generate(generator, seed=1, **params)
    from worldgen.export import metadata, tasks

    def no_world_json(*args, **kwargs):
        raise AssertionError("the score built a piece of world.json")

    with monkeypatch.context() as m:
        m.setattr(metadata, "build", no_world_json)
        m.setattr(tasks, "task_entry", no_world_json)
        got = score(world)
    assert got == {k: world.metadata["metrics"][k] for k in KEYS}
    assert (got["difficulty"] is None) == bool(params.get("infeasible"))
