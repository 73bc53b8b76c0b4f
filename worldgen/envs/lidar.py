"""The robot's planar lidar: MuJoCo ray casting, optional noise and binning into sectors.

Beam ``i`` points ``angle_min + i * (angle_max - angle_min) / (beams - 1)``
counter-clockwise from the robot's heading, exactly as world.json's
``sensors.lidar`` (:func:`worldgen.groundtruth.lidar.spec_from_params`: unset,
the field of view is centred ahead, and a full circle casts no ray twice). All
beams are cast at once with ``mujoco.mj_multiRay`` from the robot's centre at
``height`` above the floor, skipping the robot's own body and visual-only geoms
(group 2, worldgen's markers), so they see walls, obstacles, door leaves and
movers. A beam that hits nothing within ``range_max`` reads ``range_max``;
every reading is clipped into ``[range_min, range_max]``.

Noise (``noise`` > 0): Gaussian with that standard deviation, added to every
beam that hit something, drawn from the generator the environment passes in
(one normal per beam, hit or not, so the draws never depend on the scene);
the result is clipped again. Sectors (``sectors`` set): the beams, in order,
split into equal runs, each reporting its smallest reading, as the deep-RL
navigation walkthroughs feed a policy.
"""

from __future__ import annotations

import math
from typing import Optional

import numpy as np

from worldgen.groundtruth.lidar import angles, spec_from_params
from worldgen.scene import Pose

__all__ = ["Lidar", "VISUAL_GROUP"]

#: MJCF geom group of worldgen's visual-only geoms (markers); beams pass through it.
VISUAL_GROUP = 2


def _has_normals() -> bool:
    """Whether this MuJoCo's ``mj_multiRay`` takes the ``normal`` output (newer releases) before ``nray``."""
    import mujoco

    return "normal" in (mujoco.mj_multiRay.__doc__ or "")


_MULTIRAY_NORMALS = _has_normals()


class Lidar:
    """A scan of ``beams`` rays over ``fov`` (rad) from ``angle_min`` (None: centred ahead)."""

    def __init__(self, beams: int, fov: float, angle_min: Optional[float], range_min: float, range_max: float,
                 noise: float = 0.0, sectors: Optional[int] = None):
        params = {"lidar_fov": fov, "lidar_samples": beams, "lidar_angle_min": angle_min, "lidar_height": 1.0,
                  "lidar_range_min": range_min, "lidar_range_max": range_max}
        spec = spec_from_params(params, Pose(0.0, 0.0, 0.0))
        #: (beams,) angle of each beam from the heading, rad (read-only).
        self.angles = angles(spec)
        self.angles.setflags(write=False)
        self.angle_min, self.angle_max = spec.angle_min, spec.angle_max
        self.beams, self.sectors = beams, sectors
        self.range_min, self.range_max, self.noise = float(range_min), float(range_max), float(noise)
        self._cos, self._sin = np.cos(self.angles), np.sin(self.angles)
        self._vec = np.zeros((beams, 3))
        self._dist = np.zeros(beams)
        self._geom = np.zeros(beams, dtype=np.int32)
        self._pnt = np.zeros(3)
        groups = np.ones(6, dtype=np.uint8)
        groups[VISUAL_GROUP] = 0
        self._groups = groups

    @property
    def size(self) -> int:
        """Length of :meth:`observe`'s output: sectors when binning, else beams."""
        return self.sectors or self.beams

    def cast(self, model, data, x: float, y: float, yaw: float, height: float, exclude_body: int,
             frame: Optional[tuple] = None) -> np.ndarray:
        """(beams,) noise-free ranges (m) from (x, y, height) with heading ``yaw``; a new array. ``frame``
        (origin (3,), rotation (3, 3)) casts from a tilted lidar instead: the beams in the frame's x-y plane,
        from its x axis (the robot on terrain, worldgen.envs.terrain)."""
        import mujoco

        vec = self._vec
        if frame is None:
            c, s = math.cos(yaw), math.sin(yaw)
            vec[:, 0] = self._cos * c - self._sin * s
            vec[:, 1] = self._sin * c + self._cos * s
            vec[:, 2] = 0.0  # after a tilted cast
            self._pnt[:] = (x, y, height)
        else:
            origin, rotation = frame
            vec[:] = np.outer(self._cos, rotation[:, 0]) + np.outer(self._sin, rotation[:, 1])
            self._pnt[:] = origin
        if _MULTIRAY_NORMALS:
            mujoco.mj_multiRay(model, data, self._pnt, vec.reshape(-1), self._groups, 1, exclude_body,
                               self._geom, self._dist, None, self.beams, self.range_max)
        else:  # MuJoCo releases before mj_multiRay's ``normal`` output
            mujoco.mj_multiRay(model, data, self._pnt, vec.reshape(-1), self._groups, 1, exclude_body,
                               self._geom, self._dist, self.beams, self.range_max)
        d = self._dist
        ranges = np.where((d < 0.0) | (d > self.range_max), self.range_max, d)
        np.maximum(ranges, self.range_min, out=ranges)
        return ranges

    def observe(self, ranges: np.ndarray, rng: Optional[np.random.Generator]) -> np.ndarray:
        """What the policy sees of noise-free ``ranges``: noise added (drawn from ``rng``), clipped, binned."""
        out = ranges
        if self.noise > 0.0:
            assert rng is not None, "a noisy lidar draws its noise from a generator"
            draws = rng.normal(0.0, self.noise, self.beams)
            out = np.where(ranges < self.range_max, ranges + draws, ranges)
            np.clip(out, self.range_min, self.range_max, out=out)
        if self.sectors:
            out = out.reshape(self.sectors, -1).min(axis=1)
        return out
