"""Infeasible worlds on purpose: wall every goal in, for negative tests.

A navigation stack must also be tested on a goal it cannot reach (does it give
up, report failure, not crash into the wall?). With the common parameter
``infeasible=True`` the pipeline takes a normal draft of any generator and
closes a square ring of walls around each task's goal (:func:`wall_in_goals`).
The ring leaves the goal itself free (its inner faces keep ``robot.clearance``
plus :data:`GAP` from the footprint), so ``spawn_free`` and ``goal_free`` still
pass and the report's failed check is ``path_exists``: the world is infeasible
for exactly one stated reason. A generator that has its own way of being
infeasible declares its own ``infeasible`` parameter and is left alone.
"""

from __future__ import annotations

from typing import Optional, Sequence

import numpy as np

from worldgen.floats import round_float
from worldgen.scene import Box, Material, Node, Pose, Robot, Scene, Task

__all__ = ["wall_in_goals", "GAP", "THICKNESS", "BLOCK_RGBA"]

#: Space (m) between the footprint's clearance margin at the goal and the ring's inner faces.
GAP = 0.05
#: Ring wall thickness (m): solid for every simulator's contact solver.
THICKNESS = 0.1
BLOCK_RGBA = (0.45, 0.10, 0.10, 1.0)


def wall_in_goals(scene: Scene, tasks: Sequence[Task], robot: Robot, friction: float) -> tuple[Scene, Optional[str]]:
    """``scene`` with a closed ring of walls around every goal: (scene, None), or (scene, reason).

    The reason is given (and the draft should be redrawn) when a ring would
    touch another task's spawn or goal disc.
    """
    inner = robot.inflation + GAP
    outer = inner + THICKNESS
    height = round_float(max(0.5, 2.0 * (robot.height + robot.clearance)))
    points = np.array([[p.x, p.y] for t in tasks for p in (t.spawn, t.goal)], dtype=float).reshape(-1, 2)
    mat = Material("goal_block", BLOCK_RGBA, friction)
    nodes = list(scene.nodes)
    for k, task in enumerate(tasks):
        gx, gy = task.goal.x, task.goal.y
        # Distance from every other task point to the ring's outer square (0 inside it).
        dx = np.maximum(np.abs(points[:, 0] - gx) - outer, 0.0)
        dy = np.maximum(np.abs(points[:, 1] - gy) - outer, 0.0)
        near = np.hypot(dx, dy) < robot.inflation + GAP
        near[2 * k + 1] = False  # this ring's own goal sits inside it on purpose
        if near.any():
            return scene, f"the wall ring around {task.id}'s goal would touch another spawn or goal"
        span, side = round_float(2 * outer), round_float(2 * inner)
        mid = round_float(inner + THICKNESS / 2)
        walls = (
            ("n", Box((span, THICKNESS, height)), gx, gy + mid),
            ("s", Box((span, THICKNESS, height)), gx, gy - mid),
            ("e", Box((THICKNESS, side, height)), gx + mid, gy),
            ("w", Box((THICKNESS, side, height)), gx - mid, gy),
        )
        for tag, box, x, y in walls:
            nodes.append(Node(f"goal_block_{k}_{tag}", "wall", box,
                              Pose(round_float(x), round_float(y), height / 2), material=mat))
    return scene.with_nodes(nodes), None
