"""The terrain in the exported files: MuJoCo's ground under sampled points is world.json's height there
(within 1 cm; mj_ray straight down), on every kind of element and on the floor between them; a world with
terrain steps in MuJoCo without warnings; a flat world's MJCF has no trace of it."""

import numpy as np
import pytest
from support.reftools_mujoco import load_and_step

import worldgen
from worldgen.export.mjcf import to_mjcf
from worldgen.scene.terrain import Ramp, Rough, Step

mujoco = pytest.importorskip("mujoco")

#: The agreement the issue asks for between an engine's ground and the model's, m.
TOLERANCE = 0.01


def ground_heights(model, points: np.ndarray, top: float = 5.0) -> np.ndarray:
    """The height of the first thing a ray straight down from ``top`` meets above each point."""
    data = mujoco.MjData(model)
    mujoco.mj_forward(model, data)
    geom = np.zeros(1, dtype=np.int32)
    down = np.array([0.0, 0.0, -1.0])
    return np.array([top - mujoco.mj_ray(model, data, np.array([x, y, top]), down, None, 1, -1, geom)
                     for x, y in points])


@pytest.mark.parametrize("seed", [0, 4])
def test_mujoco_ground_is_world_json_height_at_sampled_points(seed):
    world = worldgen.generate("terrain", seed, size=[12, 12], n_ramps=2, n_kerbs=4, pothole_share=0.5, n_rough=2,
                              rough_amplitude=0.03, n_obstacles=0)
    terrain = world.scene.terrain
    assert {type(e) for e in terrain.elements} == {Ramp, Step, Rough}
    assert any(isinstance(e, Step) and e.height < 0 for e in terrain.elements)  # a pothole cut in the floor
    rng = np.random.default_rng(seed)
    points = [e.to_world(rng.uniform([-e.length / 2, -e.width / 2], [e.length / 2, e.width / 2], (150, 2)))
              for e in terrain.elements]
    points = np.vstack(points + [rng.uniform(-5.8, 5.8, (300, 2))])
    model = mujoco.MjModel.from_xml_string(to_mjcf(world.scene).decode())
    got = ground_heights(model, points)
    want = terrain.heights(points)
    assert np.abs(got - want).max() < TOLERANCE, points[np.argmax(np.abs(got - want))]


def test_a_terrain_world_steps_in_mujoco_without_warnings():
    world = worldgen.generate("terrain", 1, size=[10, 10], n_kerbs=3, pothole_share=1.0)
    load_and_step(world.folder_blobs(formats=["mjcf"])["world.mjcf.xml"], steps=50)


def test_a_flat_world_has_no_terrain_in_its_mjcf():
    xml = to_mjcf(worldgen.generate("cluttered", 0, size=[6, 6], n_obstacles=3).scene).decode()
    assert "terrain_" not in xml and "hfield" not in xml
