"""The robot every feasibility figure is computed for: its footprint and, on terrain, its climbing limits."""

from __future__ import annotations

import math
from dataclasses import dataclass

__all__ = ["Robot", "CLIMB_DEFAULTS"]

#: The climbing limits a robot has unless told otherwise, typical of a small indoor differential-drive base
#: (not one robot's datasheet): 10 degrees, above the 1:12 (4.8 degree) ramps building codes allow for
#: wheelchairs, so those ramps pass; steps of 20 mm up or down, the threshold Misty Robotics specified for
#: Misty II to cross door sills (about 19 mm); 30 mm under the chassis.
CLIMB_DEFAULTS = {"max_incline": round(math.radians(10.0), 6), "max_step_up": 0.02, "max_step_down": 0.02,
                  "ground_clearance": 0.03}


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
