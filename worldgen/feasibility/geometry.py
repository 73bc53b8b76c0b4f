"""Obstacle footprints as flat arrays, and exact 2-D point and segment distances, vectorised.

Footprints are
discs or convex polygons (see :mod:`worldgen.scene.footprint`); here they are kept as
flat numpy arrays (disc centres and radii; every polygon edge with its owner)
so one call answers for many points or segments without a Python loop per
obstacle. A bounding-box broad phase keeps the work near the query.

Obstacle ids are shared by every function: discs first (0 .. n_discs - 1),
then polygons.
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import cached_property

import numpy as np
import shapely

from worldgen.scene.footprint import Footprint

__all__ = ["Obstacles2D", "cross", "point_segment_distance", "segment_segment_distance"]


def point_segment_distance(p: np.ndarray, a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Distance from points ``p`` to segments ``ab``; (..., 2) arrays broadcast together."""
    abx, aby = b[..., 0] - a[..., 0], b[..., 1] - a[..., 1]
    apx, apy = p[..., 0] - a[..., 0], p[..., 1] - a[..., 1]
    den = abx * abx + aby * aby
    # minimum(maximum()) rather than np.clip: the same values, without clip's dispatch (called per query).
    t = np.minimum(np.maximum((apx * abx + apy * aby) / np.where(den > 0, den, 1.0), 0.0), 1.0)
    # np.hypot is several times slower than this, and overflow cannot happen at room scale.
    dx = apx - t * abx
    dy = apy - t * aby
    return np.sqrt(dx * dx + dy * dy)


def cross(u: np.ndarray, v: np.ndarray) -> np.ndarray:
    """The z component of ``u x v``, (..., 2) arrays: positive where ``v`` turns counter-clockwise from ``u``."""
    return u[..., 0] * v[..., 1] - u[..., 1] * v[..., 0]


def segment_segment_distance(a, b, c, d) -> np.ndarray:
    """Distance between segments ``ab`` and ``cd`` (0 where they cross); arrays broadcast.

    The four end-to-segment distances and the four orientation tests share their differences: each is
    computed once, by the same operations as :func:`point_segment_distance` and a cross product would
    (the same floats), since the clearance test calls this for every edge it measures.
    """
    ax, ay, bx, by = a[..., 0], a[..., 1], b[..., 0], b[..., 1]
    cx, cy, dx, dy = c[..., 0], c[..., 1], d[..., 0], d[..., 1]
    abx, aby, cdx, cdy = bx - ax, by - ay, dx - cx, dy - cy
    acx, acy, adx, ady = cx - ax, cy - ay, dx - ax, dy - ay  # c and d from a
    cax, cay, cbx, cby = ax - cx, ay - cy, bx - cx, by - cy  # a and b from c
    den_ab = abx * abx + aby * aby
    den_cd = cdx * cdx + cdy * cdy
    den_ab = np.where(den_ab > 0, den_ab, 1.0)
    den_cd = np.where(den_cd > 0, den_cd, 1.0)
    dist = np.minimum(
        np.minimum(_to_segment(cax, cay, cdx, cdy, den_cd), _to_segment(cbx, cby, cdx, cdy, den_cd)),
        np.minimum(_to_segment(acx, acy, abx, aby, den_ab), _to_segment(adx, ady, abx, aby, den_ab)),
    )
    # A proper crossing: each segment's ends lie on opposite sides of the other's line.
    o1 = abx * acy - aby * acx
    o2 = abx * ady - aby * adx
    o3 = cdx * cay - cdy * cax
    o4 = cdx * cby - cdy * cbx
    crossing = (o1 * o2 < 0) & (o3 * o4 < 0)
    return np.where(crossing, 0.0, dist)


def _to_segment(apx, apy, abx, aby, den) -> np.ndarray:
    """:func:`point_segment_distance` from its differences (``den`` the segment's squared length, 1 if 0)."""
    t = np.minimum(np.maximum((apx * abx + apy * aby) / den, 0.0), 1.0)
    ex = apx - t * abx
    ey = apy - t * aby
    return np.sqrt(ex * ex + ey * ey)


@dataclass(frozen=True, eq=False)
class Obstacles2D:
    """Footprints as arrays.

    ``disc_xy`` (nd, 2), ``disc_r`` (nd,); polygons as counter-clockwise
    vertex rings ``poly_vertices`` (list of (k, 2)), their edges flattened into
    ``edge_a``/``edge_b`` (ne, 2) with ``edge_owner`` (ne,) polygon index and
    ``edge_start`` (np + 1,) offsets; ``boxes`` (n, 4) minx, miny, maxx, maxy
    per obstacle id; ``names`` per obstacle id.
    """

    disc_xy: np.ndarray
    disc_r: np.ndarray
    poly_vertices: tuple
    edge_a: np.ndarray
    edge_b: np.ndarray
    edge_owner: np.ndarray
    edge_start: np.ndarray
    boxes: np.ndarray
    names: tuple

    @classmethod
    def from_footprints(cls, footprints: list[Footprint]) -> "Obstacles2D":
        discs = [f for f in footprints if f.is_disc]
        polys = [f for f in footprints if not f.is_disc]
        disc_xy = np.array([f.centre for f in discs], dtype=float).reshape(-1, 2)
        disc_r = np.array([f.radius for f in discs], dtype=float)
        rings = _ccw_rings([f.polygon for f in polys])
        counts = np.array([len(r) for r in rings], dtype=np.int64)
        start = np.concatenate([[0], np.cumsum(counts)]).astype(np.int64)
        if rings:
            edge_a = np.concatenate(rings)
            edge_b = np.concatenate([np.roll(r, -1, axis=0) for r in rings])
        else:
            edge_a = edge_b = np.zeros((0, 2))
        owner = np.repeat(np.arange(len(rings)), counts)
        disc_boxes = np.column_stack([disc_xy - disc_r[:, None], disc_xy + disc_r[:, None]])
        poly_boxes = shapely.bounds(np.array([f.polygon for f in polys], dtype=object)).reshape(-1, 4)
        boxes = np.concatenate([disc_boxes.reshape(-1, 4), poly_boxes]).astype(float)
        names = tuple(f.name for f in discs) + tuple(f.name for f in polys)
        return cls(disc_xy, disc_r, tuple(rings), edge_a, edge_b, owner, start, boxes, names)

    @cached_property
    def cores(self) -> np.ndarray:
        """(N,) shapely geometries by obstacle id: each polygon, and each disc's centre point."""
        # Made in two vectorised calls (one shapely object at a time cost 0.24 ms at 50 obstacles).
        points = shapely.points(self.disc_xy) if len(self.disc_xy) else np.zeros(0, dtype=object)
        polygons = (shapely.polygons(shapely.linearrings(self.edge_a, indices=self.edge_owner))
                    if len(self.poly_vertices) else np.zeros(0, dtype=object))
        return np.concatenate([np.asarray(points, dtype=object), np.asarray(polygons, dtype=object)])

    @property
    def n_discs(self) -> int:
        return len(self.disc_r)

    def __len__(self) -> int:
        return len(self.names)

    def near(self, lo: np.ndarray, hi: np.ndarray, reach: float) -> np.ndarray:
        """(m, n) bool: query box m (corners ``lo``/``hi``, (m, 2)) within ``reach`` of obstacle box n."""
        b = self.boxes
        return (
            (lo[:, None, 0] - reach <= b[None, :, 2]) & (hi[:, None, 0] + reach >= b[None, :, 0])
            & (lo[:, None, 1] - reach <= b[None, :, 3]) & (hi[:, None, 1] + reach >= b[None, :, 1])
        )

    def segments_distance(self, a: np.ndarray, b: np.ndarray, reach: float) -> tuple[np.ndarray, np.ndarray]:
        """Smallest distance from each segment ``a[i]b[i]`` ((m, 2) each) to any obstacle.

        Only obstacles whose box lies within ``reach`` of the segment's box are
        measured; where none is, the distance is ``inf`` (it is at least
        ``reach``). Returns (distance (m,), obstacle id (m,), -1 where inf).
        """
        a = np.asarray(a, dtype=float).reshape(-1, 2)
        b = np.asarray(b, dtype=float).reshape(-1, 2)
        m = len(a)
        best = np.full(m, np.inf)
        which = np.full(m, -1, dtype=np.int64)
        if m == 0 or len(self) == 0:
            return best, which
        close = self.near(np.minimum(a, b), np.maximum(a, b), reach)
        seg, obs = np.nonzero(close)
        if len(seg) == 0:
            return best, which
        nd = self.n_discs
        is_disc = obs < nd
        if is_disc.any():
            s, o = seg[is_disc], obs[is_disc]
            d = point_segment_distance(self.disc_xy[o], a[s], b[s]) - self.disc_r[o]
            _take_min(best, which, s, o, np.maximum(d, 0.0))
        if (~is_disc).any():
            s, p = seg[~is_disc], obs[~is_disc] - nd
            counts = self.edge_start[p + 1] - self.edge_start[p]
            s_e = np.repeat(s, counts)
            p_e = np.repeat(p, counts)
            offsets = np.arange(counts.sum()) - np.repeat(np.cumsum(counts) - counts, counts)
            e = self.edge_start[p_e] + offsets
            d = segment_segment_distance(a[s_e], b[s_e], self.edge_a[e], self.edge_b[e])
            # A segment wholly inside a polygon crosses no edge: its start is inside.
            pair = np.repeat(np.arange(len(s)), counts)
            d = np.where(self._inside_polygon(a[s_e], e, pair, len(s)), 0.0, d)
            _take_min(best, which, s_e, p_e + nd, d)
        return best, which

    def _inside_polygon(self, pts: np.ndarray, e: np.ndarray, pair: np.ndarray, n_pairs: int) -> np.ndarray:
        """Per (point, edge) row: True where the point lies left of every edge of its pair's polygon."""
        left = cross(self.edge_b[e] - self.edge_a[e], pts - self.edge_a[e]) >= 0
        all_left = np.ones(n_pairs, dtype=bool)
        np.logical_and.at(all_left, pair, left)
        return all_left[pair]

    def points_distance(self, xy: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Exact distance from each of the (n, 2) points to the nearest obstacle, 0 inside.

        Returns (distance (n,), obstacle id (n,)); inf and -1 without obstacles.
        """
        xy = np.asarray(xy, dtype=float).reshape(-1, 2)
        return self.segments_distance(xy, xy, np.inf)


def _ccw_rings(polygons: list) -> list[np.ndarray]:
    """Each (convex) polygon's exterior as a counter-clockwise (k, 2) ring without the closing point."""
    if not polygons:
        return []
    coords, index = shapely.get_coordinates(shapely.get_exterior_ring(polygons), return_index=True)
    last = np.r_[index[1:] != index[:-1], True]  # each ring's closing point
    pts, owner = coords[~last], index[~last]
    start = np.flatnonzero(np.r_[True, owner[1:] != owner[:-1]])
    count = np.diff(np.r_[start, len(owner)])
    nxt = np.arange(len(pts)) + 1
    nxt[start + count - 1] = start  # each ring's last point wraps to its first
    twice_area = np.add.reduceat(pts[:, 0] * pts[nxt, 1] - pts[:, 1] * pts[nxt, 0], start)
    rings = np.split(pts, start[1:])
    return [r if a > 0 else r[::-1].copy() for r, a in zip(rings, twice_area)]


def _take_min(best: np.ndarray, which: np.ndarray, rows: np.ndarray, ids: np.ndarray, d: np.ndarray) -> None:
    """best[r] = min(best[r], d) over pairs, remembering the id of the minimum."""
    order = np.lexsort((d, rows))
    rows, ids, d = rows[order], ids[order], d[order]
    first = np.r_[True, rows[1:] != rows[:-1]]
    r, i, v = rows[first], ids[first], d[first]
    better = v < best[r]
    best[r[better]] = v[better]
    which[r[better]] = i[better]
