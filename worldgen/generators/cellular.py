"""The cell grid of the ``barn`` generator: a cellular automaton, its cells merged into boxes, and a
quick proof that a grid cannot be crossed.

A grid is a boolean array ``grid[row, col]`` (True = filled); row 0 is the start end (lowest y), the
last row the goal end, column 0 the lowest x. Off the grid, a cell beside the side edges counts as
filled, corners included (the field's sides are closed, as BARN's are, and beyond them lies no floor),
and one beyond the start or goal end as empty (those ends open onto the free strips where the robot
starts and stops).

>>> g = np.zeros((3, 3), dtype=bool)
>>> g[1, 1] = True
>>> neighbours(g).tolist()
[[4, 1, 4], [4, 0, 4], [4, 1, 4]]
"""

from __future__ import annotations

import math
from collections import deque

import numpy as np

__all__ = ["random_fill", "neighbours", "smooth", "automaton", "merge_boxes", "crossing_blocked"]

#: The eight neighbours of a cell, for labelling regions a disc can move between.


def random_fill(rng: np.random.Generator, rows: int, cols: int, fraction: float) -> np.ndarray:
    """Each cell filled independently with probability ``fraction`` (one uniform draw per cell, row by row)."""
    return rng.random((rows, cols)) < fraction


def neighbours(grid: np.ndarray) -> np.ndarray:
    """(rows, cols) count of the filled cells among each cell's eight neighbours, off-grid cells
    counted as the module says (filled beside the sides, empty beyond the ends)."""
    g = np.asarray(grid, dtype=np.int16)
    padded = np.pad(g, ((1, 1), (0, 0)), constant_values=0)  # the open ends
    padded = np.pad(padded, ((0, 0), (1, 1)), constant_values=1)  # the closed sides, corners too
    rows, cols = g.shape
    total = np.zeros_like(g)
    for dr in (0, 1, 2):
        for dc in (0, 1, 2):
            if dr != 1 or dc != 1:
                total += padded[dr:dr + rows, dc:dc + cols]
    return total


def smooth(grid: np.ndarray, birth: int, death: int) -> np.ndarray:
    """One synchronous pass: a cell with at least ``birth`` filled neighbours is filled, one with fewer
    than ``death`` is emptied, any other keeps its state (BARN's rule is birth 5, death 2)."""
    count = neighbours(grid)
    return np.where(count >= birth, True, np.where(count < death, False, np.asarray(grid, dtype=bool)))


def automaton(rng: np.random.Generator, rows: int, cols: int, fraction: float, passes: int,
              birth: int, death: int) -> np.ndarray:
    """A random fill, then ``passes`` smoothing passes."""
    grid = random_fill(rng, rows, cols, fraction)
    for _ in range(passes):
        grid = smooth(grid, birth, death)
    return grid


def merge_boxes(grid: np.ndarray) -> list[tuple[int, int, int, int]]:
    """The filled cells as disjoint axis-aligned rectangles ``(row, col, height, width)`` in cells.

    Greedy: at the first filled cell not yet covered, the rectangle grows along the scan line as far
    as uncovered filled cells go, then line by line while the whole span stays filled and uncovered.
    Scanned by rows and by columns, the fewer rectangles win (rows on a tie). Either way they cover
    exactly the filled cells, each once.
    """
    g = np.asarray(grid, dtype=bool)
    by_rows = _greedy(g)
    by_cols = [(r, c, h, w) for c, r, w, h in _greedy(g.T)]
    return by_cols if len(by_cols) < len(by_rows) else by_rows


def _greedy(g: np.ndarray) -> list[tuple[int, int, int, int]]:
    free = g.copy()  # filled and not yet covered
    rows, cols = g.shape
    boxes = []
    for r in range(rows):
        c = 0
        while c < cols:
            if not free[r, c]:
                c += 1
                continue
            w = 1
            while c + w < cols and free[r, c + w]:
                w += 1
            h = 1
            while r + h < rows and free[r + h, c:c + w].all():
                h += 1
            free[r:r + h, c:c + w] = False
            boxes.append((r, c, h, w))
            c += w
    return boxes


def crossing_blocked(grid: np.ndarray, cell: float, inflation: float) -> bool:
    """True when no disc of radius ``inflation`` can cross the field from the start end to the goal end.

    Only ever True when that is certain, so a draw it rejects is one the exact check would refuse too:
    a disc centre ``p`` at more than ``inflation`` from every filled cell lies in a cell whose centre is
    within ``cell / sqrt(2)`` of ``p``, so that centre is more than ``inflation - cell / sqrt(2)`` from
    every filled cell; as ``p`` crosses the field it passes through a chain of such cells, each one of
    the eight neighbours of the last, from the first row to the last. No such chain: no crossing.
    """
    g = np.asarray(grid, dtype=bool)
    reach = inflation - cell / math.sqrt(2.0)
    blocked = g
    if reach >= 0:
        # Offsets (in cells) of the centres within `reach` of a filled cell's square.
        k = int(math.floor(reach / cell + 0.5)) + 1
        offsets = np.arange(-k, k + 1)
        dx = np.maximum(np.abs(offsets)[None, :] - 0.5, 0.0) * cell
        dy = np.maximum(np.abs(offsets)[:, None] - 0.5, 0.0) * cell
        structure = np.hypot(dx, dy) <= reach
        blocked = _dilate(g, structure)
    return not _rows_joined(~blocked)


def _dilate(grid: np.ndarray, structure: np.ndarray) -> np.ndarray:
    """``grid`` grown by the (2k + 1)-square ``structure`` centred on each filled cell (cells beyond the
    edges are not filled)."""
    rows, cols = grid.shape
    k = structure.shape[0] // 2
    padded = np.zeros((rows + 2 * k, cols + 2 * k), dtype=bool)
    out = grid.copy()
    padded[k:k + rows, k:k + cols] = grid
    for dr, dc in zip(*np.nonzero(structure)):
        out |= padded[2 * k - dr:2 * k - dr + rows, 2 * k - dc:2 * k - dc + cols]
    return out


def _rows_joined(free: np.ndarray) -> bool:
    """True when a chain of free cells, each one of the eight neighbours of the last, joins the first row
    to the last (a breadth-first walk from the free cells of the first row)."""
    rows, cols = free.shape
    seen = np.zeros_like(free)
    queue = deque((0, c) for c in np.flatnonzero(free[0]).tolist())
    seen[0, free[0]] = True
    while queue:
        r, c = queue.popleft()
        if r == rows - 1:
            return True
        for rr in (r - 1, r, r + 1):
            for cc in (c - 1, c, c + 1):
                if 0 <= rr < rows and 0 <= cc < cols and free[rr, cc] and not seen[rr, cc]:
                    seen[rr, cc] = True
                    queue.append((rr, cc))
    return False
