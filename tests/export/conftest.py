"""The ROS 2 bundle tests' shared world (test_ros2*.py): two tasks, written with its bundle (one per test
module); the bundle's launch description under stand-ins of ROS's launch API; a `ros2` stand-in on the PATH."""

import pytest
from support.bundle import bundle_world
from support.launch_standins import described, ros2_env


@pytest.fixture(scope="module")
def world():
    return bundle_world()


@pytest.fixture(scope="module")
def folder(world, tmp_path_factory):
    return world.write(tmp_path_factory.mktemp("ros"), ros=True)


@pytest.fixture
def description(folder, world, tmp_path, monkeypatch):
    return described(folder, world.world_id, tmp_path, monkeypatch)


@pytest.fixture
def fake_ros2(tmp_path):
    return ros2_env(tmp_path)
