"""The terrain model: heights exact for the analytic elements, the rough patch's gradient bound exact, and
elements that overlap, or that are malformed, refused with one line."""

import math

import numpy as np
import pytest

from worldgen.errors import SceneError
from worldgen.scene import Box, Node, Pose, Scene
from worldgen.scene.terrain import Ramp, Rough, Step, Terrain


def test_a_ramp_rises_over_its_run_holds_its_landing_and_comes_down():
    ramp = Ramp(1.0, 2.0, math.pi / 2, 2.0, 0.2, 1.0, 0.5)  # runs along world y
    assert ramp.length == 2.5
    ys = np.array([0.75, 1.0, 1.25, 1.75, 2.0, 2.25, 2.75, 3.25, 3.3])
    got = ramp.heights(np.column_stack([np.full_like(ys, 1.0), ys]))
    np.testing.assert_allclose(got, [0.0, 0.05, 0.1, 0.2, 0.2, 0.2, 0.1, 0.0, 0.0], atol=1e-12)
    assert ramp.heights(np.array([[2.01, 2.0]]))[0] == 0.0  # beside it: the floor
    assert ramp.incline == pytest.approx(math.degrees(math.atan(0.2)))
    np.testing.assert_allclose(ramp.gradients(np.array([[1.0, 1.0], [1.0, 2.0]])), [0.2, 0.0])


def test_a_step_is_a_plateau_and_a_negative_one_a_pothole():
    kerb, pothole = Step(0, 0, 0.3, 1.0, 0.5, 0.04), Step(3, 0, 0, 1.0, 1.0, -0.03)
    terrain = Terrain((kerb, pothole))
    np.testing.assert_allclose(terrain.heights([[0, 0], [3, 0], [1.5, 0]]), [0.04, -0.03, 0.0])
    assert terrain.extent() == (-0.03, 0.04)


def test_a_rough_patch_passes_through_its_nodes_and_its_steepest_gradient_is_a_true_bound():
    rng = np.random.default_rng(4)
    grid = np.zeros((6, 7))
    grid[1:-1, 1:-1] = rng.uniform(-0.05, 0.05, (4, 5))
    patch = Rough(0.5, -0.5, 0.7, 0.2, tuple(map(tuple, grid)))
    nodes = patch.to_world(np.array([[-0.6 + 0.2 * i, -0.5 + 0.2 * j] for j in range(6) for i in range(7)]))
    np.testing.assert_allclose(patch.heights(nodes), grid.ravel(), atol=1e-12)
    pts = patch.to_world(rng.uniform([-0.6, -0.5], [0.6, 0.5], (20000, 2)))
    sampled = patch.gradients(pts).max()
    assert sampled <= patch.steepest() + 1e-12
    assert sampled >= 0.95 * patch.steepest()  # and it is reached (on a whole triangle)


def test_overlapping_or_malformed_elements_are_refused():
    with pytest.raises(SceneError, match="overlap"):
        Terrain((Step(0, 0, 0, 1, 1, 0.05), Ramp(0.5, 0, 0, 1, 0.1, 1, 0)))
    with pytest.raises(SceneError, match="rise"):
        Ramp(0, 0, 0, 1, 0.0, 1, 0)
    with pytest.raises(SceneError, match="non-zero"):
        Step(0, 0, 0, 1, 1, 0.0)
    with pytest.raises(SceneError, match="border"):
        Rough(0, 0, 0, 0.5, ((0.1, 0.0), (0.0, 0.0)))


def test_terrain_enters_the_content_hash_and_a_flat_scene_keeps_its_own():
    floor = Node("floor", "floor", Box((4, 4, 0.1)), Pose(0, 0, -0.05))
    flat = Scene((floor,))
    assert "terrain" not in flat.canonical()
    bumpy = flat.with_terrain(Terrain((Step(0, 0, 0, 1, 1, 0.05),)))
    assert bumpy.content_hash() != flat.content_hash()
    assert bumpy.with_nodes(bumpy.nodes).terrain is bumpy.terrain
    assert bumpy.with_terrain(None).content_hash() == flat.content_hash()


def test_the_robot_still_imports_from_where_it_was():
    import worldgen.scene
    import worldgen.scene.graph
    import worldgen.scene.robot

    assert worldgen.scene.Robot is worldgen.scene.graph.Robot is worldgen.scene.robot.Robot
