"""Every passage wider than the footprint needs is a passage, and the narrowest one is reported exactly.

- A wall across the room with one gap of need + 1 cm (and need + 1 mm), at any angle: the path
  goes through it, proven by worldgen's FCL check and, independently, by MuJoCo's own distance
  (``mj_geomDistance``) from a probe cylinder of the robot's size moved along it every 2 cm.
- Requests feasible by construction (boxes kept off a known free lane) always generate.
- ``narrowest_passage`` is the gap itself where the gap decides, and against the reference's
  free space it is the widest disc that gets through (bracketed by bisection-free tests just
  below and above it).
"""

from __future__ import annotations

import math

import mujoco
import numpy as np
import pytest
import shapely
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st
from support import exact_reference
from support.checks import with_probe
from support.reftools_mujoco import load

import worldgen
from worldgen import feasibility
from worldgen.scene import Box, Node, Pose, Robot, Scene, Task
from worldgen.scene.doors import open_scene
from worldgen.scene.footprint import SAFETY, robot_footprints
from worldgen.world import World

#: Probe samples along the path (m), as the issue asks.
STEP = 0.02


def gap_world(gap: float, yaw: float, offset: float) -> Scene:
    """A 10 x 8 m room cut by a wall (two boxes, 0.2 m thick) through the origin at ``yaw``, with one
    gap of ``gap`` m whose centre lies ``offset`` m along the wall."""
    floor = Node("floor", "floor", Box((12, 10, 0.1)), Pose(0, 0, -0.05))
    along = np.array([math.cos(yaw + math.pi / 2), math.sin(yaw + math.pi / 2)])
    nodes = [floor]
    for name, sign in (("wall_a", 1), ("wall_b", -1)):
        length = 20.0
        centre = (offset + sign * (gap / 2 + length / 2)) * along
        nodes.append(Node(name, "wall", Box((0.2, length, 1.0)), Pose(centre[0], centre[1], 0.5, 0, 0, yaw)))
    return Scene(tuple(nodes), bounds=((-5, -4), (5, 4)))


def probe_clearance(scene: Scene, robot: Robot, waypoints) -> float:
    """MuJoCo's smallest distance from a probe cylinder (the footprint) to any collider along the path."""
    mjcf = World("hand_built", 0, {}, scene, (), robot, None, 1).to_mjcf()
    model = load(with_probe(mjcf, robot.radius, robot.height))
    data = mujoco.MjData(model)
    mujoco.mj_forward(model, data)
    probe = model.geom("probe").id
    others = [g for g in range(model.ngeom) if g != probe and model.geom(g).name not in ("floor", "")]
    w = np.asarray(waypoints, dtype=float)
    pts = [w[:1]]
    for a, b in zip(w[:-1], w[1:]):
        n = max(1, math.ceil(np.hypot(*(b - a)) / STEP))
        pts.append(a + (b - a) * (np.arange(1, n + 1) / n)[:, None])
    best = math.inf
    for x, y in np.vstack(pts):
        data.mocap_pos[0] = [x, y, robot.height / 2]
        mujoco.mj_kinematics(model, data)
        for g in others:
            best = min(best, mujoco.mj_geomDistance(model, data, probe, g, 1.0, None))
    return best


@pytest.mark.parametrize("slack", [0.01, 0.001])
@pytest.mark.parametrize("radius,clearance", [(0.2, 0.05), (0.15, 0.0), (0.3, 0.1)])
@pytest.mark.parametrize("yaw,offset", [(0.0, 0.0), (0.4, 1.3), (-1.1, -0.7), (math.pi / 2, 2.0)])
def test_a_gap_a_hair_wider_than_the_footprint_is_driven_through(slack, radius, clearance, yaw, offset):
    robot = Robot(radius=radius, height=0.4, clearance=clearance)
    gap = 2 * robot.inflation + slack
    scene = gap_world(gap, yaw, offset)
    normal = np.array([math.cos(yaw), math.sin(yaw)])
    centre = offset * np.array([-math.sin(yaw), math.cos(yaw)])
    spawn, goal = centre - 2.0 * normal, centre + 2.0 * normal
    task = Task("task_0", Pose(*spawn, 0.0), Pose(*goal, 0.0))
    report = feasibility.check(scene, [task], robot)
    assert report.feasible, [c.detail for c in report.failed()]
    assert report.narrowest_passage == pytest.approx(gap, abs=1e-9)
    path = report.paths[0]
    assert path.length == pytest.approx(4.0, abs=1e-9)  # straight through the middle of the gap
    assert path.min_clearance >= clearance  # worldgen's FCL proof, on the swept volume
    # Independently: MuJoCo's distance from the footprint, every 2 cm along the path.
    assert probe_clearance(scene, robot, path.waypoints) >= clearance - 1e-6


def test_a_gap_a_hair_narrower_is_refused_and_says_why():
    robot = Robot(radius=0.2, height=0.4, clearance=0.05)
    scene = gap_world(2 * robot.inflation - 0.001, 0.3, 0.5)
    task = Task("task_0", Pose(-2.0, 0.0, 0.0), Pose(2.0, 0.5, 0.0))
    report = feasibility.check(scene, [task], robot)
    assert not report.feasible
    assert report.check("path_exists").detail.startswith("task_0: no path for a 0.25 m disc")


# -- feasible by construction ----------------------------------------------------------------------

@settings(max_examples=40, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(seed=st.integers(0, 2**31), n=st.integers(1, 25), bend=st.floats(-2.0, 2.0),
       slack=st.sampled_from([0.001, 0.01, 0.1]))
def test_a_room_with_a_known_free_lane_always_generates(seed, n, bend, slack):
    """Boxes are kept off a bent lane (spawn -> corner -> goal) by the footprint plus ``slack``: the lane
    is a route, so the request must come back feasible however the boxes crowd round it."""
    robot = Robot(radius=0.2, height=0.4, clearance=0.05)
    rng = np.random.default_rng(seed)
    lane = np.array([[-3.5, -2.0], [0.0, bend], [3.5, 2.0]])
    keep = robot.inflation + slack + SAFETY
    nodes = [Node("floor", "floor", Box((9, 7, 0.1)), Pose(0, 0, -0.05))]
    for k in range(n):
        size = rng.uniform(0.2, 1.0, 2)
        for _ in range(50):
            x, y, yaw = rng.uniform(-4, 4), rng.uniform(-3, 3), rng.uniform(-3, 3)
            node = Node(f"b{k}", "obstacle", Box((size[0], size[1], 0.8)), Pose(x, y, 0.4, 0, 0, yaw))
            probe = Scene((nodes[0], node), bounds=((-4.5, -3.5), (4.5, 3.5)))
            poly = robot_footprints(probe, robot)[0].polygon
            if poly.distance(shapely.LineString(lane)) >= keep:
                nodes.append(node)
                break
    scene = Scene(tuple(nodes), bounds=((-4.5, -3.5), (4.5, 3.5)))
    task = Task("task_0", Pose(*lane[0], 0.0), Pose(*lane[-1], 0.0))
    report = feasibility.check(scene, [task], robot)
    assert report.feasible, [c.detail for c in report.failed()]
    lane_length = float(np.hypot(*np.diff(lane, axis=0).T).sum())
    assert report.paths[0].length <= lane_length + 1e-9
    assert report.narrowest_passage >= 2 * (robot.inflation + slack) - 1e-9


# -- narrowest_passage against the reference's free space ------------------------------------------

@settings(max_examples=40, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(seed=st.integers(0, 2**31), n=st.integers(2, 14), shapes=st.sampled_from(["box", "cylinder", "mixed"]))
def test_narrowest_passage_is_the_widest_disc_that_gets_through(seed, n, shapes):
    try:
        world = worldgen.generate("cluttered", seed, size=[6, 5], n_obstacles=n, obstacle_shapes=shapes,
                                  box_size=[0.3, 1.4], min_gap=0.05, max_attempts=5)
    except worldgen.errors.InfeasibleError:
        return
    passage = world.feasibility.narrowest_passage
    prints = robot_footprints(open_scene(world.scene), world.robot)
    task = world.tasks[0]
    ends = (task.spawn.x, task.spawn.y), (task.goal.x, task.goal.y)
    half = passage / 2
    # A hair narrower gets through even round conservative polygons; a hair wider does not even
    # round permissive ones (grown to hold the true shapes). A polygon round an arc of radius rho
    # strays from it by at most rho x bulge.
    bulge = 1 / math.cos(math.pi / (4 * exact_reference.QUAD_SEGS)) - 1
    rho = half + max([fp.radius for fp in prints if fp.is_disc], default=0.0)
    below = half - 2e-4 - 2 * rho * bulge
    above = half + 2e-4 + 2 * rho * bulge
    assert exact_reference.connected(prints, below, world.scene.bounds, *ends, outer=True)
    assert not exact_reference.connected(prints, above, world.scene.bounds, *ends, outer=False)
    assert world.metadata["metrics"]["narrowest_passage"] == pytest.approx(passage, abs=1e-6)
