"""The geodesic distance to the goal for the robot's footprint, as a field built once per episode.

The feasibility proof's configuration space (:class:`~worldgen.feasibility.cspace.ConfigSpace`:
every footprint grown by the disc of radius ``robot.inflation`` + the planner's ``SAFETY``,
doors at their open limit) is sampled on a square grid of ``spacing`` metres over the
world's bounds, and the distance to the goal is propagated over it:

- **exact where the goal is in sight**: a grid node whose straight segment to the goal is
  free for the disc (the configuration space's own exact segment test) gets the
  straight-line distance; so does a query point in a cell whose four corners all are, and a
  point in a cell on the edge of the goal's view or of the free space whose own segment is
  free (tested exactly);
- **elsewhere**: Dijkstra over the free nodes with 16-connectivity (moves (1, 0), (1, 1),
  (2, 1) and their mirrors), seeded with those exact values. A 16-connected path is at most
  1 / cos(13.28 deg) - 1 = 2.75 % longer than the straight line it stands for, and it may
  bend only at nodes, so where the goal is out of sight the field can exceed the exact
  geodesic by at most 2.75 % of the distance to the nearest point in sight of the goal plus
  about one spacing per corner turned (and a chord between two free nodes can cut into a
  rounded corner by at most c^2 / (8 rho) for a move of length c: 1.6 mm at 5 cm, rho = 0.2 m);
  never below it by more than that cut. Between nodes: bilinear interpolation.
- **where the disc does not fit but the robot still does** (within the clearance of an obstacle,
  where the robot may drive without touching): the same Dijkstra continues there from the free
  nodes, one way (a path may end in that band but not pass through it), so the field is
  defined wherever the robot's centre can be and is not shortened by gaps the disc cannot pass.
  Nodes inside a footprint take their nearest defined node's value plus the distance to it.

The grid has ``spacing`` m cells (5 cm by default), coarsened for large worlds so that it holds
at most :data:`MAX_NODES` nodes. Building it for the ``drl_arena`` preset's 10 x 10 m room
(40,401 nodes) is measured by ``benchmarks/bench_env.py`` (the reset's ``geodesic`` part).
"""

from __future__ import annotations

import math

import numpy as np

__all__ = ["GeodesicField", "MAX_NODES"]

#: Largest number of grid nodes; a larger world gets a coarser grid (spacing grows with its extent).
MAX_NODES = 250_000
#: The 16-connected moves (each also taken backwards).
_MOVES = ((1, 0), (0, 1), (1, 1), (1, -1), (2, 1), (1, 2), (2, -1), (1, -2))


class GeodesicField:
    """Geodesic distance (m) to ``goal`` for the disc of ``cs.radius`` in ``cs``; see the module's docstring."""

    # long: builds the field in one pass (grid, footprint fill, Dijkstra); the steps share a dozen arrays
    def __init__(self, cs, goal, bounds, spacing: float = 0.05):
        from scipy.sparse import csr_matrix
        from scipy.sparse.csgraph import dijkstra

        self.cs = cs
        self.goal = np.asarray(goal, dtype=float).reshape(2)
        (x0, y0), (x1, y1) = bounds
        h = max(float(spacing), math.sqrt((x1 - x0) * (y1 - y0) / MAX_NODES))
        nx, ny = int(math.ceil((x1 - x0) / h)) + 1, int(math.ceil((y1 - y0) / h)) + 1
        self.origin, self.h, self.shape = (float(x0), float(y0)), h, (nx, ny)
        gx, gy = np.meshgrid(x0 + h * np.arange(nx), y0 + h * np.arange(ny), indexing="ij")
        pts = np.stack([gx.ravel(), gy.ravel()], axis=1)
        n = len(pts)
        # Where the disc fits (the configuration space) and where the robot's centre can be at all.
        d_obs = _obstacle_distance(cs.obstacles, self.origin, h, (nx, ny), cs.radius).ravel()
        bx0, by0, bx1, by1 = cs.box
        in_box = (pts[:, 0] >= bx0) & (pts[:, 0] <= bx1) & (pts[:, 1] >= by0) & (pts[:, 1] <= by1)
        free = in_box & (d_obs >= cs.radius)
        band = (d_obs > 0.0) & ~free
        # Exact where the goal is in sight.
        rows = np.flatnonzero(free)
        seen = np.zeros(n, dtype=bool)
        seen[rows[cs.segments_clear(pts[rows], np.broadcast_to(self.goal, (len(rows), 2)))]] = True
        euclid = np.hypot(pts[:, 0] - self.goal[0], pts[:, 1] - self.goal[1])
        # The graph: free <-> free and band <-> band both ways, free -> band only; node n is a super source
        # joined to every node in sight of the goal by its exact distance (+1, since a zero weight is no edge).
        idx = np.arange(n).reshape(nx, ny)
        src, dst, w = [np.full(int(seen.sum()), n)], [np.flatnonzero(seen)], [euclid[seen] + 1.0]
        ok = free | band
        for dx, dy in _MOVES:
            a = idx[max(0, -dx): nx - max(0, dx), max(0, -dy): ny - max(0, dy)].ravel()
            b = a + dx * ny + dy
            both = ok[a] & ok[b]
            a, b = a[both], b[both]
            length = h * math.hypot(dx, dy)
            # a -> b, unless it leaves the band for free space; never into a node in sight of the goal
            # (its exact value is final), which leaves most edges out of the search.
            forward = ~(band[a] & free[b]) & ~seen[b]
            backward = ~(free[a] & band[b]) & ~seen[a]
            src += [a[forward], b[backward]]
            dst += [b[forward], a[backward]]
            w += [np.full(int(forward.sum()), length), np.full(int(backward.sum()), length)]
        s, d, ww = np.concatenate(src), np.concatenate(dst), np.concatenate(w)
        graph = csr_matrix((ww, (s, d)), shape=(n + 1, n + 1))
        dist = dijkstra(graph, directed=True, indices=n)[:n] - 1.0
        dist[seen] = euclid[seen]
        # Inside footprints (and anything unreached): the nearest defined node's value plus the way there.
        known = np.isfinite(dist)
        if not known.all() and known.any():
            from scipy.ndimage import distance_transform_edt

            far, (ii, jj) = distance_transform_edt(~known.reshape(nx, ny), return_indices=True)
            near = (ii * ny + jj).ravel()
            dist = np.where(known, dist, dist[near] + h * far.ravel())
        elif not known.any():
            dist = euclid.copy()
        self.values = dist.reshape(nx, ny)
        self.seen = seen.reshape(nx, ny)
        # Per cell: 1 all four corners in sight of the goal (the straight line holds inside, up to an obstacle
        # corner poking in between nodes); 2 some are, or some corner is not free (a point inside may still
        # see the goal): test the point itself; 0 none is and all are free: interpolate.
        s4 = self.seen.astype(np.int8)
        f4 = free.reshape(nx, ny).astype(np.int8)
        seen_corners = s4[:-1, :-1] + s4[1:, :-1] + s4[:-1, 1:] + s4[1:, 1:]
        free_corners = f4[:-1, :-1] + f4[1:, :-1] + f4[:-1, 1:] + f4[1:, 1:]
        self._cell = np.where(seen_corners == 4, 1, np.where((seen_corners > 0) | (free_corners < 4), 2, 0)).astype(np.int8)

    @classmethod
    def for_scene(cls, scene, robot, goal, spacing: float = 0.05) -> "GeodesicField":
        """The field of ``scene`` (doors open, as the feasibility proof plans; the ground ``robot`` cannot drive
        in the way) for ``robot``, to ``goal`` (x, y)."""
        from worldgen.feasibility.check import SAFETY
        from worldgen.feasibility.cspace import ConfigSpace
        from worldgen.feasibility.geometry import Obstacles2D
        from worldgen.scene.doors import open_scene
        from worldgen.scene.drivable import terrain_footprints
        from worldgen.scene.footprint import robot_footprints

        opened = open_scene(scene)
        # Ground the robot cannot drive is in the way as the feasibility proof has it ([] on flat ground).
        obstacles = Obstacles2D.from_footprints(robot_footprints(opened, robot) + terrain_footprints(opened, robot))
        cs = ConfigSpace.build(obstacles, robot.inflation + SAFETY, opened.bounds)
        return cls(cs, goal, opened.bounds, spacing)

    def straight_free(self, x: float, y: float) -> bool:
        """The straight segment from (x, y) to the goal is free for the disc (exact)."""
        return bool(self.cs.segments_clear(np.array([[x, y]]), self.goal[None])[0])

    def distance(self, x: float, y: float) -> float:
        """Geodesic distance (m) from (x, y) to the goal (see the module's docstring for its accuracy)."""
        gx, gy = self.goal
        fx, fy = (x - self.origin[0]) / self.h, (y - self.origin[1]) / self.h
        nx, ny = self.shape
        i = min(max(int(fx), 0), nx - 2)
        j = min(max(int(fy), 0), ny - 2)
        k = self._cell[i, j]
        if k == 1 or (k == 2 and self.straight_free(x, y)):
            return math.hypot(x - gx, y - gy)
        u = min(max(fx - i, 0.0), 1.0)
        t = min(max(fy - j, 0.0), 1.0)
        v = self.values
        return float((1 - u) * ((1 - t) * v[i, j] + t * v[i, j + 1]) + u * ((1 - t) * v[i + 1, j] + t * v[i + 1, j + 1]))


def _obstacle_distance(obstacles, origin, h: float, shape, reach: float) -> np.ndarray:
    """(nx, ny) exact distance from each grid node to the nearest obstacle (0 inside), or inf where it is
    ``reach`` or more: each obstacle is measured only over the nodes of its box grown by ``reach``
    (the general :meth:`Obstacles2D.points_distance` measures every node against every box: 100x slower here)."""
    from worldgen.feasibility.geometry import point_segment_distance

    nx, ny = shape
    out = np.full(shape, np.inf)
    nd = obstacles.n_discs
    for o in range(len(obstacles)):
        lo_x, lo_y, hi_x, hi_y = obstacles.boxes[o]
        i0 = max(0, int(math.floor((lo_x - reach - origin[0]) / h)))
        i1 = min(nx, int(math.ceil((hi_x + reach - origin[0]) / h)) + 1)
        j0 = max(0, int(math.floor((lo_y - reach - origin[1]) / h)))
        j1 = min(ny, int(math.ceil((hi_y + reach - origin[1]) / h)) + 1)
        if i0 >= i1 or j0 >= j1:
            continue
        px, py = np.meshgrid(origin[0] + h * np.arange(i0, i1), origin[1] + h * np.arange(j0, j1), indexing="ij")
        p = np.stack([px, py], axis=-1)
        if o < nd:
            d = np.maximum(np.hypot(px - obstacles.disc_xy[o, 0], py - obstacles.disc_xy[o, 1]) - obstacles.disc_r[o], 0.0)
        else:
            e0, e1 = obstacles.edge_start[o - nd], obstacles.edge_start[o - nd + 1]
            a, b = obstacles.edge_a[e0:e1], obstacles.edge_b[e0:e1]
            d = np.full(px.shape, np.inf)
            inside = np.ones(px.shape, dtype=bool)
            for k in range(e1 - e0):  # a convex ring, counter-clockwise: inside is left of every edge
                d = np.minimum(d, point_segment_distance(p, a[k], b[k]))
                ex, ey = b[k] - a[k]
                inside &= ex * (py - a[k, 1]) - ey * (px - a[k, 0]) >= 0
            d = np.where(inside, 0.0, d)
        window = out[i0:i1, j0:j1]
        np.minimum(window, np.where(d < reach, d, np.inf), out=window)
    return out
