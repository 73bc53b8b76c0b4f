"""Movers in the environment: each mover's MuJoCo mocap body driven along its script, every physics step.

The scripts are world.json's ``dynamic_obstacles[].trajectory`` (``t, x, y``
rows, straight legs at constant speed, looping or waiting at the end), read by
:func:`worldgen.scene.motion.positions_at` (as :func:`~worldgen.scene.motion.mover_positions`
reads them) for all the physics steps of one control period at once.
"""

from __future__ import annotations

import numpy as np

from worldgen.scene.motion import positions_at

__all__ = ["MoverScript"]


class MoverScript:
    """The movers of one world (world.json ``dynamic_obstacles`` entries), positioned at many times at once."""

    def __init__(self, movers: list):
        self.tracks = [np.asarray(m["trajectory"], dtype=float) for m in movers]
        self.loops = [bool(m["loop"]) for m in movers]
        self.z = np.array([float(m["height"]) / 2.0 for m in movers])

    def __len__(self) -> int:
        return len(self.tracks)

    def positions(self, times: np.ndarray) -> np.ndarray:
        """(len(times), movers, 2): where each mover's centre is at each time (s)."""
        return positions_at(self.tracks, self.loops, times)

    def place(self, data, mocap: np.ndarray, xy: np.ndarray) -> None:
        """Write positions ``xy`` (movers, 2) into ``data.mocap_pos`` for the mocap indices ``mocap``."""
        data.mocap_pos[mocap, 0] = xy[:, 0]
        data.mocap_pos[mocap, 1] = xy[:, 1]
        data.mocap_pos[mocap, 2] = self.z
