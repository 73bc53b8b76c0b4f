"""The navigation environment at a difficulty level: every episode's world drawn at the level asked for."""

from __future__ import annotations

import pytest
from support.envs import ENV_ID, gymnasium

import worldgen
from worldgen.errors import ParameterError


def test_every_episode_is_a_world_at_the_level_asked_for():
    env = gymnasium.make(ENV_ID, generator="cluttered", difficulty="3/10").unwrapped
    for seed in range(3):
        _, info = env.reset(seed=seed)
        world = worldgen.generate("cluttered", info["world_seed"], difficulty="3/10")
        assert info["world_id"] == world.world_id and world.metadata["metrics"]["difficulty_level"] == 3


@pytest.mark.parametrize("kwargs, message", [
    ({"generator": "cluttered", "difficulty": "12/10"}, "parameter 'difficulty' must be a level 'k/10'"),
    ({"generator": "minimal", "difficulty": "3/10"}, "parameter 'difficulty' is offered by the generators barn, cluttered, corridor, door, terrain, not by 'minimal'"),
])
def test_a_bad_level_fails_when_the_env_is_made(kwargs, message):
    with pytest.raises(ParameterError, match=message):
        gymnasium.make(ENV_ID, **kwargs)
