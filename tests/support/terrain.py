"""A small terrain world whose reference path drives up a ramp, along its landing and down again: what the
drive and environment tests in MuJoCo and Gazebo share (docs/terrain.md)."""

from __future__ import annotations

import worldgen

__all__ = ["RAMP_PARAMS", "RAMP_SEED", "ramp_world", "KERB_PARAMS", "KERB_SEED"]

#: A 7 x 3 m room, one ramp across it (9.0 to 9.5 degrees, 0.10 to 0.12 m high), the task fixed from one
#: end of the room to the other, so that the straight reference path crosses the ramp.
RAMP_PARAMS = dict(size=(7.0, 3.0), n_obstacles=0, n_kerbs=0, n_rough=0, n_ramps=1, ramp_width=(2.0, 2.4),
                   ramp_incline=(9.0, 9.5), ramp_rise=(0.1, 0.12), ramp_landing=(0.5, 0.8), spawn=(-3.0, 0.0, 0.0),
                   goal=(3.0, 0.0), min_spawn_goal_distance=1.0)
#: The seed whose ramp lies across the path (9.4 degrees, 0.10 m up, a 0.68 m landing; the path is straight).
RAMP_SEED = 5
#: One 6 cm kerb (three times the step the robot climbs, twice its ground clearance) near the straight line
#: from spawn to goal, which the reference path goes round; seed 0 puts it in the straight line's way.
KERB_PARAMS = dict(size=(7.0, 4.0), n_obstacles=0, n_kerbs=1, n_ramps=0, n_rough=0, kerb_height=(0.06, 0.06),
                   kerb_size=(1.0, 1.5), pothole_share=0.0, spawn=(-3.0, 0.0, 0.0), goal=(3.0, 0.0))
KERB_SEED = 0


def ramp_world() -> worldgen.World:
    return worldgen.generate("terrain", seed=RAMP_SEED, **RAMP_PARAMS)
