"""Corners the timed path passes on the move: a small turn taken on an arc the certificate covers, instead of
a stop, a turn on the spot and a start (docs/people.md, "Corners passed moving").

At an inner waypoint where the path turns by ``theta`` (0 < theta <= :data:`CUT_ANGLE`) the robot may keep
moving: it drives the arc of radius ``rho`` tangent to both legs, from ``ell = rho tan(theta / 2)`` before
the waypoint to as far after it, at the schedule's share of that stretch (the arc is shorter than the two
pieces of leg it replaces, by the factor ``k = theta / (2 tan(theta / 2))``, so it goes ``k`` times the
schedule's speed there). While the schedule is within ``ell`` of the waypoint its speed is at most
``rho omega``, so the robot's turn rate on the arc (its speed over ``rho``) is within ``omega``. The robot
is then never farther from the schedule than ``rho (sec(theta / 2) - 1)`` (reached at the waypoint, where
the schedule is at the corner and the robot at the arc's middle; before and after, both the sideways and
the along-the-way distance are smaller), at most :data:`CUT`: the certificate keeps that much more from
every person near the corner (the largest arc's, whichever is driven), and the static clearance is
re-proved for the arc itself: FCL sweeps the robot along :data:`ARC_PIECES` chords inscribed in it, each
keeping the clearance plus the most the arc bulges beyond its chord (``rho (1 - cos(theta / 2n))``, 0.09
mm for a 0.3 rad turn on a 0.5 m arc), so every point of the arc keeps the clearance. Where it does not, a
smaller arc (:data:`SHRINK`) is tried. (One chord between the arc's ends, nearer the inside of the turn
than the arc by up to 0.6 mm, cost crowd_reacting its gap: issue 37.)

``rho`` is the smaller of ``v / omega`` (the arc a robot at top speed turns) and the radius whose arc strays
:data:`CUT` from the waypoint, made smaller still where the reaches of two neighbouring candidates (every
turn up to :data:`CUT_ANGLE`) would overlap on the leg between them: each then reaches along that leg in
proportion to its own reach, so arcs never overlap. :mod:`worldgen.verify.timed` re-derives all of this from world.json.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

__all__ = ["CUT", "CUT_ANGLE", "SHRINK", "ARC_PIECES", "Cut", "cuts", "passed_moving", "cap_moves", "arc_polyline",
           "arc_clear"]

#: The most (m) the robot may be off its schedule through a corner it passes moving.
CUT = 0.005
#: The largest turn (rad) passed moving; a larger one is turned on the spot.
CUT_ANGLE = 0.3
#: The shares of a corner's largest arc tried, in turn, until one's chord is clear (a smaller arc strays
#: less into the corner, and is driven slower).
SHRINK = (1.0, 0.5, 0.25, 0.125)
#: The chords an arc is proved clear along.
ARC_PIECES = 8


@dataclass(frozen=True)
class Cut:
    """The arc through waypoint ``index``: its radius ``rho``, its reach ``ell`` either side of the waypoint
    along the path, how far ``dev`` the robot on it may be from the schedule, the schedule's top ``speed``
    within ``ell`` of the waypoint, and the chord's ends ``a``, ``b`` (m)."""

    index: int
    rho: float
    ell: float
    dev: float
    speed: float
    a: tuple[float, float]
    b: tuple[float, float]

    def scaled(self, share: float, corner) -> "Cut":
        """The arc of ``share`` times this one's radius through the same ``corner`` (x, y)."""
        v = np.asarray(corner, dtype=float)
        a, b = v + (np.asarray(self.a) - v) * share, v + (np.asarray(self.b) - v) * share
        return Cut(self.index, self.rho * share, self.ell * share, self.dev * share, self.speed * share,
                   (float(a[0]), float(a[1])), (float(b[0]), float(b[1])))


def cuts(waypoints, max_speed: float, turn_rate: float) -> dict[int, Cut]:
    """The arc each inner waypoint of ``waypoints`` (k, 2) would be passed on, keyed by its index: every
    waypoint whose turn is above 0 and at most :data:`CUT_ANGLE` (between legs of some length)."""
    w = np.asarray(waypoints, dtype=float).reshape(-1, 2)
    d = np.diff(w, axis=0)
    legs = np.hypot(d[:, 0], d[:, 1])
    yaw = np.arctan2(d[:, 1], d[:, 0])
    # Each candidate's reach at the largest radius (0 where a waypoint is no candidate), then shrunk where
    # two reaches would overlap on the leg between them: each gets the leg in proportion to its own.
    want = np.zeros(len(w))
    half = np.zeros(len(w))
    for j in range(1, len(w) - 1):
        if legs[j - 1] > 0.0 and legs[j] > 0.0:
            theta = abs((yaw[j] - yaw[j - 1] + math.pi) % (2 * math.pi) - math.pi)
            if 0.0 < theta <= CUT_ANGLE:
                half[j] = theta / 2
                stray = 1 / math.cos(half[j]) - 1  # 0 in floating point for a turn of some 1e-8 rad
                rho = min(max_speed / turn_rate, CUT / stray) if stray > 0 else max_speed / turn_rate
                want[j] = rho * math.tan(half[j])
    out = {}
    for j in map(int, np.flatnonzero(want > 0)):
        ell = min(want[j], legs[j - 1] * want[j] / (want[j - 1] + want[j]), legs[j] * want[j] / (want[j] + want[j + 1]))
        rho = ell / math.tan(half[j])
        a, b = w[j] - d[j - 1] / legs[j - 1] * ell, w[j] + d[j] / legs[j] * ell
        out[j] = Cut(j, rho, ell, rho * (1 / math.cos(half[j]) - 1), rho * turn_rate,
                          (float(a[0]), float(a[1])), (float(b[0]), float(b[1])))
    return out


def passed_moving(w: np.ndarray, max_speed: float, turn_rate: float, leg_ds: np.ndarray, clear,
                  dt: float) -> dict:
    """The corners passed on the move (waypoint index: (the :class:`Cut` driven, the
    largest arc's ``dev``)): the first arc of :data:`SHRINK` whose chord ``clear``
    (:func:`arc_clear`) finds clear, while it allows at least one cell (``leg_ds``, m) a step of ``dt`` s on both legs."""
    if clear is None:
        return {}
    out = {}
    for j, largest in cuts(w, max_speed, turn_rate).items():
        for share in SHRINK:
            cut = largest.scaled(share, w[j])
            if max(leg_ds[j - 1], leg_ds[j]) > cut.speed * dt:
                break  # slower than a cell a step on a leg: turned on the spot
            if clear(cut, w[j]):
                out[j] = (cut, largest.dev)
                break
    return out


def cap_moves(ok: np.ndarray, s: np.ndarray, corner: np.ndarray, leg_ds: np.ndarray, at: float, cut: Cut,
              dt: float) -> None:
    """No move of the timed sweep (:mod:`worldgen.people.timed`: ``ok`` (cell, cells a step), the cells at arc
    lengths ``s``, the legs' first cells ``corner`` and cell lengths ``leg_ds``) that comes within
    ``cut.ell`` (along the path) of the corner at arc length ``at`` faster than the arc's ``cut.speed``."""
    n = len(s) - 1
    reach = cut.ell + 1e-5  # 10 um more than the arc's: world.json's 6-decimal rows stay out of it where fast
    lo = int(np.searchsorted(s, at - reach - (ok.shape[1] + 1) * float(leg_ds.max()), side="left"))
    hi = int(np.searchsorted(s, at + reach, side="right"))
    c = np.arange(lo, min(hi, n) + 1)
    cell = leg_ds[np.clip(np.searchsorted(corner, c, side="right") - 1, 0, len(leg_ds) - 1)]
    for u in range(1, ok.shape[1]):
        near = (s[c] <= at + reach) & (s[np.minimum(c + u, n)] >= at - reach)
        ok[c, u] &= ~(near & (u * cell > cut.speed * dt))


def arc_polyline(a, corner, b, rho: float, pieces: int = ARC_PIECES) -> tuple[np.ndarray, float]:
    """The arc of radius ``rho`` from ``a`` (on the leg into ``corner``) to ``b`` (on the leg out of it), tangent
    to both, as ``pieces + 1`` points on it, and how far (m) the arc bulges beyond each of their chords."""
    a, v, b = (np.asarray(p, dtype=float) for p in (a, corner, b))
    if min(np.hypot(*(v - a)), np.hypot(*(b - v))) < 1e-12:  # a turn of 1e-8 rad: its arc a point
        return np.array([a, b]), 0.0
    t1, t2 = (v - a) / np.hypot(*(v - a)), (b - v) / np.hypot(*(b - v))
    side = 1.0 if t1[0] * t2[1] - t1[1] * t2[0] >= 0.0 else -1.0  # the turn's sense: left +1, right -1
    theta = math.atan2(abs(t1[0] * t2[1] - t1[1] * t2[0]), float(t1 @ t2))
    centre = a + rho * side * np.array([-t1[1], t1[0]])
    phi = side * theta * np.arange(pieces + 1) / pieces
    r = a - centre
    points = centre + np.stack([r[0] * np.cos(phi) - r[1] * np.sin(phi), r[0] * np.sin(phi) + r[1] * np.cos(phi)], 1)
    return points, rho * (1.0 - math.cos(theta / (2 * pieces)))


def arc_clear(scene, robot):
    """A function of a :class:`Cut` and its corner (x, y): whether the robot's disc swept along the cut's arc
    keeps ``robot.clearance`` (and 1e-5 m more, for world.json's 6-decimal waypoints) from the scene's static
    geometry, doors open, by FCL as the static path was proven (the colliders built at the first call)."""
    built: list = []

    def clear(cut: Cut, corner) -> bool:
        from worldgen.feasibility.collision import Colliders
        from worldgen.feasibility.verify import verify_path
        from worldgen.scene.doors import open_scene

        if not built:
            built.append(Colliders(open_scene(scene)))
        points, bulge = arc_polyline(cut.a, corner, cut.b, cut.rho)
        return bool(verify_path(built[0], robot, points).distance >= robot.clearance + 1e-5 + bulge)

    return clear
