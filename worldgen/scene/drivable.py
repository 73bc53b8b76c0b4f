"""Where a wheeled robot may not put its footprint on a scene's terrain, and the step edges it crosses.

A place is drivable when the incline under the footprint and every step edge within it are within the
robot's climbing limits (:class:`~worldgen.scene.Robot`). What is not drivable comes back as floor
polygons (:func:`terrain_footprints`, role ``terrain``) that the feasibility planner inflates like any
obstacle's shadow, so the exact planner runs on the drivable set. Per element (docs/terrain.md):

- a ramp steeper than ``max_incline``, or whose foot or crest bends more than the chassis clears
  (a kink of angle t is cleared when ``radius * tan(t / 2) <= ground_clearance``: the ground's rise
  above the chord between two contact points ``radius`` either side of it), is not drivable anywhere;
  otherwise only the parts of its two sides that drop by more than the step limits are edges to keep off;
- a step higher (a pothole deeper) than the step limits has its four edges as thin polygons;
- a rough patch steeper than ``max_incline`` anywhere, or whose highest and lowest points differ by more
  than ``ground_clearance``, is not drivable anywhere.

An edge is crossed both up and down by a path that goes over it, so the smaller of ``max_step_up`` and
``max_step_down`` is the limit for every edge (conservative where a path only climbs).
"""

from __future__ import annotations

import math
from typing import Optional

import numpy as np
import shapely

from worldgen.scene.footprint import Footprint
from worldgen.scene.graph import Robot, Scene
from worldgen.scene.terrain import Ramp, Rough, Step, Terrain

__all__ = ["terrain_footprints", "step_edges", "EDGE_THICKNESS", "kink_cleared", "ramp_side_height"]

#: How thick a step edge is as a polygon (m): the planner takes polygons with area, and a tenth of a
#: millimetre, centred on the edge, keeps the forbidden set's boundary within 0.05 mm of the true edge.
EDGE_THICKNESS = 1e-4


def kink_cleared(angle_deg: float, robot: Robot) -> bool:
    """True when a bend of ``angle_deg`` in the ground passes under the chassis."""
    return robot.radius * math.tan(math.radians(angle_deg) / 2) <= robot.ground_clearance + 1e-12


def _ramp_drivable(ramp: Ramp, robot: Robot) -> bool:
    crest = ramp.incline if ramp.landing > 0 else 2 * ramp.incline
    return ramp.incline <= math.degrees(robot.max_incline) + 1e-9 and kink_cleared(ramp.incline, robot) and \
        kink_cleared(crest, robot)


def _rough_drivable(rough: Rough, robot: Robot) -> bool:
    grid = rough.array
    steepest = math.degrees(math.atan(rough.steepest()))
    return steepest <= math.degrees(robot.max_incline) + 1e-9 and float(grid.max() - grid.min()) <= robot.ground_clearance + 1e-12


def ramp_side_height(ramp: Ramp, u: np.ndarray) -> np.ndarray:
    """The height of a ramp's side edge (its drop to the floor) at local ``u``."""
    up = np.minimum(u + ramp.length / 2, ramp.length / 2 - u)
    return ramp.rise * np.clip(up / ramp.run, 0.0, 1.0)


def step_edges(terrain: Terrain) -> list[tuple[int, shapely.LineString, Optional[Ramp], float]]:
    """Every step edge: (element index, the edge as a world line, the ramp it is a side of or None, the
    edge's height: a step's |height|, a ramp side's highest point)."""
    out: list[tuple[int, shapely.LineString, Optional[Ramp], float]] = []
    for k, e in enumerate(terrain.elements):
        hl, hw = e.length / 2, e.width / 2
        if isinstance(e, Step):
            corners = e.to_world(np.array([[-hl, -hw], [hl, -hw], [hl, hw], [-hl, hw]]))
            for a in range(4):
                out.append((k, shapely.LineString([corners[a], corners[(a + 1) % 4]]), None, abs(e.height)))
        elif isinstance(e, Ramp):
            for side in (-hw, hw):
                out.append((k, shapely.LineString(e.to_world(np.array([[-hl, side], [hl, side]]))), e, e.rise))
    return out


def terrain_footprints(scene: Scene, robot: Robot) -> list[Footprint]:
    """The floor polygons ``robot`` may not touch with its footprint on ``scene``'s terrain (none on flat
    ground), named ``terrain_<element>`` (``_edge_<k>`` for an edge)."""
    terrain = scene.terrain
    if terrain is None:
        return []
    limit = min(robot.max_step_up, robot.max_step_down)
    out: list[Footprint] = []
    for k, e in enumerate(terrain.elements):
        name = f"terrain_{k}"
        if isinstance(e, Ramp) and not _ramp_drivable(e, robot) or isinstance(e, Rough) and not _rough_drivable(e, robot):
            out.append(Footprint(name, "terrain", polygon=e.outline()))
        elif isinstance(e, Step) and abs(e.height) > limit + 1e-12:
            hl, hw, t = e.length / 2, e.width / 2, EDGE_THICKNESS / 2
            for a, (u0, u1, v0, v1) in enumerate(((-hl - t, hl + t, -hw - t, -hw + t), (-hl - t, hl + t, hw - t, hw + t),
                                                  (-hl - t, -hl + t, -hw, hw), (hl - t, hl + t, -hw, hw))):
                out.append(Footprint(f"{name}_edge_{a}", "terrain", polygon=_rect(e, u0, u1, v0, v1)))
        elif isinstance(e, Ramp) and e.rise > limit + 1e-12:
            # The side drops more than the limit where it has climbed past limit / rise of its run.
            reach = e.length / 2 - e.run * limit / e.rise
            hw, t = e.width / 2, EDGE_THICKNESS / 2
            for a, side in enumerate((-hw, hw)):
                out.append(Footprint(f"{name}_edge_{a}", "terrain", polygon=_rect(e, -reach, reach, side - t, side + t)))
    return out


def _rect(e, u0: float, u1: float, v0: float, v1: float) -> shapely.Polygon:
    return shapely.Polygon(e.to_world(np.array([[u0, v0], [u1, v0], [u1, v1], [u0, v1]])))
