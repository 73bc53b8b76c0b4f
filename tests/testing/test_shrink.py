"""worldgen.shrink: the smallest failing world, written and honest about where it came from."""

import json

import pytest

import worldgen
from worldgen.errors import ParameterError
from worldgen.export import metadata


@pytest.fixture(scope="module")
def busy():
    return worldgen.generate("cluttered", seed=3, size=[10, 10], n_obstacles=30, n_movers=1)


def obstacles(world):
    return [n.name for n in world.scene.nodes if n.role == "obstacle"]


def test_shrinks_to_the_one_obstacle_that_matters(busy, tmp_path):
    culprit = obstacles(busy)[7]
    calls = []

    def still_fails(world):
        calls.append(world)
        return culprit in obstacles(world)

    result = worldgen.shrink(busy, still_fails, tmp_path)
    assert obstacles(result.world) == [culprit] and result.world.scene.movers == ()
    assert len(result.removed) == 30 and result.calls == len(calls) < 60
    assert all(w.feasibility.feasible for w in calls)
    meta = json.loads((result.path / "world.json").read_text())
    metadata.validate(meta)
    assert meta["feasibility"]["feasible"] is True and meta["metrics"]["obstacle_count"] == 1
    assert meta["generator"] == "cluttered" and meta["seed"] == 3
    assert meta["params"] == json.loads(json.dumps(busy.params))  # the original's: check regenerates it
    assert meta["edits"] == [{"op": "remove_mover", "mover": "mover_0"}] + \
        [{"op": "remove", "node": name} for name in sorted(set(obstacles(busy)) - {culprit})]
    assert [e["name"] for e in meta["entities"] if e["role"] == "obstacle"] == [culprit]


def test_keeps_what_the_failure_needs(busy, tmp_path):
    # A failure that needs any three obstacles and the mover keeps exactly those.
    result = worldgen.shrink(busy, lambda w: len(obstacles(w)) >= 3 and len(w.scene.movers) == 1, tmp_path)
    assert len(obstacles(result.world)) == 3 and len(result.world.scene.movers) == 1
    # Reference paths are re-proven for the thinner world: never longer than before.
    assert result.world.feasibility.paths[0].length <= busy.feasibility.paths[0].length + 1e-9


def test_refuses_a_world_that_does_not_fail(busy, tmp_path):
    with pytest.raises(ParameterError, match="parameter 'still_fails' must return True for the world given"):
        worldgen.shrink(busy, lambda w: False, tmp_path)
    with pytest.raises(ParameterError, match="parameter 'max_calls' must be an integer >= 1"):
        worldgen.shrink(busy, lambda w: True, tmp_path, max_calls=0)


def test_a_shrunk_world_passes_worldgen_check(busy, tmp_path):
    """The removals are edits: check regenerates the original, replays them (each re-proved), and finds the same
    bytes. Before shrink recorded its removals as edits, check failed every shrunk world at 'regenerate'."""
    from worldgen.verify import check_folder

    culprits = obstacles(busy)[3:5]
    result = worldgen.shrink(busy, lambda w: set(culprits) <= set(obstacles(w)), tmp_path)
    assert sorted(obstacles(result.world)) == sorted(culprits)
    outcome = check_folder(result.path)
    assert outcome.ok, outcome.line()


def test_refuses_a_world_with_people(tmp_path):
    crowd = worldgen.generate("cluttered", seed=1, size=[10, 10], n_obstacles=4, n_people=2)
    with pytest.raises(ParameterError, match="without people"):
        worldgen.shrink(crowd, lambda w: True, tmp_path)
