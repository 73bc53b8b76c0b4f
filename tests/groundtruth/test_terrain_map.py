"""map.pgm on terrain: every cell whose square meets ground the robot cannot drive is occupied, the cells
the proven path runs through stay free, and a robot that can drive everything gets the obstacles' map."""

import numpy as np
import shapely

import worldgen
from worldgen.groundtruth import occupancy, truth
from worldgen.scene.drivable import terrain_footprints

STEEP = dict(size=[12, 12], n_kerbs=4, kerb_height=[0.05, 0.08], n_ramps=2, ramp_incline=[12, 14], n_rough=1)


def centres(grid, rows, cols):
    (ox, oy), h = grid.origin, grid.resolution
    return np.column_stack([ox + (cols + 0.5) * h, oy + (rows + 0.5) * h])


def test_cells_of_ground_the_robot_cannot_drive_are_occupied_and_the_path_stays_free():
    world = worldgen.generate("terrain", 2, **STEEP)
    grid = truth.occupancy_map(world)
    plain = occupancy.build(truth.planning_scene(world), world.params["map_height"], world.params["map_resolution"])
    forbidden = terrain_footprints(world.scene, world.robot)
    assert forbidden and grid.occupied.sum() > plain.occupied.sum()
    assert (grid.occupied | ~plain.occupied).all()  # the obstacles' cells are all still there
    added = grid.occupied & ~plain.occupied
    rows, cols = np.nonzero(added)
    h = grid.resolution
    union = shapely.union_all([f.polygon for f in forbidden])
    # Every added cell meets undrivable ground, and every cell whose centre lies in it was added.
    assert (shapely.distance(shapely.points(centres(grid, rows, cols)), union) <= h * 0.7072).all()
    rr, cc = np.nonzero(~grid.occupied)
    assert not shapely.contains_xy(union, *centres(grid, rr, cc).T).any()
    for path in world.feasibility.paths:
        line = shapely.LineString(path.waypoints)
        pts = np.array([line.interpolate(d).coords[0] for d in np.arange(0.0, line.length, h / 2)])
        (ox, oy) = grid.origin
        cells = np.floor((pts - [ox, oy]) / h).astype(int)
        assert not grid.occupied[cells[:, 1], cells[:, 0]].any()


def test_a_robot_that_drives_everything_gets_the_obstacles_map():
    world = worldgen.generate("terrain", 2, **dict(STEEP, robot_max_incline=45, robot_max_step_up=0.5,
                                                      robot_max_step_down=0.5, robot_ground_clearance=0.5))
    plain = occupancy.build(truth.planning_scene(world), world.params["map_height"], world.params["map_resolution"])
    assert terrain_footprints(world.scene, world.robot) == []
    assert np.array_equal(truth.occupancy_map(world).occupied, plain.occupied)
