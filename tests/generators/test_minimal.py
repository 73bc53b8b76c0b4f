"""The minimal generator: one target at an exact distance, as MuJoCo's own ray casting measures it."""

from __future__ import annotations

import math

import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st
from support.checks import ray, recheck, reference_tools

import worldgen
from worldgen.errors import ParameterError


def test_a_wall_two_metres_ahead_is_two_metres_away_in_mujoco():
    world = worldgen.generate("minimal", target="wall", target_distance=2.0)
    recheck(world)
    d, name = ray(world, (0.0, 0.0), 0.0, 0.5)
    assert name == "target"
    assert abs(d - 2.0) <= 1e-6
    # The near face is the plane x = 2 in the scene too (the exporter is not the only witness).
    target = world.scene.node("target")
    assert target.pose.x - target.shape.size[0] / 2 == pytest.approx(2.0, abs=1e-12)


@settings(max_examples=25, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(
    target=st.sampled_from(["wall", "box", "cylinder"]),
    distance=st.floats(0.42, 4.0),
    bearing=st.floats(-math.pi, math.pi),
    yaw=st.floats(-math.pi, math.pi),
    walls=st.booleans(),
    height=st.floats(0.2, 2.0),
    spawn_xy=st.tuples(st.floats(-1.0, 1.0), st.floats(-1.0, 1.0)),
)
def test_the_target_is_exactly_where_asked_and_the_world_is_drivable(target, distance, bearing, yaw, walls, height, spawn_xy):
    spawn = [round(spawn_xy[0], 6), round(spawn_xy[1], 6), round(yaw, 6)]
    params = dict(target=target, target_distance=round(distance, 6), target_bearing=round(bearing, 6),
                  spawn=spawn, walls=walls, target_height=round(height, 6), size=[12.0, 12.0])
    world = worldgen.generate("minimal", **params)
    recheck(world)
    task = world.tasks[0]
    assert (task.spawn.x, task.spawn.y, task.spawn.yaw) == tuple(spawn)
    d, name = ray(world, spawn[:2], spawn[2] + params["target_bearing"], params["target_height"] / 2)
    assert name == "target"
    # Centre and yaw are written with 6 decimals: the hit moves by well under 2e-6 m.
    assert d == pytest.approx(params["target_distance"], abs=2e-6)
    roles = [n.role for n in world.scene.nodes]
    assert roles.count("wall") == (4 if walls else 0) + (target == "wall")
    assert len(world.scene.nodes) == 2 + 4 * walls


def test_a_cylinder_counts_to_its_surface_and_a_box_to_its_face():
    cyl = worldgen.generate("minimal", target="cylinder", target_radius=0.3, target_distance=1.5, target_bearing=math.pi / 2)
    node = cyl.scene.node("target")
    assert (node.pose.x, node.pose.y) == pytest.approx((0.0, 1.8), abs=2e-6)  # the bearing is kept to 6 decimals
    box = worldgen.generate("minimal", target="box", target_depth=0.4, target_distance=1.5, spawn_yaw=math.pi)
    node = box.scene.node("target")
    assert (node.pose.x, node.pose.y) == pytest.approx((-1.7, 0.0), abs=1e-6)
    assert node.shape.size[:2] == (0.4, 0.5)  # depth as given; width the box default


def test_no_random_draws_the_seed_only_names_the_world():
    a = worldgen.generate("minimal", seed=0, target="box")
    b = worldgen.generate("minimal", seed=99, target="box")
    assert a.scene.content_hash() == b.scene.content_hash() and a.to_sdf() != b.to_sdf()  # the name carries the seed
    assert a.content_hash != b.content_hash  # world.json records the seed
    assert a.world_id != b.world_id


def test_the_default_goal_stands_beside_the_target_and_a_given_one_is_kept():
    world = worldgen.generate("minimal", target="wall", target_distance=2.0)
    goal = world.tasks[0].goal
    # Level with the near face, clear of the wall's end by the footprint + 1 mm + 0.05 m.
    assert goal.x == pytest.approx(2.0) and goal.y == pytest.approx(2.0 + 0.25 + 0.001 + 0.05, abs=1e-6)
    world = worldgen.generate("minimal", target="wall", goal=[-2.0, 1.0])
    assert (world.tasks[0].goal.x, world.tasks[0].goal.y) == (-2.0, 1.0)
    recheck(world)


@pytest.mark.parametrize("params", [
    dict(target="wall", walls=True),
    dict(target="box", target_bearing=0.7, spawn_yaw=-1.2),
    dict(target="cylinder", target_distance=3.0, walls=True, wall_thickness=0.3),
])
def test_sample_worlds_pass_the_reference_tools(params, tmp_path):
    world = worldgen.generate("minimal", **params)
    reference_tools(world, tmp_path)


@pytest.mark.parametrize("params,pattern", [
    (dict(target_distance=0.25), r"^parameter 'target_distance' must be at least robot_radius \+ clearance \+ "
                                 r"1 mm = 0.251 m, got 0.25"),
    (dict(target_distance=8.0), r"^parameter 'target_distance' puts the wall .* off the floor \[-5, 5\] x \[-5, 5\]"),
    (dict(target="cylinder", target_width=1.0), r"^parameter 'target_width' does not apply to a cylinder target"),
    (dict(spawn=[0.0, 0.0, 0.5], spawn_yaw=0.5), r"^parameters 'spawn' and 'spawn_yaw' both set the heading"),
    (dict(spawn=[0.0, 0.0, 4.0]), r"^parameter 'spawn' yaw \(third value\) must be in \[-3.1416, 3.1416\] rad"),
    (dict(spawn=[4.76, 0.0, math.pi]), r"^parameter 'spawn' must keep the robot's 0.25 m disc and 1 mm "
                                       r"\(0.251 m\) inside the floor \[-5, 5\] x \[-5, 5\]"),
    (dict(goal=[0.0, 4.75]), r"^parameter 'goal' must keep the robot's 0.25 m disc and 1 mm"),
    (dict(target_width=10.5), r"^parameter 'target_distance' puts the wall"),
    (dict(target_width=9.9), r"^parameter 'goal' must be given: neither side of the target leaves room"),
    (dict(target="sphere"), r"^parameter 'target' must be one of wall, box, cylinder"),
    (dict(target_bearing=4.0), r"^parameter 'target_bearing' must be in \[-3.1416, 3.1416\]"),
    (dict(spawn=[1.0, 2.0]), r"^parameter 'spawn' must be three numbers"),
])
def test_bad_parameters_get_one_line_naming_them(params, pattern):
    with pytest.raises(ParameterError, match=pattern) as err:
        worldgen.generate("minimal", **params)
    assert "\n" not in str(err.value)


def test_the_params_world_json_records_rebuild_the_same_world():
    """world.json rounds floats (pi -> 3.141593): the recorded params must still be accepted."""
    world = worldgen.generate("minimal", seed=3, target="box", target_bearing=-math.pi, spawn_yaw=math.pi)
    again = worldgen.generate(world.generator, seed=3, **world.metadata["params"])
    assert again.content_hash == world.content_hash
