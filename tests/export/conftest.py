"""The ROS 2 bundle tests' shared world (test_ros2*.py): two tasks, written with its bundle (one per test module)."""

import pytest
from support.bundle import bundle_world


@pytest.fixture(scope="module")
def world():
    return bundle_world()


@pytest.fixture(scope="module")
def folder(world, tmp_path_factory):
    return world.write(tmp_path_factory.mktemp("ros"), ros=True)
