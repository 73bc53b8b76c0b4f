"""Drivable for the footprint: a ramp one degree within the robot's incline limit is a passage and one
degree beyond is refused; a step 1 mm within its step limit is crossed and 1 mm beyond is refused; the
path records its incline profile and the largest step it crosses."""

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from worldgen.feasibility import check
from worldgen.scene import Box, Node, Pose, Robot, Scene, Task
from worldgen.scene.drivable import kink_cleared, terrain_footprints
from worldgen.scene.terrain import Ramp, Rough, Step, Terrain

FLOOR = Node("floor", "floor", Box((10, 2, 0.1)), Pose(0, 0, -0.05))
TASK = Task("t0", Pose(-4, 0, 0), Pose(4, 0, 0))


def passage(element, robot) -> tuple[bool, object]:
    """Is a 2 m wide lane blocked across its whole width by ``element`` still drivable end to end?"""
    scene = Scene((FLOOR,), bounds=((-5, -1), (5, 1)), terrain=Terrain((element,)))
    report = check(scene, [TASK], robot)
    return report.feasible, report


@settings(max_examples=12, deadline=None)
@given(limit=st.floats(3.0, 14.0), rise=st.floats(0.05, 0.4), landing=st.floats(0.0, 2.0))
def test_a_ramp_one_degree_within_the_limit_is_a_passage_and_one_degree_beyond_is_refused(limit, rise, landing):
    # A chassis high enough that no bend stops it: this is the incline's test.
    robot = Robot(0.2, 0.4, 0.05, max_incline=math.radians(limit), ground_clearance=0.2)
    for delta, expected in ((-1.0, True), (1.0, False)):
        run = rise / math.tan(math.radians(limit + delta))
        ok, report = passage(Ramp(0, 0, 0, 2.0, rise, run, landing), robot)
        assert ok is expected, (limit + delta, [c for c in report.checks if not c.ok])
        if ok:
            got = report.terrain[0]
            assert got.largest_incline == pytest.approx(math.radians(limit + delta), abs=1e-9)
            assert got.profile[:, 1].max() == pytest.approx(rise)
            assert report.check("terrain_drivable").ok


@settings(max_examples=12, deadline=None)
@given(up=st.floats(0.005, 0.2), down=st.floats(0.005, 0.2), pothole=st.booleans())
def test_a_step_one_millimetre_within_the_limit_is_crossed_and_one_beyond_is_refused(up, down, pothole):
    robot = Robot(0.2, 0.4, 0.05, max_step_up=up, max_step_down=down)
    limit = min(up, down)  # a path over a kerb or a pothole climbs one edge and drops the other
    for delta, expected in ((-0.001, True), (0.001, False)):
        height = (limit + delta) * (-1 if pothole else 1)
        ok, report = passage(Step(0, 0, 0, 1.0, 2.0, height), robot)
        assert ok is expected, (height, [c for c in report.checks if not c.ok])
        if ok:
            assert report.terrain[0].largest_step == pytest.approx(abs(height))


def test_a_kerb_too_high_is_driven_round_when_there_is_room():
    scene = Scene((FLOOR,), bounds=((-5, -3), (5, 3)), terrain=Terrain((Step(0, 0, 0, 1.0, 2.0, 0.1),)))
    report = check(scene, [TASK], Robot(0.2, 0.4, 0.05))
    assert report.feasible
    assert report.paths[0].length > 8.0 and report.terrain[0].largest_step == 0.0
    # The footprint keeps off the edges: the check's value is the margin beyond its radius.
    assert report.check("terrain_drivable").value >= 0.05 - 1e-6


def test_a_rough_patch_is_refused_when_its_bumps_exceed_the_ground_clearance():
    grid = np.zeros((5, 9))
    grid[2, 1:-1] = 0.02  # a ridge 2 cm high, gently sloped (0.08 per m)
    patch = Rough(0, 0, 0, 0.25, tuple(map(tuple, grid)))
    assert passage(patch, Robot(0.2, 0.4, 0.05, ground_clearance=0.03))[0]
    assert not passage(patch, Robot(0.2, 0.4, 0.05, ground_clearance=0.015))[0]


def test_a_bend_passes_under_the_chassis_by_its_half_angle():
    robot = Robot(0.2, 0.4, 0.05, ground_clearance=0.2 * math.tan(math.radians(5)))
    assert kink_cleared(10.0, robot) and not kink_cleared(10.01, robot)


def test_a_bump_bends_twice_its_incline_at_the_crest():
    """A ramp with no landing bends by twice its incline at its crest: refused where the same ramp with a
    landing (bends of one incline each) passes under the chassis."""
    robot = Robot(0.2, 0.4, 0.05, max_incline=math.radians(20), ground_clearance=0.2 * math.tan(math.radians(8)))
    run = 0.1 / math.tan(math.radians(12))

    def forbidden(landing):
        return terrain_footprints(Scene((FLOOR,), terrain=Terrain((Ramp(0, 0, 0, 1, 0.1, run, landing),))), robot)

    assert [f.name for f in forbidden(0.5)] == ["terrain_0_edge_0", "terrain_0_edge_1"]  # only its high sides
    assert [f.name for f in forbidden(0.0)] == ["terrain_0"]  # the whole bump
