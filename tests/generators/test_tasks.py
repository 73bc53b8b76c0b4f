"""Every generator writes as many tasks as its parameters say, or refuses the request: never a silent drop."""

from __future__ import annotations

import pytest

import worldgen
from worldgen.errors import ParameterError


@pytest.mark.parametrize("generator", ["corridor", "minimal"])
def test_one_task_generators_refuse_more_tasks_instead_of_dropping_them(generator):
    with pytest.raises(ParameterError, match=r"^parameter 'n_tasks' must be exactly 1, got 3$"):
        worldgen.generate(generator, 0, n_tasks=3)


@pytest.mark.parametrize("generator", ["cluttered", "door"])
def test_generators_write_as_many_tasks_as_asked(generator):
    world = worldgen.generate(generator, 1, n_tasks=3)
    assert len(world.tasks) == world.params["n_tasks"] == 3 == len(world.metadata["tasks"])
