"""The robot: the footprint every feasibility figure is computed for (with, on terrain, its climbing limits),
and the one description of the robot every simulator builds (:class:`RobotDescription`: the footprint, its
motion limits, its body's mass and its lidar), read from world.json or a World by
:func:`worldgen.groundtruth.folder.robot_description_of` and ``open_world(...).robot_description``.

The description sits here, in scene/, because every room that builds a robot comes after it: the people's
certificate (people/), the robot files for Gazebo and ROS (export/robot.py), the environment (envs/) and
``worldgen drive`` (sim/); the reader that fills it from world.json is groundtruth/folder.py, the one reader
of a written world.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from worldgen.errors import ParameterError
from worldgen.params import COMMON_PARAMS

__all__ = ["Robot", "CLIMB_DEFAULTS", "MAX_SPEED", "TURN_RATE", "ACCELERATION", "BODY_MASS", "LidarDescription",
           "RobotDescription"]

#: The climbing limits a robot has unless told otherwise, typical of a small indoor differential-drive base
#: (not one robot's datasheet): 10 degrees, above the 1:12 (4.8 degree) ramps building codes allow for
#: wheelchairs, so those ramps pass; steps of 20 mm up or down, the threshold Misty Robotics specified for
#: Misty II to cross door sills (about 19 mm); 30 mm under the chassis.
CLIMB_DEFAULTS = {"max_incline": round(math.radians(10.0), 6), "max_step_up": 0.02, "max_step_down": 0.02,
                  "ground_clearance": 0.03}

_PARAM_DEFAULTS = {p.name: p.default for p in COMMON_PARAMS}
#: The motion limits a robot has where its world states none (world.json's robot block carries them only in
#: worlds with people): the defaults of the parameters ``robot_speed`` (m/s), ``robot_turn_rate`` (rad/s) and
#: ``robot_acceleration`` (m/s^2), whose one home is worldgen.params (docs/people.md says why these values).
MAX_SPEED = float(_PARAM_DEFAULTS["robot_speed"])
TURN_RATE = float(_PARAM_DEFAULTS["robot_turn_rate"])
ACCELERATION = float(_PARAM_DEFAULTS["robot_acceleration"])
#: kg of the robot's body: the environment's and the drive's MuJoCo cylinder and the Gazebo model's chassis
#: (world.json states no mass; 10 kg is a small indoor base's order of magnitude, not one robot's datasheet).
BODY_MASS = 10.0


@dataclass(frozen=True)
class Robot:
    """The footprint every feasibility figure is computed for: a vertical cylinder.

    ``clearance`` is the margin kept between the footprint's edge and any obstacle. The climbing limits
    matter only on terrain (worldgen.scene.terrain; docs/terrain.md): ``max_incline`` rad,
    ``max_step_up`` / ``max_step_down`` m, ``ground_clearance`` m under the chassis. Their defaults
    (:data:`CLIMB_DEFAULTS`) are typical of a small indoor differential-drive base.
    """

    radius: float
    height: float
    clearance: float
    max_incline: float = CLIMB_DEFAULTS["max_incline"]
    max_step_up: float = CLIMB_DEFAULTS["max_step_up"]
    max_step_down: float = CLIMB_DEFAULTS["max_step_down"]
    ground_clearance: float = CLIMB_DEFAULTS["ground_clearance"]

    def limits(self) -> dict:
        """The climbing limits by their world.json names."""
        return {"max_incline": self.max_incline, "max_step_up": self.max_step_up,
                "max_step_down": self.max_step_down, "ground_clearance": self.ground_clearance}

    @property
    def inflation(self) -> float:
        """Radius of the disc that must never touch an obstacle: radius + clearance."""
        return self.radius + self.clearance


@dataclass(frozen=True)
class LidarDescription:
    """The robot's planar lidar, as world.json's ``sensors.lidar`` states it: ``height`` (m) above the floor
    under the robot, ``samples`` rays from ``angle_min`` to ``angle_max`` (rad, counter-clockwise from the
    heading, ROS LaserScan spacing), ranges reported in [``range_min``, ``range_max``] (m)."""

    height: float
    samples: int
    angle_min: float
    angle_max: float
    range_min: float
    range_max: float


@dataclass(frozen=True)
class RobotDescription:
    """Everything a simulator needs to build the robot, in one place.

    ``footprint``: the :class:`Robot` feasibility proved drivable (radius, height, clearance, climbing
    limits); ``max_speed`` (m/s), ``turn_rate`` (rad/s, on the spot), ``acceleration`` (m/s^2, speeding up
    and braking): the robot's motion limits, world.json's ``robot.max_speed``, ``max_turn_rate``,
    ``max_acceleration`` where it states them, else the world's parameters, else :data:`MAX_SPEED`,
    :data:`TURN_RATE`, :data:`ACCELERATION`; ``lidar``: its :class:`LidarDescription`; ``mass``: kg of
    the body (:data:`BODY_MASS`).
    """

    footprint: Robot
    max_speed: float
    turn_rate: float
    acceleration: float
    lidar: LidarDescription
    mass: float = BODY_MASS

    def __post_init__(self):
        for name in ("max_speed", "turn_rate", "acceleration", "mass"):
            value = getattr(self, name)
            if not (math.isfinite(value) and value > 0):
                raise ParameterError(f"the robot's {name} must be a finite number > 0, got {value!r}")

    @property
    def radius(self) -> float:
        return self.footprint.radius

    @property
    def height(self) -> float:
        return self.footprint.height
