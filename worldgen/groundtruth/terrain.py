"""The terrain in the occupancy map: the cells of ground the robot cannot drive are occupied.

nav2 reads map.pgm as the places it may not go; on terrain those are the obstacles' cross-section and,
for the robot world.json names, every cell whose square meets ground it cannot drive
(worldgen.scene.drivable: a ramp or rough patch too steep, a step edge too high, each a floor polygon).
Cells are marked as the obstacles' are: closed squares, a mere touch along an edge does not count.
"""

from __future__ import annotations

import math

import numpy as np
import shapely

from worldgen.groundtruth.occupancy import OccupancyMap
from worldgen.scene import Robot, Scene
from worldgen.scene.drivable import terrain_footprints

__all__ = ["with_undrivable"]


def with_undrivable(grid: OccupancyMap, scene: Scene, robot: Robot) -> OccupancyMap:
    """``grid`` with the cells ``robot`` cannot drive on ``scene``'s terrain occupied (``grid`` itself on
    flat ground or where the robot can drive all of it)."""
    polygons = [f.polygon for f in terrain_footprints(scene, robot) if f.polygon is not None]  # all are polygons
    if not polygons:
        return grid
    occupied = grid.occupied.copy()
    rows, cols = occupied.shape
    (ox, oy), h = grid.origin, grid.resolution
    for polygon in polygons:
        x0, y0, x1, y1 = polygon.bounds
        c0, c1 = max(int(math.floor((x0 - ox) / h)), 0), min(int(math.ceil((x1 - ox) / h)), cols)
        r0, r1 = max(int(math.floor((y0 - oy) / h)), 0), min(int(math.ceil((y1 - oy) / h)), rows)
        if c0 >= c1 or r0 >= r1:
            continue
        rr, cc = np.mgrid[r0:r1, c0:c1]
        cells = shapely.box(ox + cc * h, oy + rr * h, ox + (cc + 1) * h, oy + (rr + 1) * h)
        meets = shapely.intersects(cells, polygon) & ~shapely.touches(cells, polygon)
        occupied[rr[meets], cc[meets]] = True
    return OccupancyMap(occupied, grid.origin, grid.resolution)
