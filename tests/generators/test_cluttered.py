"""The cluttered generator's draws, checked against its own promises (no feasibility here)."""

import math
import subprocess
import sys
import textwrap

import numpy as np
import pytest
import shapely
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st
from support import draft

import worldgen
from worldgen.generators import get


def _footprint(node):
    x, y = node.pose.x, node.pose.y
    if node.shape.kind == "cylinder":
        return shapely.Point(x, y).buffer(node.shape.radius, quad_segs=64)
    sx, sy = node.shape.size[:2]
    c, s = math.cos(node.pose.yaw), math.sin(node.pose.yaw)
    return shapely.Polygon([(x + c * u - s * v, y + s * u + c * v)
                            for u, v in ((-sx / 2, -sy / 2), (sx / 2, -sy / 2), (sx / 2, sy / 2), (-sx / 2, sy / 2))])


@settings(max_examples=40, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(
    seed=st.integers(0, 2**32),
    n=st.integers(0, 40),
    shapes=st.sampled_from(["box", "cylinder", "mixed"]),
    gap=st.floats(0.0, 0.5),
    size=st.tuples(st.floats(6, 15), st.floats(6, 15)),
    walls=st.booleans(),
)
def test_draws_keep_their_promises(seed, n, shapes, gap, size, walls):
    params = dict(n_obstacles=n, obstacle_shapes=shapes, min_gap=gap, size=list(size), walls=walls,
                  min_spawn_goal_distance=2.0)
    spec = get("cluttered")
    d = spec.build(spec.resolve(params), np.random.default_rng(seed))
    if d.rejected:  # a crowded request may fail a draw, but must say so rather than cheat
        assert d.rejected in ("obstacle_placement", "task_placement") and d.detail
        return
    scene, tasks = d.scene, d.tasks
    obstacles = [nd for nd in scene.nodes if nd.role == "obstacle"]
    assert len(obstacles) == n
    assert len([nd for nd in scene.nodes if nd.role == "wall"]) == (4 if walls else 0)
    room = shapely.box(-size[0] / 2, -size[1] / 2, size[0] / 2, size[1] / 2)
    prints = [_footprint(o) for o in obstacles]
    for o, fp in zip(obstacles, prints):
        assert room.buffer(1e-6).contains(fp), o.name
        assert o.pose.z == o.shape.size[2] / 2 if o.shape.kind == "box" else o.pose.z == o.shape.length / 2
        if shapes != "mixed":
            assert o.shape.kind == shapes
    for i in range(len(prints)):
        for j in range(i + 1, len(prints)):
            assert prints[i].distance(prints[j]) >= gap - 2e-3  # the buffered circle is inscribed
    robot_r = 0.25  # default radius + clearance
    for t in tasks:
        for pose in (t.spawn, t.goal):
            p = shapely.Point(pose.x, pose.y)
            assert room.buffer(-robot_r).contains(p)
            assert all(fp.distance(p) > robot_r for fp in prints)
        assert math.hypot(t.goal.x - t.spawn.x, t.goal.y - t.spawn.y) >= 2.0


def test_same_seed_same_draw_and_streams_are_independent():
    a, _ = draft("cluttered", 5, n_obstacles=15)
    b, _ = draft("cluttered", 5, n_obstacles=15)
    assert a.content_hash() == b.content_hash()
    # Asking for more tasks draws from another stream: not one obstacle moves.
    c, tasks = draft("cluttered", 5, n_obstacles=15, n_tasks=3)
    assert c.content_hash() == a.content_hash() and len(tasks) == 3
    d, _ = draft("cluttered", 6, n_obstacles=15)
    assert d.content_hash() != a.content_hash()


def test_many_tasks_do_not_overlap():
    _, tasks = draft("cluttered", 1, n_obstacles=5, n_tasks=8, size=[12, 12])
    spawns = np.array([[t.spawn.x, t.spawn.y] for t in tasks])
    goals = np.array([[t.goal.x, t.goal.y] for t in tasks])
    for pts in (spawns, goals):
        d = np.hypot(*(pts[:, None, :] - pts[None, :, :]).transpose(2, 0, 1))
        assert d[~np.eye(len(pts), dtype=bool)].min() >= 0.5


def test_density_replaces_count():
    scene, _ = draft("cluttered", 0, density=0.1, size=[10, 10])
    assert sum(nd.role == "obstacle" for nd in scene.nodes) == 10


def test_overcrowded_room_is_rejected_not_truncated():
    spec = get("cluttered")
    params = spec.resolve({"n_obstacles": 400, "size": [5, 5]})
    d = spec.build(params, np.random.default_rng(0))
    assert d.rejected == "obstacle_placement" and "400" in d.detail


def test_other_packages_register_generators_through_entry_points(tmp_path):
    # A throw-away distribution on sys.path whose entry point names a GeneratorSpec.
    pkg = tmp_path / "extra_gen.py"
    pkg.write_text(textwrap.dedent('''
        from worldgen.generators import GeneratorSpec, Draft
        from worldgen.generators.cluttered import build, PARAMS, check
        SPEC = GeneratorSpec("extra", "a plugin generator", PARAMS, build, check)
    '''))
    dist = tmp_path / "extra_gen-1.0.dist-info"
    dist.mkdir()
    (dist / "METADATA").write_text("Metadata-Version: 2.1\nName: extra-gen\nVersion: 1.0\n")
    (dist / "entry_points.txt").write_text("[worldgen.generators]\nextra = extra_gen:SPEC\n")
    code = "from worldgen.generators import get, names; print(names()); print(get('extra').summary)"
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                         env={"PYTHONPATH": str(tmp_path), "PATH": "/usr/bin:/bin"}, check=True).stdout
    assert "'extra'" in out and "a plugin generator" in out


@settings(max_examples=300, deadline=None)
@given(st.lists(st.floats(-3, 3), min_size=6, max_size=6), st.lists(st.floats(0.05, 2), min_size=4, max_size=4),
       st.floats(0.02, 1.0))
def test_placement_distances_equal_shapelys(xyyaw, sizes, radius):
    """The closed-form distances the draw uses (rectangles, discs, points) against GEOS."""
    from worldgen.generators.cluttered import _Footprint
    from worldgen.scene import Box, Cylinder

    (x1, y1, yaw1, x2, y2, yaw2), (a, b, c, d) = xyyaw, sizes
    r1 = _Footprint("box", Box((a, b, 1.0)), x1, y1, yaw1)
    r2 = _Footprint("box", Box((c, d, 1.0)), x2, y2, yaw2)
    disc = _Footprint("cylinder", Cylinder(radius, 1.0), x2, y2, 0.0)
    p1, p2 = shapely.Polygon(r1.corners), shapely.Polygon(r2.corners)
    assert r1.distance(r2) == pytest.approx(p1.distance(p2), abs=1e-12)
    assert r1.distance(disc) == pytest.approx(p1.distance(shapely.Point(x2, y2)) - radius, abs=1e-12)
    assert r1.point_distance(x2, y2) == pytest.approx(p1.distance(shapely.Point(x2, y2)), abs=1e-12)


def test_a_density_past_the_obstacle_ceiling_is_one_line_at_once():
    """Found by `make fuzz`: density 2.08 on 500 x 109 m asked for 114,007 obstacles and took 70 s of failed draws."""
    from worldgen.errors import ParameterError

    with pytest.raises(ParameterError) as err:
        worldgen.generate("cluttered", seed=1912466004, size=[500.0, 109.3645], density=2.0849, task_region=0.0)
    assert str(err.value).startswith("parameter 'density' gives 114007 obstacles on this 500 x 109.365 m floor; at most 5000")
    assert worldgen.generate("cluttered", seed=0, size=[10, 10], density=0.2).params["density"] == 0.2
