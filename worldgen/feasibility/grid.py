"""A uniform grid over the grown obstacles, so that a long segment is tested only against the
obstacles near the points it passes (worlds of many obstacles; see ``GRID_FROM`` in cspace)."""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

__all__ = ["SegmentGrid"]


@dataclass(frozen=True, eq=False)
class SegmentGrid:
    """Obstacles by square cell of side ``h``: each listed in every cell within h / 4 of its grown box,
    so a point sampled every h / 2 along a segment finds, in its own cell, every obstacle the
    segment comes within the radius of near that point."""

    origin: tuple[float, float]
    h: float
    shape: tuple[int, int]
    start: np.ndarray
    ids: np.ndarray

    @classmethod
    def build(cls, cs) -> "SegmentGrid":
        """The grid over a :class:`~worldgen.feasibility.cspace.ConfigSpace`'s grown obstacles."""
        boxes = cs.obstacles.boxes
        x0, y0, x1, y1 = cs.box
        spread = float(np.median(cs.hull_r))
        h = max(2 * spread, math.sqrt(max((x1 - x0) * (y1 - y0), 1e-9) / len(boxes)), 1e-3)
        grow = cs.radius + h / 4
        origin = (min(x0, boxes[:, 0].min()) - grow, min(y0, boxes[:, 1].min()) - grow)
        nx = int(math.ceil((max(x1, boxes[:, 2].max()) + grow - origin[0]) / h)) + 1
        ny = int(math.ceil((max(y1, boxes[:, 3].max()) + grow - origin[1]) / h)) + 1
        i0 = np.floor((boxes[:, 0] - grow - origin[0]) / h).astype(np.int64)
        i1 = np.floor((boxes[:, 2] + grow - origin[0]) / h).astype(np.int64)
        j0 = np.floor((boxes[:, 1] - grow - origin[1]) / h).astype(np.int64)
        j1 = np.floor((boxes[:, 3] + grow - origin[1]) / h).astype(np.int64)
        wi, wj = i1 - i0 + 1, j1 - j0 + 1
        count = wi * wj
        owner = np.repeat(np.arange(len(boxes)), count)
        local = np.arange(count.sum()) - np.repeat(np.cumsum(count) - count, count)
        cell = (i0[owner] + local // wj[owner]) * ny + (j0[owner] + local % wj[owner])
        order = np.argsort(cell, kind="stable")
        start = np.searchsorted(cell[order], np.arange(nx * ny + 1))
        return cls(origin, h, (nx, ny), start.astype(np.int64), owner[order].astype(np.int64))

    def pairs(self, rows: np.ndarray, pts: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """(row, obstacle) for every obstacle listed in the cell of each point (rows[k] owns pts[k])."""
        nx, ny = self.shape
        i = np.clip(np.floor((pts[:, 0] - self.origin[0]) / self.h).astype(np.int64), 0, nx - 1)
        j = np.clip(np.floor((pts[:, 1] - self.origin[1]) / self.h).astype(np.int64), 0, ny - 1)
        cell = i * ny + j
        # A segment's next sample in the same cell finds nothing new.
        fresh = np.r_[True, (cell[1:] != cell[:-1]) | (rows[1:] != rows[:-1])]
        rows, cell = rows[fresh], cell[fresh]
        lo, hi = self.start[cell], self.start[cell + 1]
        count = hi - lo
        row = np.repeat(rows, count)
        k = np.repeat(lo, count) + (np.arange(count.sum()) - np.repeat(np.cumsum(count) - count, count))
        return row, self.ids[k]
