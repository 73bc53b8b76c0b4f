"""What moves in ``world.usda``, and where the tasks are: movers and people as time-sampled kinematic
bodies, spawns and goals as named Xforms (:mod:`worldgen.export.usd` writes the rest of the stage).

A mover or person ``/World/Movers/<name>`` or ``/World/People/<name>`` is an ``Xform`` with
``PhysicsRigidBodyAPI`` and ``physics:kinematicEnabled = true`` (moved by its animation, pushing what
it meets, never pushed) holding its cylinder (``shape``, a collider, base on the floor). Its
``xformOp:translate`` has one time sample per row of world.json's trajectory: ``(x, y, height / 2)``
at time code ``t x`` :data:`TIME_CODES_PER_SECOND`, which is the stage's ``timeCodesPerSecond``, so
a sample's time code over that rate is world.json's time in seconds. USD interpolates time samples
linearly (a stage's default), which is exactly world.json's walk: straight legs at constant speed.
Past its last sample a prim holds its last value, as a person stands where it stopped. USD has no
looping samples, so a looping mover's script is written out period after period until ``duration``
(the longest task's ``time_limit``, the longest walk, at least one period): after that it stands.

``/World/Tasks/<task id>`` holds ``spawn`` and ``goal``: Xforms at world.json's poses (yaw as an
``orient`` quaternion); ``goal`` carries ``worldgen:goalTolerance`` (m).
"""

from __future__ import annotations

import math
from typing import Sequence

import numpy as np

from worldgen.export.usd_prims import Specs, quaternion
from worldgen.floats import round_float
from worldgen.scene.mover import MOVER_RGBA, Mover
from worldgen.scene.shapes import Cylinder

__all__ = ["TIME_CODES_PER_SECOND", "samples", "horizon", "writer_args", "write_movers", "write_tasks"]

#: The stage's timeCodesPerSecond (and framesPerSecond): Isaac Sim's default rate, so the movers play at
#: the right speed in its timeline as it comes; a time code is 60 x world.json's seconds.
TIME_CODES_PER_SECOND = 60


def samples(mover: Mover, duration: float = 0.0) -> np.ndarray:
    """(k, 3) ``t, x, y``: the mover's rows, a looping one's repeated until ``duration`` s (one period at least).

    worldgen's looping movers end where they start, so a repetition starts from its second row.
    """
    rows = np.asarray(mover.trajectory, dtype=float)
    if not mover.loop:
        return rows
    period = mover.period
    repeats = max(1, math.ceil(duration / period - 1e-9))
    parts = [rows] + [rows[1:] + np.array([k * period, 0.0, 0.0]) for k in range(1, repeats)]
    return np.concatenate(parts)


def horizon(world) -> float:
    """How long (s) a world's looping movers are written out for: its longest task time limit or walk."""
    from worldgen.export.tasks import task_entry

    limits = [task_entry(world, task, path)["time_limit"] for task, path in zip(world.tasks, world.feasibility.paths)
              if path is not None]
    ends = [m.period for m in world.scene.movers]
    return max(limits + ends + [0.0])


def writer_args(world) -> dict:
    """What :func:`worldgen.export.usd.to_usd` reads off a World besides its scene: tasks and duration."""
    return {"tasks": world.tasks, "duration": horizon(world)}


def write_movers(specs: Specs, world, movers: Sequence[Mover], materials: dict[float, str], duration: float) -> float:
    """Write every mover and person under ``world``; return the last time code written (0 without any)."""
    end = 0.0
    scopes: dict[str, object] = {}
    for mover in movers:
        group = "People" if mover.person else "Movers"
        if group not in scopes:
            scopes[group] = specs.prim(world, group, "Scope")
        prim = specs.prim(scopes[group], mover.name, "Xform", ["PhysicsRigidBodyAPI"])
        specs.attr(prim, "physics:kinematicEnabled", "Bool", True)
        rows = samples(mover, duration)
        z = mover.height / 2.0
        translate = specs.attr(prim, "xformOp:translate", "Double3", None)
        Vec3d, path, put = specs.Gf.Vec3d, translate.path, specs.layer.SetTimeSample
        # Time codes rounded like every other number: world.json's times have 6 decimals.
        for t, x, y in rows.tolist():
            put(path, round_float(t * TIME_CODES_PER_SECOND), Vec3d(round_float(x), round_float(y), round_float(z)))
        specs.attr(prim, "xformOpOrder", "TokenArray", ["xformOp:translate"], uniform=True)
        specs.shape(prim, Cylinder(mover.radius, mover.height), MOVER_RGBA, materials[mover.friction], rigid=True)
        end = max(end, round_float(float(rows[-1, 0]) * TIME_CODES_PER_SECOND))
    return end


def write_tasks(specs: Specs, world, tasks) -> None:
    """``/World/Tasks/<id>/spawn`` and ``goal`` for each task, in order."""
    if not tasks:
        return
    scope = specs.prim(world, "Tasks", "Scope")
    for task in tasks:
        holder = specs.prim(scope, task.id, "Scope")
        for label, pose in (("spawn", task.spawn), ("goal", task.goal)):
            prim = specs.prim(holder, label, "Xform")
            specs.transform(prim, pose.position, quaternion(pose.roll, pose.pitch, pose.yaw))
            if label == "goal":
                attr = specs.attr(prim, "worldgen:goalTolerance", "Double", round_float(task.goal_tolerance))
                attr.custom = True
