"""The robot's body, shared by its two files (robot.sdf, :mod:`worldgen.export.robot`; robot.urdf,
:mod:`worldgen.export.robot_urdf`): every length from the world's robot description, the parts below the
chassis with their masses, and the inertia of a cylinder."""

from __future__ import annotations

import math

from worldgen.errors import ParameterError
from worldgen.groundtruth.folder import robot_description_of
from worldgen.scene.robot import RobotDescription

__all__ = ["DEFAULT_NAME", "COLOUR", "Dimensions", "described", "dimensions", "inertia_cylinder", "parts", "chassis"]

#: The model's name: the ROS 2 bundle's robot (worldgen.export.ros2.DEFAULT_ROBOT_NAME).
DEFAULT_NAME = "robot"
# The wheels' and casters' own masses (kg), beside the chassis' (the description's mass).
_WHEEL_KG, _CASTER_KG = 0.5, 0.2
#: The robot's colour (RGBA), in both files.
COLOUR = "0.95 0.45 0.1 1"


class Dimensions:
    """Every length of the robot, m, from the footprint (radius, height) and the lidar's height."""

    def __init__(self, radius: float, height: float, lidar_height: float):
        if not (radius > 0 and height > 0 and math.isfinite(radius) and math.isfinite(height)):
            raise ParameterError(f"robot radius and height must be finite and > 0, got {radius!r}, {height!r}")
        self.radius, self.height, self.lidar_height = radius, height, lidar_height
        self.wheel_radius = min(0.05, height / 4.0, radius / 4.0)
        self.wheel_width = 0.8 * self.wheel_radius
        # A wheel touches the floor as the sphere of its radius (robot.sdf), which reaches 0.9 r from the centre:
        # the wheels stay inside the footprint cylinder.
        self.wheel_separation = 2.0 * (0.9 * radius - self.wheel_radius)
        self.caster_radius = self.wheel_radius / 2.0
        self.caster_x = radius - 1.5 * self.caster_radius
        # The chassis' collision spans [caster radius, height] above the floor: only wheels and casters touch it.
        self.chassis_bottom = self.caster_radius


def described(world) -> RobotDescription:
    """The robot description of ``world``: a World, world.json's content, or a description already made."""
    return world if isinstance(world, RobotDescription) else robot_description_of(world)


def dimensions(world) -> Dimensions:
    """The robot's :class:`Dimensions` for ``world`` (a World, world.json's content or a
    :class:`~worldgen.scene.robot.RobotDescription`): its footprint and its lidar's height above the floor."""
    robot = described(world)
    return Dimensions(robot.radius, robot.height, robot.lidar.height)


def inertia_cylinder(m: float, r: float, length: float) -> tuple[float, float, float]:
    side = m * (3 * r * r + length * length) / 12.0
    return side, side, m * r * r / 2.0


def parts(d: Dimensions) -> list[tuple]:
    """(link, joint type, xyz from base_link, shape, mass, friction) of every body below base_link."""
    y = d.wheel_separation / 2.0
    rc, rw = d.caster_radius, d.wheel_radius
    return [("left_wheel", "revolute", (0.0, y, 0.0), ("cylinder", rw, d.wheel_width), _WHEEL_KG, 1.0),
            ("right_wheel", "revolute", (0.0, -y, 0.0), ("cylinder", rw, d.wheel_width), _WHEEL_KG, 1.0),
            ("front_caster", "fixed", (d.caster_x, 0.0, rc - rw), ("sphere", rc), _CASTER_KG, 0.0),
            ("back_caster", "fixed", (-d.caster_x, 0.0, rc - rw), ("sphere", rc), _CASTER_KG, 0.0)]


def chassis(d: Dimensions) -> tuple[float, float]:
    """(length, z of its centre above base_link) of the chassis cylinder."""
    length = d.height - d.chassis_bottom
    return length, d.chassis_bottom + length / 2.0 - d.wheel_radius
