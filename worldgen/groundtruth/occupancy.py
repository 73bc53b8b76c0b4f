"""The occupancy map beside every world: a horizontal slice of the collision geometry.

Format: the ROS 2 navigation map server's (nav2 ``map_server``): a binary PGM
(P5) and a YAML file naming it. Row 0 of the image is the map's top (largest y),
as the map server reads it; ``origin`` is the pose of the lower-left corner of
the lower-left cell. Occupied cells are black (0), free cells white (254):
``mode: trinary``, ``negate: 0``, thresholds 0.65 / 0.25 (the map server's
defaults), so 0 reads as occupied and 254 as free; nothing is unknown, the world
is known exactly.

Which cells are occupied: a cell is occupied when its square, at height
``map_height``, meets the collision geometry's cross-section at that height
(closed sets; a mere touch along a cell edge, within 1e-9 m, does not count).
This is conservative: a wall thinner than a cell still closes the map, as a
planner needs, and every cell whose centre lies in a shape is occupied.
Cross-sections are exact for boxes (any orientation), spheres, upright
cylinders and meshes; a tilted cylinder is sliced as a 64-sided prism pushed out
to contain it (conservative by under 0.13 % of its radius).

Extent: the scene's bounds together with every floor node's shadow (so the
walls on the floor's edge are in the map), in whole cells from the lower-left
corner.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from worldgen.errors import ParameterError
from worldgen.files import MAP_IMAGE_NAME, MAP_YAML_NAME
from worldgen.floats import fmt, round_float
from worldgen.scene import Scene

__all__ = ["OccupancyMap", "build", "extent", "MAX_CELLS", "OCCUPIED", "FREE"]

OCCUPIED = 0
FREE = 254
#: The largest map written (cells); 20 x 20 m at 0.05 m is 160 000.
MAX_CELLS = 25_000_000
#: A touch closer than this (m) to a cell's edge does not make the cell occupied.
_TOUCH = 1e-9
_VERTICAL = 1e-9
_PRISM_SIDES = 64


@dataclass(frozen=True, eq=False)
class OccupancyMap:
    """``occupied`` (rows, cols) bool with row 0 at the bottom (smallest y); ``origin`` (x, y) m."""

    occupied: np.ndarray
    origin: tuple[float, float]
    resolution: float

    def image(self) -> np.ndarray:
        """(rows, cols) uint8 as written: row 0 = top, occupied 0, free 254."""
        return np.where(self.occupied[::-1], OCCUPIED, FREE).astype(np.uint8)

    def pgm(self) -> bytes:
        rows, cols = self.occupied.shape
        return b"P5\n%d %d\n255\n" % (cols, rows) + self.image().tobytes()

    def yaml(self, image: str = MAP_IMAGE_NAME) -> bytes:
        ox, oy = self.origin
        return (
            f"image: {image}\n"
            f"mode: trinary\n"
            f"resolution: {fmt(self.resolution)}\n"
            f"origin: [{fmt(ox)}, {fmt(oy)}, 0]\n"
            f"negate: 0\n"
            f"occupied_thresh: 0.65\n"
            f"free_thresh: 0.25\n"
        ).encode()

    def describe(self, image: str = MAP_IMAGE_NAME, yaml: str = MAP_YAML_NAME) -> dict:
        """world.json's ``occupancy`` block."""
        return {"image": image, "yaml": yaml, "resolution": self.resolution,
                "origin": [self.origin[0], self.origin[1], 0.0]}


def extent(scene: Scene, resolution: float) -> tuple[tuple[float, float], tuple[int, int]]:
    """((x0, y0), (rows, cols)): the lower-left corner and the size of the map in cells."""
    (x0, y0), (x1, y1) = scene.bounds
    for node in scene.nodes:
        if node.role == "floor" and node.shape is not None:
            box = scene.aabb(node.name)
            x0, y0 = min(x0, box[0, 0]), min(y0, box[0, 1])
            x1, y1 = max(x1, box[1, 0]), max(y1, box[1, 1])
    x0, y0 = round_float(x0), round_float(y0)  # the written origin is the origin used
    cols = max(1, math.ceil((x1 - x0) / resolution - 1e-9))
    rows = max(1, math.ceil((y1 - y0) / resolution - 1e-9))
    if rows * cols > MAX_CELLS:
        least = math.sqrt((x1 - x0) * (y1 - y0) / MAX_CELLS)
        raise ParameterError(
            f"parameter 'map_resolution' must be at least {least:.4f} m for this {x1 - x0:g} x {y1 - y0:g} m floor "
            f"(at most {MAX_CELLS} cells), got {resolution!r}"
        )
    return (x0, y0), (rows, cols)


def build(scene: Scene, height: float, resolution: float) -> OccupancyMap:
    """The occupancy map of the slice ``z = height`` at ``resolution`` m per cell."""
    (ox, oy), (rows, cols) = extent(scene, resolution)
    raster = _Raster(ox, oy, resolution, rows, cols)
    for node in scene.nodes:
        if node.shape is None or not node.collision:
            continue
        _slice_node(raster, node.shape, scene.world_matrix(node.name), height)
    return OccupancyMap(raster.finish(), (ox, oy), resolution)


# -- cross-sections ---------------------------------------------------------------------

def _slice_node(raster: "_Raster", shape, m: np.ndarray, z: float) -> None:
    upright = abs(abs(m[2, 2]) - 1.0) < _VERTICAL
    cx, cy, cz = m[:3, 3]
    if shape.kind == "sphere":
        dz = z - cz
        if abs(dz) <= shape.radius:
            raster.disc(cx, cy, math.sqrt(max(shape.radius**2 - dz * dz, 0.0)))
    elif shape.kind == "cylinder" and upright:
        if abs(z - cz) <= shape.length / 2:
            raster.disc(cx, cy, shape.radius)
    elif shape.kind == "box" and upright:
        if abs(z - cz) <= shape.size[2] / 2:
            hx, hy = shape.size[0] / 2, shape.size[1] / 2
            local = np.array([[-hx, -hy], [hx, -hy], [hx, hy], [-hx, hy]])
            raster.convex(local @ m[:2, :2].T + m[:2, 3])
    elif shape.kind == "box":
        corners = shape.local_corners() @ m[:3, :3].T + m[:3, 3]
        loop = _convex_section(corners, _BOX_EDGES, z)
        if loop is not None:
            raster.convex(loop)
    elif shape.kind == "cylinder":
        ang = np.linspace(0.0, 2 * np.pi, _PRISM_SIDES, endpoint=False)
        r = shape.radius / math.cos(math.pi / _PRISM_SIDES)  # the prism contains the cylinder
        ring = np.c_[r * np.cos(ang), r * np.sin(ang)]
        h = shape.length / 2
        local = np.vstack([np.c_[ring, np.full(_PRISM_SIDES, -h)], np.c_[ring, np.full(_PRISM_SIDES, h)]])
        loop = _convex_section(local @ m[:3, :3].T + m[:3, 3], _prism_edges(_PRISM_SIDES), z)
        if loop is not None:
            raster.convex(loop)
    elif shape.kind == "mesh":
        import trimesh

        verts = shape.scaled_vertices() @ m[:3, :3].T + m[:3, 3]
        if verts[:, 2].min() > z or verts[:, 2].max() < z:
            return
        mesh = trimesh.Trimesh(verts, shape.faces, process=False)
        segments = trimesh.intersections.mesh_plane(mesh, [0.0, 0.0, 1.0], [0.0, 0.0, z])
        if len(segments):
            raster.segments(np.asarray(segments)[:, :, :2])


def _box_edges() -> np.ndarray:
    # Box.local_corners() orders corners by the bits (x, y, z) = (i >> 2, i >> 1, i) & 1:
    # an edge joins two corners differing in one bit.
    return np.array([(a, a | bit) for a in range(8) for bit in (1, 2, 4) if not a & bit])


_BOX_EDGES = _box_edges()


def _prism_edges(n: int) -> np.ndarray:
    i = np.arange(n)
    return np.vstack([np.c_[i, (i + 1) % n], np.c_[n + i, n + (i + 1) % n], np.c_[i, n + i]])


def _convex_section(points: np.ndarray, edges: np.ndarray, z: float):
    """(k, 2) ordered loop of a convex solid's section by the plane at z, or None."""
    a, b = points[edges[:, 0]], points[edges[:, 1]]
    za, zb = a[:, 2] - z, b[:, 2] - z
    on = np.vstack([a[za == 0][:, :2], b[zb == 0][:, :2]])
    cross = (za * zb < 0)
    t = za[cross] / (za[cross] - zb[cross])
    hits = a[cross, :2] + t[:, None] * (b[cross, :2] - a[cross, :2])
    pts = np.vstack([on, hits])
    if len(pts) == 0:
        return None
    centre = pts.mean(axis=0)
    order = np.argsort(np.arctan2(pts[:, 1] - centre[1], pts[:, 0] - centre[0]), kind="stable")
    return pts[order]


# -- rasterising ----------------------------------------------------------------------------

def _spans(lo: np.ndarray, count: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """For items with rows lo .. lo + count - 1: (item index, row) of every pair, flat."""
    item = np.repeat(np.arange(len(count)), count)
    step = np.arange(int(count.sum())) - np.repeat(np.cumsum(count) - count, count)
    return item, lo[item] + step


class _Raster:
    """Collects shapes, then turns them into occupied runs (row, first col, last col) in
    a few vectorised passes (one per kind, not one per shape) and fills them at once."""

    def __init__(self, ox, oy, h, rows, cols):
        self.ox, self.oy, self.h, self.rows, self.cols = ox, oy, h, rows, cols
        self.runs: list[tuple[np.ndarray, np.ndarray, np.ndarray]] = []
        self._discs: list[tuple[float, float, float]] = []
        self._loops: list[np.ndarray] = []

    def disc(self, cx, cy, r):
        self._discs.append((cx, cy, r))

    def convex(self, loop: np.ndarray):
        self._loops.append(loop if len(loop) > 1 else np.vstack([loop, loop]))

    def _row_range(self, ylo, yhi):
        """First and last row whose strip meets [ylo, yhi] by more than a touch (arrays)."""
        j0 = np.maximum(np.floor((ylo + _TOUCH - self.oy) / self.h), 0).astype(np.int64)
        j1 = np.minimum(np.ceil((yhi - _TOUCH - self.oy) / self.h) - 1, self.rows - 1).astype(np.int64)
        return j0, j1

    def _add(self, rows, xa, xb):
        """Cells of ``rows`` whose x-extent meets [xa, xb] by more than a touch."""
        i0 = np.maximum(np.floor((xa + _TOUCH - self.ox) / self.h), 0).astype(np.int64)
        i1 = np.minimum(np.ceil((xb - _TOUCH - self.ox) / self.h) - 1, self.cols - 1).astype(np.int64)
        self.runs.append((np.asarray(rows, dtype=np.int64), i0, i1))

    def _fill_discs(self):
        c = np.array(self._discs, dtype=float).reshape(-1, 3)
        j0, j1 = self._row_range(c[:, 1] - c[:, 2], c[:, 1] + c[:, 2])
        k, rows = _spans(j0, np.maximum(j1 - j0 + 1, 0))
        cx, cy, r = c[k, 0], c[k, 1], c[k, 2]
        lo = self.oy + rows * self.h
        # Distance from the centre's y to the strip: the disc's widest chord inside the strip.
        dy = np.maximum(np.maximum(lo - cy, cy - (lo + self.h)), 0.0)
        half = np.sqrt(np.maximum(r * r - dy * dy, 0.0))
        self._add(rows, cx - half, cx + half)

    def _clip(self, p, q):
        """Each segment p->q (k, 2) clipped to each row strip it meets: (segment, row, xa, xb)."""
        # A horizontal segment exactly on a strip's edge meets no strip by more than a touch;
        # the other edges of its polygon bring in the rows on both sides.
        j0, j1 = self._row_range(np.minimum(p[:, 1], q[:, 1]), np.maximum(p[:, 1], q[:, 1]))
        seg, rows = _spans(j0, np.maximum(j1 - j0 + 1, 0))
        a, b = p[seg], q[seg]
        s0 = self.oy + rows * self.h
        dy = b[:, 1] - a[:, 1]
        flat = dy == 0
        safe = np.where(flat, 1.0, dy)
        t0 = (s0 - a[:, 1]) / safe
        t1 = (s0 + self.h - a[:, 1]) / safe
        tlo = np.where(flat, 0.0, np.clip(np.minimum(t0, t1), 0.0, 1.0))
        thi = np.where(flat, 1.0, np.clip(np.maximum(t0, t1), 0.0, 1.0))
        xa = a[:, 0] + tlo * (b[:, 0] - a[:, 0])
        xb = a[:, 0] + thi * (b[:, 0] - a[:, 0])
        return seg, rows, np.minimum(xa, xb), np.maximum(xa, xb)

    def _fill_convex(self):
        """Convex sections: in each row, the x-extent of the part of the loop inside the strip
        (for a convex set, every cell of the row within that extent meets it)."""
        sizes = np.array([len(loop) for loop in self._loops])
        p = np.vstack(self._loops)
        nxt = np.arange(len(p)) + 1
        ends = np.cumsum(sizes)
        nxt[ends - 1] = ends - sizes  # each loop closes on its first point
        seg, rows, xa, xb = self._clip(p, p[nxt])
        if not len(rows):
            return
        owner = np.repeat(np.arange(len(sizes)), sizes)[seg]
        key = owner * self.rows + rows
        order = np.argsort(key, kind="stable")
        key, xa, xb = key[order], xa[order], xb[order]
        first = np.flatnonzero(np.r_[True, key[1:] != key[:-1]])
        self._add(key[first] % self.rows, np.minimum.reduceat(xa, first), np.maximum.reduceat(xb, first))

    def segments(self, segs: np.ndarray):
        """Any closed section given as segments (k, 2, 2): its boundary cells, then by
        even-odd crossings along each row's centre line, the cells whose centre is inside."""
        _, rows, xa, xb = self._clip(segs[:, 0], segs[:, 1])
        self._add(rows, xa, xb)
        y0, y1 = segs[:, 0, 1], segs[:, 1, 1]
        j0, j1 = self._row_range(np.array([min(y0.min(), y1.min())]), np.array([max(y0.max(), y1.max())]))
        for j in range(int(j0[0]), int(j1[0]) + 1):
            yc = self.oy + (j + 0.5) * self.h
            crossing = (np.minimum(y0, y1) <= yc) & (yc < np.maximum(y0, y1))
            if not crossing.any():
                continue
            a, b = segs[crossing, 0], segs[crossing, 1]
            xs = np.sort(a[:, 0] + (yc - a[:, 1]) / (b[:, 1] - a[:, 1]) * (b[:, 0] - a[:, 0]))
            if len(xs) % 2:
                continue  # an open section has no inside to speak of
            lo = np.maximum(np.ceil((xs[0::2] - self.ox) / self.h - 0.5), 0).astype(np.int64)
            hi = np.minimum(np.floor((xs[1::2] - self.ox) / self.h - 0.5), self.cols - 1).astype(np.int64)
            self.runs.append((np.full(len(lo), j, dtype=np.int64), lo, hi))

    def finish(self) -> np.ndarray:
        if self._discs:
            self._fill_discs()
        if self._loops:
            self._fill_convex()
        occupied = np.zeros(self.rows * self.cols, dtype=bool)
        if self.runs:
            rows = np.concatenate([r for r, _, _ in self.runs])
            i0 = np.concatenate([a for _, a, _ in self.runs])
            i1 = np.concatenate([b for _, _, b in self.runs])
            run, offset = _spans(rows * self.cols + i0, np.maximum(i1 - i0 + 1, 0))
            occupied[offset] = True
        return occupied.reshape(self.rows, self.cols)
