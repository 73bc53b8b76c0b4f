"""tasks[].path.length against the exact shortest path, written here: a visibility graph over buffered obstacles.

The robot is a disc of radius R = robot.inflation; its centre may go wherever
it keeps at least R from every obstacle footprint and from the edge of the
bounds. The free space is the bounds shrunk by R minus every footprint grown by
R (a box grows into a rounded rectangle, a disc into a bigger disc). Here the
rounded corners become fine polygons inscribed in the true arcs, so the graph's
answer can only be a hair shorter than the truth (a corner is cut by under 0.1 mm with
128 segments per circle), never longer. The shortest path among polygons runs
straight between polygon vertices that see each other, so Dijkstra over that
visibility graph gives it. Nothing here shares code with worldgen's planner.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
import shapely
from scipy.sparse import coo_matrix
from scipy.sparse.csgraph import dijkstra

import worldgen
from worldgen import feasibility
from worldgen.footprint import robot_footprints
from worldgen.scene import Box, Cylinder, Node, Pose, Robot, Scene, Task

ROBOT = Robot(radius=0.2, height=0.4, clearance=0.05)
R = ROBOT.inflation
QUAD_SEGS = 32  # 128 segments per full circle
#: Segments shorter than this inside the obstacles still count as seeing each other: tangents
#: graze the inscribed polygons.
GRAZE = 1e-7


def exact_length(scene: Scene, robot: Robot, start, goal) -> float:
    prints = robot_footprints(scene, robot)
    grown = [shapely.Point(fp.centre).buffer(fp.radius + robot.inflation, quad_segs=QUAD_SEGS) if fp.is_disc
             else fp.polygon.buffer(robot.inflation, quad_segs=QUAD_SEGS) for fp in prints]
    (x0, y0), (x1, y1) = scene.bounds
    r = robot.inflation
    inner = shapely.box(x0 + r, y0 + r, x1 - r, y1 - r)
    blocked = shapely.union_all(grown + [shapely.box(x0 - 99, y0 - 99, x1 + 99, y1 + 99).difference(inner)])
    core = blocked.buffer(-GRAZE)  # the inside proper: a segment along an edge is free
    shapely.prepare(core)
    # Every vertex of the blocked region's boundary, with its two neighbours along the ring.
    pts, prev, nxt = [np.asarray(start, float), np.asarray(goal, float)], [None, None], [None, None]
    for poly in getattr(blocked, "geoms", [blocked]):
        for ring in [poly.exterior, *poly.interiors]:
            c = np.asarray(ring.coords)[:-1]
            pts += list(c)
            prev += list(np.roll(c, 1, axis=0))
            nxt += list(np.roll(c, -1, axis=0))
    n = len(pts)
    pts = np.array(pts)
    ends = np.zeros(n, dtype=bool)
    ends[:2] = True
    prev = np.array([p if p is not None else np.zeros(2) for p in prev])
    nxt = np.array([p if p is not None else np.zeros(2) for p in nxt])
    i, j = np.triu_indices(n, k=1)
    d = pts[j] - pts[i]

    def side(q, at):
        v = q - pts[at]
        return d[:, 0] * v[:, 1] - d[:, 1] * v[:, 0]

    def tangent(at):
        # A shortest path only bends round a vertex whose two ring neighbours lie on one side of it.
        a, b = side(prev[at], at), side(nxt[at], at)
        return ends[at] | (a * b >= -1e-15)

    keep = tangent(i) & tangent(j)
    i, j = i[keep], j[keep]
    seen = ~shapely.intersects(shapely.linestrings(np.stack([pts[i], pts[j]], axis=1)), core)
    i, j = i[seen], j[seen]
    w = np.linalg.norm(pts[i] - pts[j], axis=1)
    graph = coo_matrix((w, (i, j)), shape=(n, n)).tocsr()
    return float(dijkstra(graph, directed=False, indices=0)[1])


def check_task(scene, task, robot=ROBOT):
    report = feasibility.check(scene, [task], robot)
    assert report.feasible, report.failed()
    ref = exact_length(scene, robot, (task.spawn.x, task.spawn.y), (task.goal.x, task.goal.y))
    got = report.paths[0].length
    assert got >= ref - 1e-4, (got, ref)  # never shorter than the shortest (but for the inscribed arcs)
    assert got <= 1.02 * ref, (got, ref)
    return got, ref


def test_the_reference_itself_on_a_disc_by_hand():
    # One disc between the ends: two tangents and an arc.
    floor = Node("floor", "floor", Box((20, 20, 0.1)), Pose(0, 0, -0.05))
    d, rr = 4.0, 1.0
    pillar = Node("p", "obstacle", Cylinder(rr - R, 1.0), Pose(0, 0, 0.5))
    scene = Scene((floor, pillar), bounds=((-9, -9), (9, 9)))
    by_hand = 2 * math.sqrt(d * d - rr * rr) + rr * (math.pi - 2 * math.acos(rr / d))
    assert exact_length(scene, ROBOT, (-d, 0), (d, 0)) == pytest.approx(by_hand, rel=1e-4)
    assert exact_length(scene, ROBOT, (-d, 0), (d, 0)) <= by_hand


#: Small, dense worlds: exact shortest paths squeeze through gaps a little wider than the disc,
#: which is where a grid-based planner goes wrong (every case once failed, by up to 44 %).
CASES = [(shapes, seed) for shapes in ("box", "mixed", "cylinder") for seed in range(12)]


@pytest.mark.parametrize("shapes,seed", CASES)
def test_cluttered_boxes_walls_and_cylinders(shapes, seed):
    world = worldgen.generate("cluttered", seed, size=[6, 5], n_obstacles=9, obstacle_shapes=shapes,
                              box_size=[0.3, 1.4], min_spawn_goal_distance=3.5)
    task = world.tasks[0]
    ref = exact_length(world.scene, world.robot, (task.spawn.x, task.spawn.y), (task.goal.x, task.goal.y))
    got = world.metadata["tasks"][0]["path"]["length"]  # as written in world.json
    assert ref - 1e-4 <= got <= 1.02 * ref, (got, ref)


def _wall(name, x, y, sx, sy, yaw=0.0):
    return Node(name, "wall", Box((sx, sy, 1.0)), Pose(x, y, 0.5, 0, 0, yaw))


@pytest.mark.parametrize("case", ["gap", "zigzag", "turned", "pocket"])
def test_hand_built_walls(case):
    floor = Node("floor", "floor", Box((14, 14, 0.1)), Pose(0, 0, -0.05))
    walls = {
        # A wall across the room with a door-sized gap off the straight line.
        "gap": [_wall("w1", 0.0, 1.2, 0.2, 3.6), _wall("w2", 0.0, -2.3, 0.2, 1.4)],
        # Two offset walls: the path weaves round both ends.
        "zigzag": [_wall("w1", -1.5, 1.0, 0.15, 4.0), _wall("w2", 1.5, -1.0, 0.15, 4.0)],
        # Turned walls and a crate.
        "turned": [_wall("w1", -1.0, 0.5, 0.2, 4.0, 0.5), _wall("w2", 1.8, -0.6, 0.2, 3.0, -0.9),
                   Node("crate", "obstacle", Box((0.8, 0.6, 0.5)), Pose(0.4, 0.2, 0.25, 0, 0, 0.3))],
        # A U-shaped pocket between spawn and goal: the path must go round it, not into it.
        "pocket": [_wall("back", 0.8, 0.0, 0.2, 3.0), _wall("top", 0.0, 1.4, 1.8, 0.2),
                   _wall("bottom", 0.0, -1.4, 1.8, 0.2)],
    }[case]
    scene = Scene((floor,) + tuple(walls), bounds=((-4, -3), (4, 3)))
    task = Task("task_0", Pose(-3.4, 0.1, 0.0), Pose(3.3, -0.2, 0.0))
    got, ref = check_task(scene, task)
    assert ref > math.hypot(6.7, 0.3) + 0.1  # the walls are in the way
