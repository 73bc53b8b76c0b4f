"""The corridor generator: every world it returns is drivable by an analytic re-check, loads in the
reference tools, and keeps the promises of its parameters (width, passage, shape); too narrow a
corridor is refused with the numbers."""

from __future__ import annotations

import math

import mujoco
import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st
from support.checks import recheck, reference_tools

import worldgen
from worldgen.errors import InfeasibleError, ParameterError
from worldgen.generators.corridor import proven_width
from worldgen.generators.corridor_layout import layout

#: The passage figure is the checker's: connectivity between cell centres puts the radius within
#: half a cell diagonal, so the width within sqrt(2) cells, plus the bisection's 1/8 cell
#: (feasibility/passage.py). Measured: up to 1.18 cells below the true width.


# -- an independent re-check: plain geometry, none of worldgen's feasibility code -------------

# -- property test over the parameter space --------------------------------------------------

@st.composite
def corridor_params(draw):
    shape = draw(st.sampled_from(["straight", "L", "U", "zigzag"]))
    radius = draw(st.sampled_from([0.1, 0.2, 0.3]))
    clearance = draw(st.sampled_from([0.0, 0.05, 0.1]))
    inflation = radius + clearance
    # From 1 mm more than the footprint needs, 2 x inflation, up: every one is a passage.
    width = round(2 * inflation + 0.001 + draw(st.floats(0.0, 1.2)), 3)
    params = dict(shape=shape, robot_radius=radius, clearance=clearance, width=width,
                  wall_thickness=draw(st.sampled_from([0.05, 0.1, 0.3])), max_attempts=20)
    leg = width + 2 * params["wall_thickness"] + draw(st.floats(0.5, 4.0))
    if shape == "zigzag":
        n = draw(st.integers(2, 5))
        params["segments"] = [round(leg + draw(st.floats(0, 2)), 3) for _ in range(n)]
        params["turns"] = ",".join(draw(st.sampled_from(["left", "right"])) for _ in range(n - 1))
    else:
        params["length"] = round(leg + (4.0 if shape == "straight" else 1.0), 3)
    passage = 2 * inflation + 0.2  # the default min_passage
    params["n_obstacles"] = draw(st.integers(0, 4)) if width >= passage + 0.051 else 0
    params["side_openings"] = draw(st.integers(0, 2))
    params["opening_width"] = 0.5
    return params


def _generate_or_refuse(seed, params):
    """The world, or None where the request is refused as it must be (a zigzag that runs into itself, obstacles
    in a corridor with no leg long enough for one)."""
    try:
        return worldgen.generate("corridor", seed=seed, **params)
    except ParameterError as exc:
        assert "run into" in str(exc) or "longer than" in str(exc) or "must be 0 in this corridor" in str(exc), str(exc)
        return None


@settings(max_examples=30, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(params=corridor_params(), seed=st.integers(0, 2**32))
def test_every_corridor_is_drivable_by_an_independent_recheck(params, seed):
    try:
        world = _generate_or_refuse(seed, params)
    except InfeasibleError as exc:  # only crowding may fail, and it must say so
        assert "obstacle_placement" in str(exc) or "opening_placement" in str(exc), str(exc)
        return
    if world is None:
        return
    recheck(world)
    report = world.feasibility
    width = params["width"]
    # Wall poses and sizes are kept to 6 decimals, so the gap between two walls may differ
    # from the width asked for by a few 1e-7 m; the passage is measured exactly on the walls.
    assert report.narrowest_passage <= width + 5e-6
    inflation = params["robot_radius"] + params["clearance"]
    floor = min(width, 2 * inflation + 0.2) if params["n_obstacles"] else width
    assert report.narrowest_passage >= floor - 5e-6
    # Shape: the number of legs, end walls, obstacles; spawn at the start, goal at the far end.
    lay = layout(world.params)
    names = [n.name for n in world.scene.nodes]
    assert "wall_start" in names and "wall_end" in names
    assert sum(n.role == "obstacle" for n in world.scene.nodes) == params["n_obstacles"]
    task = world.tasks[0]
    assert np.hypot(task.spawn.x - lay.points[0][0], task.spawn.y - lay.points[0][1]) <= max(width / 2, 0.5) + 1e-6
    assert np.hypot(task.goal.x - lay.points[-1][0], task.goal.y - lay.points[-1][1]) <= max(width / 2, 0.5) + 1e-6


# -- width: every corridor wider than the footprint needs passes; below, a clear refusal ---------

@pytest.mark.parametrize("shape", ["straight", "L", "U", "zigzag"])
@pytest.mark.parametrize("radius,clearance", [(0.2, 0.05), (0.1, 0.0), (0.35, 0.1)])
@pytest.mark.parametrize("slack", [0.01, 0.001])
def test_a_corridor_a_hair_wider_than_the_footprint_needs_is_a_passage(shape, radius, clearance, slack):
    """Need + 1 cm must pass, and need + 1 mm too: the checker keeps only 0.1 mm a side."""
    width = round(2 * (radius + clearance) + slack, 6)
    world = worldgen.generate("corridor", shape=shape, length=4.0, width=width, robot_radius=radius,
                              clearance=clearance)
    recheck(world)
    assert world.feasibility.narrowest_passage == pytest.approx(width, abs=5e-6)


@pytest.mark.parametrize("shape", ["straight", "L", "U", "zigzag"])
def test_the_proven_width_is_feasible_for_every_shape(shape):
    params = dict(shape=shape, length=4.0)
    resolved = worldgen.generators.get("corridor").resolve(dict(params, width=2.0))
    world = worldgen.generate("corridor", width=round(proven_width(resolved) + 5e-6, 6), **params)
    recheck(world)


def test_too_narrow_for_the_robot_says_so_with_the_numbers():
    with pytest.raises(InfeasibleError) as err:
        worldgen.generate("corridor", width=0.8, robot_radius=0.45, clearance=0.05)
    assert str(err.value) == ("corridor width 0.8 m cannot pass a 0.45 m radius robot with 0.05 m clearance "
                              "(needs >= 1.0 m)")


def test_inside_the_safety_margin_is_refused_honestly():
    with pytest.raises(InfeasibleError, match=r"corridor width 0.5001 m leaves less than the checker's 0.1 mm "
                                              r"safety margin on each side of the 0.5 m .* from 0.50021 m wide"):
        worldgen.generate("corridor", width=0.5001)


def test_asked_for_on_purpose_the_narrow_corridor_comes_back_infeasible():
    world = worldgen.generate("corridor", width=0.8, robot_radius=0.45, clearance=0.05, max_attempts=1,
                              allow_infeasible=True)
    assert not world.feasibility.feasible
    failed = {c.name for c in world.feasibility.failed()}
    assert {"spawn_free", "path_exists"} <= failed
    assert world.metadata["feasibility"]["feasible"] is False


def test_the_0_8_m_corridor_reports_its_narrowest_passage():
    world = worldgen.generate("corridor", width=0.8)
    recheck(world)
    assert world.feasibility.narrowest_passage == pytest.approx(0.8, abs=5e-6)  # the exact gap
    # The walls' inner faces really are 0.8 m apart.
    left = world.scene.node("wall_left_0_0")
    right = world.scene.node("wall_right_0_0")
    gap = (left.pose.y - left.shape.size[1] / 2) - (right.pose.y + right.shape.size[1] / 2)
    assert gap == pytest.approx(0.8, abs=1e-9)


def test_obstacles_leave_the_promised_passage_exactly():
    """Against the walls' and obstacles' geometry: every obstacle leaves min_passage to the far wall
    and to every other obstacle (measured between their floor shadows)."""
    world = worldgen.generate("corridor", seed=4, width=2.0, length=12.0, n_obstacles=6, min_passage=0.9)
    recheck(world)
    obstacles = [n for n in world.scene.nodes if n.role == "obstacle"]
    assert len(obstacles) == 6
    for i, a in enumerate(obstacles):
        assert a.pose.yaw == 0.0 and 2.0 - a.shape.size[1] >= 0.9 - 1e-6  # to the far wall
        for b in obstacles[i + 1:]:  # between two axis-aligned rectangles
            dx = max(0.0, abs(a.pose.x - b.pose.x) - (a.shape.size[0] + b.shape.size[0]) / 2)
            dy = max(0.0, abs(a.pose.y - b.pose.y) - (a.shape.size[1] + b.shape.size[1]) / 2)
            assert math.hypot(dx, dy) >= 0.9 - 1e-6, (a.name, b.name)


# -- reference tools on a sample ---------------------------------------------------------------

@pytest.mark.parametrize("params", [
    dict(shape="L", n_obstacles=4, side_openings=2, opening_width=0.6),
    dict(shape="zigzag", segments=[3.0, 2.5, 3.0, 2.5], turns="left,right,right", width=1.0),
    dict(shape="U", length=4.0, n_obstacles=3, wall_thickness=0.2),
])
def test_sample_worlds_pass_the_reference_tools(params, tmp_path):
    world = worldgen.generate("corridor", seed=2, **params)
    recheck(world)
    reference_tools(world, tmp_path)


def test_mujoco_sees_the_corridor_width_by_ray():
    """From the spawn, sideways rays at mid-height hit the side walls at width / 2."""
    world = worldgen.generate("corridor", width=1.3, shape="L")
    model = mujoco.MjModel.from_xml_string(world.to_mjcf())
    data = mujoco.MjData(model)
    mujoco.mj_forward(model, data)
    s = world.tasks[0].spawn
    geom = np.zeros(1, dtype=np.int32)
    for direction in ([0.0, 1.0, 0.0], [0.0, -1.0, 0.0]):
        d = mujoco.mj_ray(model, data, np.array([s.x, s.y, 0.5]), np.array(direction), None, True, -1, geom)
        assert d == pytest.approx(0.65, abs=1e-6)
        assert model.geom(int(geom[0])).name.startswith("wall_")


# -- bad parameters: one line naming the parameter ----------------------------------------------

@pytest.mark.parametrize("params,pattern", [
    (dict(shape="L", segments=[4.0]), r"^parameter 'segments' must hold 2 length\(s\) for a L corridor"),
    (dict(turns="left"), r"^parameter 'turns' does not apply to a straight corridor"),
    (dict(shape="U", turns="left,right"), r"^parameter 'turns' must be two turns the same way"),
    (dict(shape="zigzag", segments=[3.0, 3.0, 3.0], turns="left"), r"^parameter 'turns' must name 2 turns"),
    (dict(shape="zigzag", segments=[4.0, 4.0, 4.0, 4.0, 4.0], turns="left,left,left,left"),
     r"^parameter 'turns' makes leg \d run into leg 0"),
    (dict(shape="L", length=1.0, width=1.5), r"^parameter 'length' must make each leg longer"),
    (dict(n_obstacles=2, width=1.0, min_passage=0.45), r"^parameter 'min_passage' must be in \[0.50021, 1\]"),
    (dict(n_obstacles=2, width=1.0, min_passage=0.99), r"^parameter 'min_passage' must be at most width - 0.05"),
    (dict(n_obstacles=2, width=0.72), r"^parameter 'n_obstacles' must be 0 in a corridor 0.72 m wide"),
    (dict(side_openings=1, opening_width=20.0), r"^parameter 'opening_width' must fit"),
    (dict(turns="up"), r"^parameter 'turns' must be 1 to 64 comma-separated words, each one of left, right"),
    (dict(segments=[0.1]), r"^parameter 'segments' must be in \[0.5, 500\]"),
    (dict(width=0.0), r"^parameter 'width' must be in \[0.05, 50\]"),
])
def test_bad_parameters_get_one_line_naming_them(params, pattern):
    with pytest.raises(ParameterError, match=pattern) as err:
        worldgen.generate("corridor", **params)
    assert "\n" not in str(err.value)


def test_same_seed_same_world_and_obstacles_vary_with_the_seed():
    a = worldgen.generate("corridor", seed=3, n_obstacles=3, side_openings=1)
    b = worldgen.generate("corridor", seed=3, n_obstacles=3, side_openings=1)
    c = worldgen.generate("corridor", seed=4, n_obstacles=3, side_openings=1)
    assert a.to_mjcf() == b.to_mjcf() and a.content_hash == b.content_hash
    assert a.content_hash != c.content_hash


def test_a_corridor_with_no_room_for_an_obstacle_is_refused_at_once_saying_why():
    with pytest.raises(ParameterError, match=r"^parameter 'n_obstacles' must be 0 in this corridor: an obstacle needs "
                                             r"1\.6 m of a leg \(0\.2 m long and 0\.7 m of passage on each side\)"):
        worldgen.generate("corridor", 0, length=2.0, n_obstacles=1)
    # A longer corridor gets its obstacle.
    world = worldgen.generate("corridor", 0, length=6.0, n_obstacles=1, obstacle_length=[0.2, 0.2])
    assert sum(n.role == "obstacle" for n in world.scene.nodes) == 1

