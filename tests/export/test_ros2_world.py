"""What the ROS 2 bundle says about the world itself: the map nav2 localises in, the robot it ships."""

from __future__ import annotations

import re

import numpy as np
import pytest
from support.reftools_sdf import check_robot_sdf

import worldgen
from worldgen.export import ros2


def _grid(pgm: bytes) -> np.ndarray:
    """A P5 map as (rows, cols) uint8, row 0 at the top, as map_server reads it."""
    magic, cols, rows, maxval, data = pgm.split(maxsplit=4)
    assert magic == b"P5" and maxval == b"255"
    return np.frombuffer(data, dtype=np.uint8).reshape(int(rows), int(cols))


def _leaf_cells(scene, leaf: str, origin, resolution, rows) -> set[tuple[int, int]]:
    """(row, col), row 0 at the top, of the cells the leaf's mid-plane crosses at floor level: points along
    its width, 1 mm apart, through its centre line (the leaf is a box; its local x spans the doorway)."""
    size = scene.node(leaf).shape.size
    m = scene.world_matrix(leaf)
    cells = set()
    for u in np.linspace(-size[0] / 2 + 1e-3, size[0] / 2 - 1e-3, int(size[0] / 1e-3)):
        x, y, _ = (m @ np.array([u, 0.0, 0.0, 1.0]))[:3]
        col, row = int((x - origin[0]) // resolution), int((y - origin[1]) // resolution)
        cells.add((rows - 1 - row, col))
    return cells


@pytest.mark.parametrize("state", ["closed", "ajar"])
def test_nav2_gets_the_map_of_the_doors_as_they_start(state, tmp_path):
    """map.pgm (ground truth of the planning scene) draws each leaf open; the bundle's map draws it where
    it starts, and nav2's map_server and the launch file point at the bundle's."""
    world = worldgen.generate("door", seed=4, state=state, angle=0.5)
    folder = world.write(tmp_path, ros=True)
    meta = world.metadata
    [door] = meta["doors"]
    assert door["state"] == state
    mine, truth = _grid((folder / "ros2" / "map.pgm").read_bytes()), _grid((folder / "map.pgm").read_bytes())
    assert mine.shape == truth.shape and (folder / "ros2" / "map.yaml").read_text() == (
        folder / "map.yaml").read_text()  # same origin, resolution, thresholds; image: map.pgm beside it
    res, origin = meta["occupancy"]["resolution"], meta["occupancy"]["origin"]
    cells = _leaf_cells(world.scene, door["name"], origin, res, mine.shape[0])
    assert cells and all(mine[r, c] == 0 for r, c in cells)  # every cell under the starting leaf occupied
    assert any(truth[r, c] == 254 for r, c in cells)  # which map.pgm leaves free: the leaf is open there
    # Everything else is map.pgm's: the maps differ only within the leaf's reach of its hinge.
    rows, cols = np.nonzero(mine != truth)
    hx, hy = door["hinge"][:2]
    centre_x = origin[0] + (cols + 0.5) * res
    centre_y = origin[1] + (mine.shape[0] - 1 - rows + 0.5) * res
    assert len(rows) and np.all(np.hypot(centre_x - hx, centre_y - hy) <= door["width"] + res)
    overrides = ros2.nav2_overrides(world, world.tasks[0])
    assert overrides["map_server"]["ros__parameters"]["yaml_filename"] == "ros2/map.yaml"
    launch = next((folder / "ros2" / "launch").glob("*.launch.py")).read_text()
    assert "MAP = 'ros2/map.yaml'" in launch


def test_a_world_whose_doors_start_open_keeps_the_worlds_map(tmp_path):
    open_world = worldgen.generate("door", seed=4, state="open")
    plain = worldgen.generate("cluttered", seed=7, size=[6, 6], n_obstacles=6)
    for world in (open_world, plain):
        files = ros2.bundle(world)
        assert "ros2/map.pgm" not in files and "ros2/map.yaml" not in files
        assert ros2.nav2_overrides(world, world.tasks[0])["map_server"]["ros__parameters"]["yaml_filename"] == "map.yaml"


@pytest.mark.parametrize("release", ["fortress", "harmonic"])
def test_the_shipped_robot_publishes_what_the_bridge_takes(release, tmp_path):
    world = worldgen.generate("cluttered", seed=7, size=[6, 6], n_obstacles=6)
    files = ros2.bundle(world, gz_release=release, robot_name="bot-1")
    sdf = files["ros2/robot.sdf"].decode()
    path = tmp_path / "robot.sdf"
    path.write_text(sdf)
    ok, messages = check_robot_sdf(path)
    assert ok, messages
    assert '<model name="bot_1">' in sdf and "<robot name=\"bot_1\"" in files["ros2/robot.urdf"].decode()
    prefix = "ignition-gazebo-" if release == "fortress" else "gz-sim-"
    assert f'filename="{prefix}diff-drive-system"' in sdf
    named = set(re.findall(r"<(?:topic|odom_topic|tf_topic)>([^<]+)<", sdf))
    world_topics = {"/clock", "/contacts"}  # the world's, not the robot's
    for entry in ros2.bridge_config(release):
        if entry["gz_topic_name"] not in world_topics:
            assert entry["gz_topic_name"].lstrip("/") in {t.lstrip("/") for t in named}, entry
