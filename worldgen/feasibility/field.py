"""A clearance field on a grid: the exact distance from each cell centre to the nearest obstacle.

Not a rasterised distance transform: every value is the true Euclidean distance
from the cell centre to the nearest footprint (disc or convex polygon) or to the
edge of the bounds, so ``value > r`` proves the centre free for a disc of radius
``r`` and, because distance is 1-Lipschitz, bounds the clearance anywhere near
the centre. Values are only computed up to ``cap``: each obstacle updates the
cells within ``cap`` of its bounding box, which keeps the cost proportional to
the number of obstacles instead of obstacles x cells. Cells farther than ``cap``
from everything hold ``cap`` (read: "at least cap").
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from worldgen.feasibility.geometry import Obstacles2D, point_segment_distance

__all__ = ["Grid", "DistanceField", "grid_for", "distance_field"]

#: Obstacles whose window is wider than this percentile of all windows are
#: handled one by one rather than padded into the batch.
_BATCH_PERCENTILE = 90


@dataclass(frozen=True)
class Grid:
    """Cell centres ``origin + (i + 0.5) * (hx, hy)`` for i < nx, j < ny, tiling the bounds."""

    origin: tuple[float, float]
    hx: float
    hy: float
    nx: int
    ny: int

    def centres(self) -> tuple[np.ndarray, np.ndarray]:
        """(nx,) x and (ny,) y of the cell centres."""
        x = self.origin[0] + (np.arange(self.nx) + 0.5) * self.hx
        y = self.origin[1] + (np.arange(self.ny) + 0.5) * self.hy
        return x, y

    def cell_of(self, xy: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Indices (i, j) of the cell containing each (n, 2) point, clipped to the grid."""
        xy = np.asarray(xy, dtype=float).reshape(-1, 2)
        i = np.clip(np.floor((xy[:, 0] - self.origin[0]) / self.hx), 0, self.nx - 1).astype(np.int64)
        j = np.clip(np.floor((xy[:, 1] - self.origin[1]) / self.hy), 0, self.ny - 1).astype(np.int64)
        return i, j

    def centre_of(self, i: np.ndarray, j: np.ndarray) -> np.ndarray:
        return np.stack([self.origin[0] + (i + 0.5) * self.hx, self.origin[1] + (j + 0.5) * self.hy], axis=-1)


def grid_for(bounds, resolution: float) -> Grid:
    """The grid over ``bounds`` with square-ish cells no larger than ``resolution``."""
    (x0, y0), (x1, y1) = bounds
    nx = max(1, math.ceil((x1 - x0) / resolution - 1e-9))
    ny = max(1, math.ceil((y1 - y0) / resolution - 1e-9))
    return Grid((float(x0), float(y0)), (x1 - x0) / nx, (y1 - y0) / ny, nx, ny)


@dataclass(frozen=True, eq=False)
class DistanceField:
    """``values`` (nx, ny): exact clearance of each cell centre, capped at ``cap``."""

    grid: Grid
    values: np.ndarray
    cap: float


def distance_field(obstacles: Obstacles2D, bounds, grid: Grid, cap: float) -> DistanceField:
    """Exact distances (up to ``cap``) from the cell centres to obstacles and bounds edges."""
    (x0, y0), (x1, y1) = bounds
    xs, ys = grid.centres()
    to_edge = np.minimum(np.minimum(xs - x0, x1 - xs)[:, None], np.minimum(ys - y0, y1 - ys)[None, :])
    values = np.minimum(to_edge, cap).ravel()
    windows = _windows(obstacles, grid, cap)
    nd = obstacles.n_discs
    # Pad into one batch only windows of similar size: a long wall would blow every window up.
    span = np.maximum(windows[:, 1] - windows[:, 0], windows[:, 3] - windows[:, 2])
    limit = min(np.percentile(span, _BATCH_PERCENTILE), 3 * np.median(span)) if len(span) else 0
    small = span <= limit
    ids = np.arange(len(obstacles))
    disc_small = ids[small & (ids < nd)]
    if len(disc_small):
        _batch(values, grid, windows[disc_small], lambda p: _disc_distance(obstacles, disc_small, p))
    rect = obstacles.is_rect
    rect_small = ids[small & (ids >= nd)][rect[ids[small & (ids >= nd)] - nd]]
    if len(rect_small):
        _batch(values, grid, windows[rect_small], lambda p: _rect_distance(obstacles, rect_small, p))
    poly_small = ids[small & (ids >= nd)][~rect[ids[small & (ids >= nd)] - nd]]
    # Batch other polygons of equal edge count together.
    counts = np.diff(obstacles.edge_start)
    for k in np.unique(counts[poly_small - nd]) if len(poly_small) else ():
        group = poly_small[counts[poly_small - nd] == k]
        _batch(values, grid, windows[group], lambda p, g=group: _poly_distance(obstacles, g, p))
    for o in ids[~small]:
        one = np.array([o])
        fn = _disc_distance if o < nd else (_rect_distance if rect[o - nd] else _poly_distance)
        _batch(values, grid, windows[one], lambda p, one=one, fn=fn: fn(obstacles, one, p))
    return DistanceField(grid, values.reshape(grid.nx, grid.ny), cap)


def _windows(obstacles: Obstacles2D, grid: Grid, cap: float) -> np.ndarray:
    """(n, 4) int: i0, i1, j0, j1 (half-open) of the cells within ``cap`` of each obstacle box."""
    b = obstacles.boxes
    i0 = np.floor((b[:, 0] - cap - grid.origin[0]) / grid.hx - 0.5)
    i1 = np.ceil((b[:, 2] + cap - grid.origin[0]) / grid.hx - 0.5) + 1
    j0 = np.floor((b[:, 1] - cap - grid.origin[1]) / grid.hy - 0.5)
    j1 = np.ceil((b[:, 3] + cap - grid.origin[1]) / grid.hy - 0.5) + 1
    w = np.stack([i0, i1, j0, j1], axis=1)
    w[:, :2] = np.clip(w[:, :2], 0, grid.nx)
    w[:, 2:] = np.clip(w[:, 2:], 0, grid.ny)
    return w.astype(np.int64).reshape(-1, 4)


def _batch(values: np.ndarray, grid: Grid, windows: np.ndarray, distance) -> None:
    """Evaluate ``distance`` on every cell of equal-sized padded windows and fold in the minimum."""
    wx = int((windows[:, 1] - windows[:, 0]).max(initial=0))
    wy = int((windows[:, 3] - windows[:, 2]).max(initial=0))
    if wx <= 0 or wy <= 0:
        return
    i = windows[:, 0, None, None] + np.arange(wx)[None, :, None]
    j = windows[:, 2, None, None] + np.arange(wy)[None, None, :]
    i, j = np.broadcast_arrays(i, j)
    valid = (i < windows[:, 1, None, None]) & (j < windows[:, 3, None, None])
    pts = grid.centre_of(i, j)  # (g, wx, wy, 2)
    d = distance(pts.reshape(len(windows), -1, 2)).reshape(i.shape)
    flat = (i * grid.ny + j)[valid]
    np.minimum.at(values, flat, d[valid])


def _disc_distance(obstacles: Obstacles2D, ids: np.ndarray, pts: np.ndarray) -> np.ndarray:
    """(g, m) distance from pts (g, m, 2) to disc ``ids[g]``, 0 inside."""
    c = obstacles.disc_xy[ids][:, None, :]
    r = obstacles.disc_r[ids][:, None]
    dx = pts[..., 0] - c[..., 0]
    dy = pts[..., 1] - c[..., 1]
    return np.maximum(np.sqrt(dx * dx + dy * dy) - r, 0.0)


def _rect_distance(obstacles: Obstacles2D, ids: np.ndarray, pts: np.ndarray) -> np.ndarray:
    """(g, m) distance from pts (g, m, 2) to rectangle ``ids[g]``, in the rectangle's own frame."""
    first = obstacles.edge_start[ids - obstacles.n_discs]
    rings = obstacles.edge_a[first[:, None] + np.arange(4)[None, :]]  # (g, 4, 2)
    centre = rings.mean(axis=1)[:, None, :]
    e0 = rings[:, 1] - rings[:, 0]
    e1 = rings[:, 2] - rings[:, 1]
    l0 = np.hypot(*e0.T)[:, None]
    l1 = np.hypot(*e1.T)[:, None]
    rel = pts - centre
    u = (rel[..., 0] * e0[:, None, 0] + rel[..., 1] * e0[:, None, 1]) / l0
    v = (rel[..., 0] * e1[:, None, 0] + rel[..., 1] * e1[:, None, 1]) / l1
    du = np.maximum(np.abs(u) - l0 / 2, 0.0)
    dv = np.maximum(np.abs(v) - l1 / 2, 0.0)
    return np.sqrt(du * du + dv * dv)


def _poly_distance(obstacles: Obstacles2D, ids: np.ndarray, pts: np.ndarray) -> np.ndarray:
    """(g, m) distance from pts (g, m, 2) to convex polygon ``ids[g]`` (all of one edge count)."""
    p = ids - obstacles.n_discs
    start = obstacles.edge_start[p]
    k = int(obstacles.edge_start[p[0] + 1] - start[0])
    e = start[:, None] + np.arange(k)[None, :]  # (g, k)
    a = obstacles.edge_a[e][:, None, :, :]  # (g, 1, k, 2)
    b = obstacles.edge_b[e][:, None, :, :]
    q = pts[:, :, None, :]  # (g, m, 1, 2)
    d = point_segment_distance(q, a, b).min(axis=2)
    ab = b - a
    aq = q - a
    inside = np.all(ab[..., 0] * aq[..., 1] - ab[..., 1] * aq[..., 0] >= 0, axis=2)
    return np.where(inside, 0.0, d)
