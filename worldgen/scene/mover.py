"""A dynamic obstacle on a scripted path: plain frozen data, like every other scene value.

A mover is a vertical cylinder standing on the floor (a walking person, say)
whose centre follows ``trajectory``: rows ``(t, x, y)`` in seconds and metres,
visited in order and joined by straight lines walked at constant speed. The
first row is at t = 0. When ``loop`` is true the script repeats after its last
row; worldgen's movers end where they start, so the repetition is seamless.

A person (``person=True``, docs/people.md) is a mover whose trajectory was walked by the
crowd model rather than scripted: it does not loop, and world.json lists it under ``people``.

Movers are not nodes: they carry no static collision geometry, the static
feasibility check ignores them, and each exporter writes them its own way
(SDF actor, MJCF mocap body, left out of URDF).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from worldgen.errors import SceneError
from worldgen.floats import round_float
from worldgen.scene.names import NAME_PATTERN

__all__ = ["Mover", "MOVER_RGBA"]

#: The colour movers are drawn in (a saturated red, unlike any static thing).
MOVER_RGBA = (0.85, 0.20, 0.20, 1.0)


@dataclass(frozen=True)
class Mover:
    """One mover. ``trajectory`` is a tuple of ``(t, x, y)`` rows, t strictly increasing from 0 (given as
    rows or as a (k, 3) array)."""

    name: str
    radius: float
    height: float
    trajectory: tuple[tuple[float, float, float], ...]
    loop: bool = True
    friction: float = 1.0
    person: bool = False

    def __post_init__(self):
        if not NAME_PATTERN.match(self.name):
            raise SceneError(f"mover name {self.name!r} must match {NAME_PATTERN.pattern}")
        for what, value in (("radius", self.radius), ("height", self.height)):
            if not (math.isfinite(value) and value > 0):
                raise SceneError(f"mover {self.name!r}: {what} must be > 0 m, got {value!r}")
        traj = self.trajectory
        if isinstance(traj, np.ndarray) and traj.ndim == 2 and traj.shape[1] == 3:
            # A (k, 3) array (a person's hundreds of rows): checked and read at once.
            finite = bool(np.isfinite(traj).all())
            rows = tuple(map(tuple, traj.astype(float).tolist()))
        else:
            rows = tuple(tuple(float(v) for v in row) for row in traj)
            finite = all(math.isfinite(v) for row in rows for v in row if len(row) == 3)
        if len(rows) < 2 or any(len(row) != 3 for row in rows):
            raise SceneError(f"mover {self.name!r}: trajectory must be at least two (t, x, y) rows")
        if not finite:
            raise SceneError(f"mover {self.name!r}: trajectory values must be finite")
        if rows[0][0] != 0.0:
            raise SceneError(f"mover {self.name!r}: trajectory must start at t = 0, got t = {rows[0][0]!r}")
        if any(b[0] <= a[0] for a, b in zip(rows, rows[1:])):
            raise SceneError(f"mover {self.name!r}: trajectory times must strictly increase")
        object.__setattr__(self, "trajectory", rows)
        object.__setattr__(self, "loop", bool(self.loop))
        object.__setattr__(self, "person", bool(self.person))

    @property
    def period(self) -> float:
        """Duration of one pass of the script, s."""
        return self.trajectory[-1][0]

    def canonical(self) -> dict:
        # "person" only where true, so that worlds with scripted movers keep their hashes.
        return ({"person": True} if self.person else {}) | {
            "name": self.name,
            "radius": round_float(self.radius),
            "height": round_float(self.height),
            "trajectory": [[round_float(v) for v in row] for row in self.trajectory],
            "loop": self.loop,
            "friction": round_float(self.friction),
        }
