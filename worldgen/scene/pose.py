"""Poses: position plus roll-pitch-yaw about fixed axes, as SDF and URDF define them."""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from worldgen.errors import SceneError

__all__ = ["Pose", "rpy_matrix", "matrix_to_pose"]


def rpy_matrix(roll: float, pitch: float, yaw: float) -> np.ndarray:
    """(3, 3) rotation R = Rz(yaw) @ Ry(pitch) @ Rx(roll)."""
    cr, sr = math.cos(roll), math.sin(roll)
    cp, sp = math.cos(pitch), math.sin(pitch)
    cy, sy = math.cos(yaw), math.sin(yaw)
    return np.array(
        [
            [cy * cp, cy * sp * sr - sy * cr, cy * sp * cr + sy * sr],
            [sy * cp, sy * sp * sr + cy * cr, sy * sp * cr - cy * sr],
            [-sp, cp * sr, cp * cr],
        ]
    )


@dataclass(frozen=True)
class Pose:
    """A rigid transform: metres and radians, REP 103 frames."""

    x: float = 0.0
    y: float = 0.0
    z: float = 0.0
    roll: float = 0.0
    pitch: float = 0.0
    yaw: float = 0.0

    def __post_init__(self):
        for name in ("x", "y", "z", "roll", "pitch", "yaw"):
            value = float(getattr(self, name))
            if not math.isfinite(value):
                raise SceneError(f"pose {name} must be finite, got {value!r}")
            object.__setattr__(self, name, value)

    @property
    def position(self) -> np.ndarray:
        """(3,) float."""
        return np.array([self.x, self.y, self.z])

    @property
    def rotation(self) -> np.ndarray:
        """(3, 3) float."""
        return rpy_matrix(self.roll, self.pitch, self.yaw)

    def matrix(self) -> np.ndarray:
        """(4, 4) homogeneous transform, child frame expressed in the parent frame."""
        m = np.eye(4)
        m[:3, :3] = self.rotation
        m[:3, 3] = self.position
        return m

    def as_list(self) -> list[float]:
        """``[x, y, z, roll, pitch, yaw]`` as in world.json."""
        return [self.x, self.y, self.z, self.roll, self.pitch, self.yaw]

    def is_yaw_only(self, tol: float = 1e-12) -> bool:
        """True when the frame's z axis stays vertical (only a yaw rotation)."""
        return abs(self.roll) <= tol and abs(self.pitch) <= tol

    def compose(self, child: "Pose") -> "Pose":
        """The pose of ``child`` (given in this frame) in this frame's parent."""
        return matrix_to_pose(self.matrix() @ child.matrix())


def matrix_to_pose(m: np.ndarray) -> Pose:
    """Inverse of :meth:`Pose.matrix` for a (4, 4) rigid transform."""
    r = m[:3, :3]
    pitch = math.asin(max(-1.0, min(1.0, -r[2, 0])))
    if abs(r[2, 0]) < 1.0 - 1e-12:
        roll = math.atan2(r[2, 1], r[2, 2])
        yaw = math.atan2(r[1, 0], r[0, 0])
    else:  # gimbal lock: fold roll into yaw
        roll = 0.0
        yaw = math.atan2(-r[0, 1], r[1, 1])
    return Pose(m[0, 3], m[1, 3], m[2, 3], roll, pitch, yaw)
