"""One control period of the environment's physics: the physics steps between two actions, with the
movers placed before each step and the robot's contacts recorded as they begin.

Reacting people (:mod:`worldgen.envs.reacting`) see the robot where it is at the period's start, moving
as it did over the last period, and are stepped once to the period's end; the physics steps then place
them along that step. A contact is a geom the robot's geom touches that is not the floor's.
"""

from __future__ import annotations

import numpy as np

from worldgen.envs.episode import Episode
from worldgen.envs.reacting import Walkers
from worldgen.envs.robot import RobotModel

__all__ = ["run_period", "touching"]


def run_period(sim: RobotModel, ep: Episode, movers: Walkers, n: int, robot_radius: float,
               stop_on_contact: bool) -> bool:
    """``n`` physics steps of ``sim`` (the movers driven before each), every contact recorded in ``ep``;
    True when a contact began (the period ends there when ``stop_on_contact``)."""
    import mujoco

    model, data = sim.model, sim.data
    xy = None
    if len(movers):  # reacting people see the robot where it is, moving as it did over the last period
        rows = ep.rows
        (t0, x0, y0, _), (t1, x1, y1, _) = rows[max(len(rows) - 2, 0)], rows[-1]
        v = ((x1 - x0) / (t1 - t0), (y1 - y0) / (t1 - t0)) if t1 > t0 else (0.0, 0.0)
        xy = movers.period(data.time, model.opt.timestep, n, (x1, y1), v, robot_radius)
    began = False
    for k in range(n):
        if xy is not None:
            movers.place(data, sim.mocap, xy[k])
        mujoco.mj_step(model, data)
        if data.ncon or ep.touching:
            if ep.touch(data.time, touching(sim)):
                began = True
                if stop_on_contact:
                    break
    return began


def touching(sim: RobotModel) -> frozenset:
    """Names of the entities the robot's geom is in contact with now (the floor left out)."""
    import mujoco

    data = sim.data
    if not data.ncon:
        return frozenset()
    pairs = data.contact.geom[: data.ncon]
    mine = (pairs[:, 0] == sim.geom) | (pairs[:, 1] == sim.geom)
    others = np.where(pairs[mine, 0] == sim.geom, pairs[mine, 1], pairs[mine, 0])
    return frozenset(mujoco.mj_id2name(sim.model, mujoco.mjtObj.mjOBJ_GEOM, int(g)) or f"geom_{int(g)}"
                     for g in others if int(g) not in sim.floor)
