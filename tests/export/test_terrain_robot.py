"""The Gazebo robot on terrain (worldgen.export.robot): in a world with terrain its casters ride vertical
springs, so that at a ramp's foot they do not lift the wheels off the ground (tests/sim/test_gazebo_terrain.py
drives it over a ramp); the model passes libsdformat's strict check; a flat world's robot keeps rigid casters."""

from __future__ import annotations

from lxml import etree
from support.reftools_sdf import check_robot_sdf
from support.terrain import ramp_world

import worldgen
from worldgen.export.robot import CASTER_PRELOAD, CASTER_SPRING, robot_sdf


def joints(sdf: str) -> dict:
    return {j.get("name"): j for j in etree.fromstring(sdf.encode()).iter("joint")}


def test_on_terrain_the_casters_ride_springs_and_the_model_is_strict_sdformat(tmp_path):
    sdf = robot_sdf(ramp_world())
    casters = {name: j for name, j in joints(sdf).items() if "caster" in name}
    assert sorted(casters) == ["back_caster_joint", "front_caster_joint"]
    for joint in casters.values():
        assert joint.get("type") == "prismatic" and joint.findtext("axis/xyz") == "0 0 1"
        assert float(joint.findtext("axis/dynamics/spring_stiffness")) == CASTER_SPRING
        assert float(joint.findtext("axis/dynamics/spring_reference")) == -CASTER_PRELOAD
    path = tmp_path / "robot.sdf"
    path.write_text(sdf)
    ok, messages = check_robot_sdf(path)
    assert ok, messages


def test_a_flat_world_keeps_rigid_casters():
    flat = worldgen.generate("cluttered", seed=0, size=[6, 6], n_obstacles=2)
    types = {name: j.get("type") for name, j in joints(robot_sdf(flat)).items()}
    assert types["front_caster_joint"] == types["back_caster_joint"] == "fixed"
    assert "spring_stiffness" not in robot_sdf(flat)
