"""Difficulty metrics: hand-computable worlds, and an independent shapely re-computation on generated ones."""

from __future__ import annotations

import math

import numpy as np
import pytest
import shapely

import worldgen
from worldgen.feasibility.report import TaskPath
from worldgen.groundtruth import metrics
from worldgen.scene import Box, Node, Pose, Robot, Scene, Task
from worldgen.scene.footprint import robot_footprints

ROBOT = Robot(0.2, 0.4, 0.05)  # inflation 0.25: dispersion reaches 1.0 m


def straight(spawn, goal):
    task = Task("task_0", Pose(*spawn), Pose(*goal))
    w = np.array([spawn, goal], dtype=float)
    return task, TaskPath("task_0", w, float(np.linalg.norm(w[1] - w[0])), 0.1)


def room(half_x, half_y, *obstacles):
    floor = Node("floor", "floor", Box((2 * half_x + 1, 2 * half_y + 1, 0.1)), Pose(0, 0, -0.05))
    return Scene((floor,) + obstacles, bounds=((-half_x, -half_y), (half_x, half_y)))


def test_empty_room_by_hand():
    scene = room(5.0, 3.0)
    task, path = straight((-4.0, 0.0), (4.0, 0.0))
    got = metrics.difficulty(scene, ROBOT, [task], [path])
    xs = np.linspace(-4.0, 4.0, metrics.SAMPLES)
    # Nearest wall: the side walls 3 m away, or the end walls nearer than that.
    assert got["closest_obstacle_distance_mean"] == pytest.approx(np.mean(np.minimum(3.0, 5.0 - np.abs(xs))))
    # Every sample: rays to the rectangle's edge, by hand for each of the 16 directions.
    theta = np.arange(16) * math.pi / 8
    c, s = np.cos(theta), np.sin(theta)
    with np.errstate(divide="ignore"):
        tx = np.where(c > 0, (5.0 - xs[:, None]) / c, np.where(c < 0, (-5.0 - xs[:, None]) / c, np.inf))
        ty = np.where(s > 0, 3.0 / s, np.where(s < 0, -3.0 / s, np.inf)) * np.ones_like(tx)
    rays = np.minimum(tx, ty)
    assert got["average_visibility"] == pytest.approx(rays.mean())
    # The shortest chord of 8 lines: the 6 m cross-section, shorter near the end walls on the steep diagonals.
    chords = (rays[:, :8] + rays[:, 8:]).min(axis=1)
    assert chords[metrics.SAMPLES // 2] == pytest.approx(6.0) and chords[0] < 6.0
    assert got["characteristic_dimension"] == pytest.approx(chords.mean())
    assert got["dispersion"] == pytest.approx(np.mean([np.sum((r < 1.0) != np.roll(r < 1.0, -1)) for r in rays]))
    assert got["tortuosity"] == 1.0


def test_a_corridor_reads_its_width_and_four_gaps():
    w = 0.8
    walls = (Node("top", "wall", Box((10.0, 0.2, 1.0)), Pose(0, w / 2 + 0.1, 0.5)),
             Node("bottom", "wall", Box((10.0, 0.2, 1.0)), Pose(0, -w / 2 - 0.1, 0.5)))
    scene = room(6.0, 3.0, *walls)
    task, path = straight((-2.0, 0.0), (2.0, 0.0))
    got = metrics.difficulty(scene, ROBOT, [task], [path])
    assert got["characteristic_dimension"] == pytest.approx(w)
    assert got["closest_obstacle_distance_mean"] == pytest.approx(w / 2)
    # Up and down (and the steep diagonals) blocked within 1 m, along the corridor open: two gaps,
    # four alternations around the circle.
    assert got["dispersion"] == 4.0
    # A detour doubles the length: tortuosity is length / straight-line distance.
    detour = TaskPath("task_0", np.array([[-2.0, 0.0], [0.0, 0.0], [2.0, 0.0]]), 8.0, 0.1)
    assert metrics.difficulty(scene, ROBOT, [task], [detour])["tortuosity"] == 2.0


def test_no_path_gives_nulls():
    task, _ = straight((-1.0, 0.0), (1.0, 0.0))
    assert metrics.difficulty(room(3.0, 3.0), ROBOT, [task], [None]) == {n: None for n in metrics.NAMES}


def _shapely_rays(origins, theta, blockers):
    """(n, k) distance from each origin to the blockers along each angle, by shapely intersections."""
    o = np.repeat(origins, len(theta), axis=0)
    t = np.tile(theta, len(origins))
    far = o + 1e3 * np.column_stack([np.cos(t), np.sin(t)])
    lines = shapely.linestrings(np.stack([o, far], axis=1))
    hits = shapely.intersection(lines, blockers)
    return shapely.distance(shapely.points(o), hits).reshape(len(origins), len(theta))


@pytest.mark.parametrize("seed", [1, 2, 3])
def test_generated_worlds_match_a_shapely_recomputation(seed):
    world = worldgen.generate("cluttered", seed=seed, size=[8, 8], n_obstacles=15, n_tasks=2)
    got = world.metadata["metrics"]
    assert set(metrics.NAMES) <= set(got)
    robot = world.robot
    prints = robot_footprints(world.scene, robot)
    shapes = [shapely.Point(fp.centre).buffer(fp.radius, quad_segs=64) if fp.is_disc else fp.polygon for fp in prints]
    obstacles = shapely.union_all(shapes)
    (x0, y0), (x1, y1) = world.scene.bounds
    frame = shapely.box(x0 - 50, y0 - 50, x1 + 50, y1 + 50).difference(shapely.box(x0, y0, x1, y1))
    pts = np.vstack([metrics.path_samples(p.waypoints) for p in world.feasibility.paths])
    near = [min(obstacles.distance(shapely.Point(p)), shapely.box(x0, y0, x1, y1).exterior.distance(shapely.Point(p)))
            for p in pts]
    assert got["closest_obstacle_distance_mean"] == pytest.approx(np.mean(near), abs=2e-4)
    theta = np.arange(16) * math.pi / 8
    rays = _shapely_rays(pts, theta, obstacles.union(frame))
    assert got["average_visibility"] == pytest.approx(rays.mean(), abs=2e-4)
    assert got["characteristic_dimension"] == pytest.approx(np.mean((rays[:, :8] + rays[:, 8:]).min(axis=1)), abs=2e-4)
    blocked = rays < metrics.DISPERSION_REACH * robot.inflation
    assert got["dispersion"] == pytest.approx(np.mean((blocked != np.roll(blocked, -1, axis=1)).sum(axis=1)))
    tort = [p.length / math.hypot(t.goal.x - t.spawn.x, t.goal.y - t.spawn.y)
            for t, p in zip(world.tasks, world.feasibility.paths)]
    assert got["tortuosity"] == pytest.approx(np.mean(tort), abs=1e-6)
    assert got["tortuosity"] >= 1.0
