"""Terrain: the ground's height as a function of (x, y), made of elements that compose into one field.

Every element is a rectangle on the floor (centre, yaw, ``length`` along its own x, ``width`` along its
own y) with a height inside it and zero outside; elements may not overlap, so the ground's height at a
point is the height of the one element that holds it (0 elsewhere) and :meth:`Terrain.heights` is exact
for every element: a ramp's straight inclines, a step's plateau, and the rough patch's triangles, the
surface the exported height fields carry.

- :class:`Ramp`: up over ``run``, flat for ``landing`` at ``rise``, down over ``run`` (a speed bump is
  a ramp with no landing; driven across its width it is a cross-slope);
- :class:`Step`: a plateau ``height`` above the floor (a kerb), or below it when negative (a pothole);
- :class:`Rough`: a seeded grid of heights every ``cell`` metres, zero on its border so it meets the
  floor without an edge, linear on each cell's two triangles.

Plain frozen data like the rest of the scene: no limits, no drivability (that is feasibility's).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Union

import numpy as np
import shapely

from worldgen.errors import SceneError
from worldgen.floats import round_float

__all__ = ["Ramp", "Step", "Rough", "Element", "Terrain", "KINDS"]


def _local(xy: np.ndarray, cx: float, cy: float, yaw: float) -> tuple[np.ndarray, np.ndarray]:
    """(u, v): points in an element's frame (u along its length, v across it)."""
    c, s = math.cos(yaw), math.sin(yaw)
    dx, dy = xy[:, 0] - cx, xy[:, 1] - cy
    return c * dx + s * dy, -s * dx + c * dy


def _to_world(cx: float, cy: float, yaw: float, uv: np.ndarray) -> np.ndarray:
    c, s = math.cos(yaw), math.sin(yaw)
    return np.column_stack([cx + c * uv[:, 0] - s * uv[:, 1], cy + s * uv[:, 0] + c * uv[:, 1]])


def _positive(kind: str, **values: float) -> None:
    for name, value in values.items():
        if not (math.isfinite(value) and value > 0):
            raise SceneError(f"terrain {kind}: {name} must be > 0 m, got {value!r}")


class _Rect:
    """What every element shares: a rectangle at (cx, cy) turned by yaw, ``length`` x ``width``."""

    cx: float
    cy: float
    yaw: float
    length: float
    width: float

    def inside(self, xy: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """(mask, u, v) of points (n, 2): inside the rectangle (edges included), and their local coordinates."""
        u, v = _local(xy, self.cx, self.cy, self.yaw)
        return (np.abs(u) <= self.length / 2) & (np.abs(v) <= self.width / 2), u, v

    def outline(self) -> shapely.Polygon:
        hl, hw = self.length / 2, self.width / 2
        return shapely.Polygon(_to_world(self.cx, self.cy, self.yaw,
                                         np.array([[-hl, -hw], [hl, -hw], [hl, hw], [-hl, hw]])))

    def to_world(self, uv: np.ndarray) -> np.ndarray:
        """(n, 2) world points of local (u, v) points."""
        return _to_world(self.cx, self.cy, self.yaw, np.asarray(uv, dtype=float).reshape(-1, 2))


@dataclass(frozen=True)
class Ramp(_Rect):
    """Up over ``run`` m to ``rise`` m, a ``landing`` m long at that height, down over ``run`` m."""

    cx: float
    cy: float
    yaw: float
    width: float
    rise: float
    run: float
    landing: float = 0.0
    kind = "ramp"

    def __post_init__(self):
        _positive("ramp", width=self.width, rise=self.rise, run=self.run)
        if not (math.isfinite(self.landing) and self.landing >= 0):
            raise SceneError(f"terrain ramp: landing must be >= 0 m, got {self.landing!r}")

    @property
    def length(self) -> float:  # type: ignore[override]  # derived from the run and the landing, never stored twice
        return 2 * self.run + self.landing

    @property
    def incline(self) -> float:
        """The inclines' angle, degrees."""
        return math.degrees(math.atan2(self.rise, self.run))

    def heights(self, xy: np.ndarray) -> np.ndarray:
        mask, u, _ = self.inside(xy)
        up = np.minimum(u + self.length / 2, self.length / 2 - u)  # distance in from the nearer end
        return np.where(mask, self.rise * np.clip(up / self.run, 0.0, 1.0), 0.0)

    def gradients(self, xy: np.ndarray) -> np.ndarray:
        mask, u, _ = self.inside(xy)
        on_incline = np.abs(u) >= self.landing / 2
        return np.where(mask & on_incline, self.rise / self.run, 0.0)

    def params(self) -> dict:
        return {"rise": self.rise, "run": self.run, "landing": self.landing}


@dataclass(frozen=True)
class Step(_Rect):
    """A plateau ``height`` m above the floor (below it when negative): a kerb, or a pothole."""

    cx: float
    cy: float
    yaw: float
    length: float
    width: float
    height: float
    kind = "step"

    def __post_init__(self):
        _positive("step", length=self.length, width=self.width)
        if not (math.isfinite(self.height) and self.height != 0):
            raise SceneError(f"terrain step: height must be a non-zero number of metres, got {self.height!r}")

    def heights(self, xy: np.ndarray) -> np.ndarray:
        mask, _, _ = self.inside(xy)
        return np.where(mask, self.height, 0.0)

    def gradients(self, xy: np.ndarray) -> np.ndarray:
        return np.zeros(len(xy))

    def params(self) -> dict:
        return {"length": self.length, "height": self.height}


@dataclass(frozen=True)
class Rough(_Rect):
    """Heights on a grid every ``cell`` m (``grid[j][i]`` at u = -length/2 + i cell, v = -width/2 + j cell),
    zero on the border, linear on the two triangles of each cell split by its diagonal from (i, j) to
    (i + 1, j + 1): the surface a height field's engines build from the same nodes (MuJoCo's, checked by ray)."""

    cx: float
    cy: float
    yaw: float
    cell: float
    grid: tuple[tuple[float, ...], ...]
    kind = "rough"

    def __post_init__(self):
        _positive("rough", cell=self.cell)
        grid = np.asarray(self.grid, dtype=float)
        if grid.ndim != 2 or min(grid.shape) < 2 or not np.isfinite(grid).all():
            raise SceneError("terrain rough: grid must be a finite table of at least 2 x 2 heights")
        if np.abs(np.concatenate([grid[0], grid[-1], grid[:, 0], grid[:, -1]])).max() > 0:
            raise SceneError("terrain rough: the grid's border must be 0 (a patch meets the floor without an edge)")

    @property
    def width(self) -> float:  # type: ignore[override]  # derived from the grid, never stored twice
        return (len(self.grid) - 1) * self.cell

    @property
    def length(self) -> float:  # type: ignore[override]  # derived from the grid, never stored twice
        return (len(self.grid[0]) - 1) * self.cell

    @property
    def array(self) -> np.ndarray:
        return np.asarray(self.grid, dtype=float)

    def _cell_of(self, xy: np.ndarray):
        mask, u, v = self.inside(xy)
        g = self.array
        fi = np.clip((u + self.length / 2) / self.cell, 0, g.shape[1] - 1 - 1e-12)
        fj = np.clip((v + self.width / 2) / self.cell, 0, g.shape[0] - 1 - 1e-12)
        i, j = np.floor(fi).astype(int), np.floor(fj).astype(int)
        return mask, g, i, j, fi - i, fj - j

    def heights(self, xy: np.ndarray) -> np.ndarray:
        mask, g, i, j, a, b = self._cell_of(xy)
        h00, h10, h01, h11 = g[j, i], g[j, i + 1], g[j + 1, i], g[j + 1, i + 1]
        h = np.where(a >= b, h00 + a * (h10 - h00) + b * (h11 - h10), h00 + b * (h01 - h00) + a * (h11 - h01))
        return np.where(mask, h, 0.0)

    def gradients(self, xy: np.ndarray) -> np.ndarray:
        mask, g, i, j, a, b = self._cell_of(xy)
        h00, h10, h01, h11 = g[j, i], g[j, i + 1], g[j + 1, i], g[j + 1, i + 1]
        du = np.where(a >= b, h10 - h00, h11 - h01) / self.cell
        dv = np.where(a >= b, h11 - h10, h01 - h00) / self.cell
        return np.where(mask, np.hypot(du, dv), 0.0)

    def steepest(self) -> float:
        """The largest gradient anywhere in the patch (exact: each triangle is a plane)."""
        g = self.array
        h00, h10, h01, h11 = g[:-1, :-1], g[:-1, 1:], g[1:, :-1], g[1:, 1:]
        lower = np.hypot(h10 - h00, h11 - h10)  # a >= b: below the diagonal
        upper = np.hypot(h11 - h01, h01 - h00)
        return float(max(lower.max(), upper.max())) / self.cell

    def params(self) -> dict:
        return {"cell": self.cell, "grid": [list(row) for row in self.grid]}


Element = Union[Ramp, Step, Rough]
KINDS = ("ramp", "step", "rough")


@dataclass(frozen=True, eq=False)
class Terrain:
    """Non-overlapping elements; the ground is flat (height 0) everywhere else."""

    elements: tuple[Element, ...]

    def __post_init__(self):
        object.__setattr__(self, "elements", tuple(self.elements))
        outlines = [e.outline() for e in self.elements]
        for a in range(len(outlines)):
            for b in range(a + 1, len(outlines)):
                if outlines[a].intersection(outlines[b]).area > 1e-12:
                    raise SceneError(f"terrain elements {a} ({self.elements[a].kind}) and {b} "
                                     f"({self.elements[b].kind}) overlap; elements must not overlap")

    def heights(self, xy) -> np.ndarray:
        """(n,) the ground's height (m) at each of the (n, 2) points."""
        xy = np.asarray(xy, dtype=float).reshape(-1, 2)
        out = np.zeros(len(xy))
        for element in self.elements:
            out += element.heights(xy)
        return out

    def gradients(self, xy) -> np.ndarray:
        """(n,) the ground's gradient magnitude (rise per metre) at each point (0 on the flat floor; on a
        rectangle's edge the element's inside value)."""
        xy = np.asarray(xy, dtype=float).reshape(-1, 2)
        out = np.zeros(len(xy))
        for element in self.elements:
            out = np.maximum(out, element.gradients(xy))
        return out

    def extent(self) -> tuple[float, float]:
        """(lowest, highest) height anywhere, floor included."""
        lows, highs = [0.0], [0.0]
        for e in self.elements:
            if isinstance(e, Ramp):
                highs.append(e.rise)
            elif isinstance(e, Step):
                (lows if e.height < 0 else highs).append(e.height)
            else:
                lows.append(float(e.array.min()))
                highs.append(float(e.array.max()))
        return min(lows), max(highs)

    @classmethod
    def from_canonical(cls, entries) -> "Terrain":
        """The terrain :meth:`canonical` (world.json's ``terrain.elements``) describes."""
        out: list[Element] = []
        for e in entries:
            (cx, cy), yaw = e["centre"], e["yaw"]
            if e["kind"] == "ramp":
                out.append(Ramp(cx, cy, yaw, e["width"], e["rise"], e["run"], e["landing"]))
            elif e["kind"] == "step":
                out.append(Step(cx, cy, yaw, e["length"], e["width"], e["height"]))
            elif e["kind"] == "rough":
                out.append(Rough(cx, cy, yaw, e["cell"], tuple(tuple(row) for row in e["grid"])))
            else:
                raise SceneError(f"terrain element kind must be one of {', '.join(KINDS)}, got {e['kind']!r}")
        return cls(tuple(out))

    def canonical(self) -> list[dict]:
        out = []
        for e in self.elements:
            entry = {"kind": e.kind, "centre": [round_float(e.cx), round_float(e.cy)], "yaw": round_float(e.yaw),
                     "width": round_float(e.width)}
            for key, value in e.params().items():
                entry[key] = ([[round_float(h) for h in row] for row in value] if key == "grid"
                              else round_float(value))
            out.append(entry)
        return out
