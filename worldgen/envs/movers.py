"""Movers in the environment: each mover's MuJoCo mocap body driven along its script, every physics step.

The scripts are world.json's ``dynamic_obstacles[].trajectory`` (``t, x, y``
rows, straight legs at constant speed, looping or waiting at the end), read
exactly as :func:`worldgen.scene.motion.mover_positions` reads them, but for all the
physics steps of one control period at once.
"""

from __future__ import annotations

import numpy as np

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
        times = np.asarray(times, dtype=float)
        out = np.zeros((len(times), len(self.tracks), 2))
        for i, (traj, loop) in enumerate(zip(self.tracks, self.loops)):
            period = traj[-1, 0]
            tt = np.mod(times, period) if loop else np.minimum(times, period)
            out[:, i, 0] = np.interp(tt, traj[:, 0], traj[:, 1])
            out[:, i, 1] = np.interp(tt, traj[:, 0], traj[:, 2])
        return out

    def place(self, data, mocap: np.ndarray, xy: np.ndarray) -> None:
        """Write positions ``xy`` (movers, 2) into ``data.mocap_pos`` for the mocap indices ``mocap``."""
        data.mocap_pos[mocap, 0] = xy[:, 0]
        data.mocap_pos[mocap, 1] = xy[:, 1]
        data.mocap_pos[mocap, 2] = self.z
