"""A taut path as the planner finds it (straight legs and the arcs between them), and the polyline
written for it: each arc replaced by a polygon circumscribed about it, so no chord cuts in."""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

__all__ = ["Contact", "Route", "waypoints", "MAX_ARC_STEP"]

#: Largest angle (rad) one straight piece of a written arc may turn: the polygon round an arc
#: is then at most 0.33 % longer than the arc.
MAX_ARC_STEP = math.pi / 16


@dataclass(frozen=True)
class Contact:
    """The path winding round ``circle`` on ``side`` (+1 counter-clockwise) from outward normal angle
    ``start`` (rad) over ``sweep`` (rad, >= 0), in the direction of travel."""

    circle: int
    side: int
    start: float
    sweep: float


@dataclass(frozen=True)
class Route:
    """A taut path: the straight legs' ends ``points`` (k, 2) (spawn, then for each contact its
    arrival and departure point, then goal), ``contacts`` between them, and the exact ``length``."""

    points: np.ndarray
    contacts: tuple[Contact, ...]
    length: float


def waypoints(cs, route: Route, spare: float) -> np.ndarray:
    """(k, 2) a polyline along ``route`` that keeps the clearance: straight legs as they are, each arc
    replaced by a polygon circumscribed about it (so no chord cuts into the obstacle it wraps).

    Such a polygon bulges out of the arc by rho (1 / cos(step / 2) - 1); the step is
    chosen so that the bulge stays within the arc's own slack to other obstacles
    (measured exactly, up to a tenth of the radius) plus ``spare`` (m), a part of the
    planner's safety margin.
    """
    arcs = [k for k, c in enumerate(route.contacts) if c.sweep > 1e-9]
    slack = {}
    if arcs:
        contacts = [route.contacts[k] for k in arcs]
        circle = np.array([c.circle for c in contacts], dtype=np.int64)
        ccw_start = np.array([c.start if c.side > 0 else c.start - c.sweep for c in contacts])
        measured = cs.arc_clearance(circle, ccw_start, np.array([c.sweep for c in contacts]))
        slack = dict(zip(arcs, measured.tolist()))
    pts: list[np.ndarray] = [route.points[0]]
    for k, contact in enumerate(route.contacts):
        arrive, depart = route.points[1 + 2 * k], route.points[2 + 2 * k]
        pts.append(arrive)
        if k in slack:
            c, rho = cs.centre[contact.circle], float(cs.rho[contact.circle])
            bulge = max(slack[k], 0.0) + spare
            step = min(MAX_ARC_STEP, 2 * math.acos(1 / (1 + bulge / rho)))
            n = max(1, math.ceil(contact.sweep / step - 1e-9))
            piece = contact.sweep / n
            out = rho / math.cos(piece / 2)
            ang = contact.start + contact.side * (np.arange(n) + 0.5) * piece
            pts.extend(c + out * np.stack([np.cos(ang), np.sin(ang)], axis=1))
        pts.append(depart)
    pts.append(route.points[-1])
    dense = np.array(pts, dtype=float)
    keep = np.r_[True, np.any(np.abs(np.diff(dense, axis=0)) > 1e-12, axis=1)]
    return dense[keep]
