"""Where movers are over time: their scripts interpolated, and a MuJoCo world's mocap bodies driven by them.

A mover (:class:`~worldgen.scene.Mover`) walks straight legs at constant speed
between the timed rows of its trajectory. :func:`mover_positions` says where
every mover is at a time ``t`` (looping), and :func:`drive_mocap` writes that
into a MuJoCo ``data.mocap_pos``, which is how the MJCF export's mocap bodies
are meant to move. Both read a World, a Scene, a world.json dict or a list of
movers, so a test can drive a world it only has as files.
"""

from __future__ import annotations

from typing import Mapping

import numpy as np

from worldgen.errors import SceneError
from worldgen.scene.graph import Scene
from worldgen.scene.mover import Mover

__all__ = ["mover_names", "mover_positions", "positions_at", "drive_mocap"]


def _mover_rows(source) -> list[tuple[str, float, np.ndarray, bool]]:
    """(name, height, (k, 3) trajectory, loop) of every mover in a World, Scene, world.json dict or list."""
    if hasattr(source, "scene"):  # a World
        source = source.scene
    if isinstance(source, Scene):
        source = source.movers
    elif isinstance(source, Mapping):
        # The order of the scene's movers and of the MJCF's mocap bodies: scripted movers, then people.
        source = list(source.get("dynamic_obstacles", [])) + list(source.get("people", []))
    out = []
    for m in source:
        if isinstance(m, Mover):
            out.append((m.name, m.height, np.asarray(m.trajectory, dtype=float), m.loop))
        else:
            out.append((m["name"], float(m["height"]), np.asarray(m["trajectory"], dtype=float), bool(m.get("loop", False))))
    return out


def mover_names(source) -> list[str]:
    """Names of the movers of a World, Scene, world.json dict or list of movers, in order."""
    return [name for name, *_ in _mover_rows(source)]


def mover_positions(source, t: float) -> np.ndarray:
    """(n, 2) float: where each mover's centre is at time ``t`` s (straight legs, constant speed).

    ``source`` is a World, a Scene, a world.json dict (``dynamic_obstacles``, then ``people``) or a
    list of movers. A looping mover repeats its script; one that does not loop
    waits at its last point.
    """
    rows = _mover_rows(source)
    return positions_at([traj for _, _, traj, _ in rows], [loop for *_, loop in rows], np.array([t]))[0]


def positions_at(tracks, loops, times: np.ndarray) -> np.ndarray:
    """(len(times), movers, 2): where each mover (its (k, 3) ``t, x, y`` track, looping or not) is at each time."""
    times = np.asarray(times, dtype=float)
    out = np.zeros((len(times), len(tracks), 2))
    for i, (traj, loop) in enumerate(zip(tracks, loops)):
        period = traj[-1, 0]
        tt = np.fmod(times, period) if loop else np.minimum(times, period)
        tt = np.where(tt < 0, tt + period, tt)
        out[:, i, 0] = np.interp(tt, traj[:, 0], traj[:, 1])
        out[:, i, 1] = np.interp(tt, traj[:, 0], traj[:, 2])
    return out


def drive_mocap(model, data, source, t: float) -> None:
    """Put each mover's MuJoCo mocap body where the script has it at ``t`` (call before ``mj_step``).

    ``model``/``data`` are a compiled MJCF world of worldgen and its MjData; the
    mocap body of a mover has the mover's name.
    """
    xy = mover_positions(source, t)
    for (name, height, _, _), (x, y) in zip(_mover_rows(source), xy):
        mocap = model.body(name).mocapid[0]
        if mocap < 0:
            raise SceneError(f"body {name!r} is not a mocap body")
        data.mocap_pos[mocap] = (x, y, height / 2.0)
