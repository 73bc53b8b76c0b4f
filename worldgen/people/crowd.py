"""The crowd model: people walking from place to place by the social force model, at a fixed step.

Helbing & Molnár, "Social force model for pedestrian dynamics", Phys. Rev. E 51, 4282 (1995).
Each person ``a`` accelerates as

    dv_a/dt = (v0_a e_a - v_a) / tau  +  sum_b w(e_a, r_b - r_a) f_ab  +  sum_B f_aB

- ``e_a``: the unit direction to the next waypoint of the shortest path for the person's disc (exact;
  a walk of many legs has them all answered by one tangent graph, :mod:`~worldgen.feasibility.roadmap`,
  a short one asks :mod:`~worldgen.feasibility.planner` leg by leg); which waypoint that is, and when
  a path is planned again or a place given up, is :mod:`~worldgen.people.routing`'s;
- ``f_ab = -grad V(b)``, ``V = V0 exp(-(b - 2 r) / sigma)``, ``b`` the semi-minor axis of the
  ellipse of the paper (``2 b = sqrt((|r_ab| + |r_ab - v_b dt_h|)^2 - |v_b dt_h|^2)``), less the two
  radii: the paper's pedestrians are points, ours discs;
- ``w = 1`` when the other person is within ``phi`` of ``e_a``, else ``c``;
- ``f_aB = (U0 / R) exp(-d / R)`` along the normal from the nearest point of obstacle ``B``, with
  ``d`` the exact distance from the person's centre to the footprint (or to the floor's edge), as in
  the paper (the disc itself is kept off by the correction below); footprints farther than
  :data:`CUTOFF` are left out (candidates are taken every :data:`LOOK` steps, with room for the way
  walked meanwhile).

Integration is semi-implicit Euler at ``dt``, speeds capped at ``1.3 v0`` (the paper's v_max). A
person before its departure time, or past its last place, stands still: an obstacle the others walk
round.

After each step the geometry is enforced, not hoped for: a step whose straight segment would bring
the disc within ``radius + 2 SLACK`` of a footprint (exact segment distances) or the floor's edge is
halved up to four times, else not taken, and the velocity set to the step actually made. So every
position, and every point between two rows of the written trajectory, keeps the person's disc off
every obstacle. People may still touch each other: the model makes it rare, nothing forbids it.

Members of a group (``groups``) feel the group force of Moussaïd et al. (2010) on top
(:mod:`worldgen.people.groups`).

:func:`simulate` is a pure function of its arguments: no randomness, same inputs, same rows.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any, Mapping, Optional, Sequence

import numpy as np

from worldgen.feasibility.cspace import ConfigSpace
from worldgen.feasibility.exact import GRAPH_MAX_CIRCLES, ExactPlanner, exact_planner
from worldgen.feasibility.geometry import Obstacles2D
from worldgen.floats import round_float
from worldgen.people.behaviours import widest_tube
from worldgen.people.groups import GroupForce, group_force
from worldgen.people.places import PERSON_HEIGHT, SLACK, draw_people, people_footprints
from worldgen.people.routing import ARRIVE, LOOK, REPLAN, STUCK, Router
from worldgen.scene import Mover, Robot, Scene, Task

__all__ = ["SocialForce", "DT", "LOOK", "REPLAN", "ARRIVE", "STUCK", "CUTOFF",
           "ROADMAP_MAX_CIRCLES", "simulate", "walk_people", "walk_plan"]

#: The integration step (s); the trajectories are written at it.
DT = 0.1
#: Distance (m) from a person's centre beyond which an obstacle's push is left out: U0 / R exp(-7.5),
#: 0.03 m/s^2, a hundredth of what a person's own drive gives.
CUTOFF = 1.5
#: Exact route queries a walk asks per person and second walked (measured 0.119 in the benchmark's world:
#: 143 for 20 people over 60 s); :func:`~worldgen.feasibility.exact.exact_planner` picks the planner by it.
#: A power of two, so that the choice is the one made with the two figures below before (exactly so wherever
#: people x seconds is exact in floating point).
QUERIES_PER_PERSON_S = 0.125
#: The largest space the graph is built for.
ROADMAP_MAX_CIRCLES = GRAPH_MAX_CIRCLES


@dataclass(frozen=True)
class SocialForce:
    """The model's parameters, Helbing & Molnár (1995) values (docs/people.md)."""

    tau: float = 0.5  # relaxation time, s
    v0: float = 2.1  # V0 of the person-person potential, m^2/s^2
    sigma: float = 0.3  # its range, m
    u0: float = 10.0  # U0 of the obstacle potential, m^2/s^2
    r: float = 0.2  # its range R, m
    horizon: float = 2.0  # dt_h: how far ahead the other's step is anticipated, s
    phi: float = math.radians(100.0)  # half the field of view, rad
    c: float = 0.5  # weight of what is outside the field of view
    v_max_ratio: float = 1.3  # v_max = 1.3 v0


class _Walls:
    """The footprints as arrays for nearest points: discs, polygon edges (grouped by polygon), the bounds."""

    def __init__(self, obstacles: Obstacles2D, bounds):
        self.obstacles = obstacles
        self.disc_xy, self.disc_r = obstacles.disc_xy, obstacles.disc_r
        self.ea, self.eb = obstacles.edge_a, obstacles.edge_b
        self.ab = self.eb - self.ea
        self.ab2 = np.maximum(np.einsum("ij,ij->i", self.ab, self.ab), 1e-300)
        self.starts = obstacles.edge_start[:-1]
        self.owner = obstacles.edge_owner
        (self.x0, self.y0), (self.x1, self.y1) = bounds

    def refresh(self, p: np.ndarray, reach: float) -> None:
        """Take as candidates, per person, the discs and polygons whose boxes lie within ``reach`` of it;
        everything :meth:`push` needs that does not move (the candidates' geometry gathered, the groups'
        offsets) is laid out here once, not at every step."""
        obs = self.obstacles
        nd = obs.n_discs
        near = obs.near(p, p, reach) if len(obs) else np.zeros((len(p), 0), dtype=bool)
        self.d_person, d_disc = np.nonzero(near[:, :nd])
        self.d_xy, self.d_r = self.disc_xy[d_disc], self.disc_r[d_disc]
        self.d_first, self.d_owner = _runs(self.d_person)
        person, poly = np.nonzero(near[:, nd:])
        counts = obs.edge_start[poly + 1] - obs.edge_start[poly]
        self.g_person, self.g_count = person, counts
        self.g_start = (np.cumsum(counts) - counts).astype(np.int64)
        self.g_first, self.g_owner = _runs(person)
        self.e_person = np.repeat(person, counts)
        e = np.repeat(obs.edge_start[poly], counts) + (np.arange(counts.sum()) - np.repeat(self.g_start, counts))
        self.e_a, self.e_ab, self.e_ab2 = self.ea[e], self.ab[e], self.ab2[e]

    def push(self, p: np.ndarray, radius: float, u0: float, rr: float, cutoff: float) -> tuple[np.ndarray, np.ndarray]:
        """(acceleration (n, 2) ``(u0 / rr) exp(-d / rr)`` away from each candidate footprint and each floor
        edge, ``d`` the exact distance from the centre; clearance (n,): the exact gap from the disc's edge
        to the nearest, at most ``cutoff - radius`` (candidates hold everything closer than ``cutoff``))."""
        n = len(p)
        ax = np.zeros(n)
        ay = np.zeros(n)
        room = np.full(n, cutoff - radius)
        k = u0 / rr
        if len(self.d_person):
            who = self.d_person
            d = p[who] - self.d_xy
            dist = np.maximum(np.hypot(d[:, 0], d[:, 1]), 1e-12)
            centre_gap = dist - self.d_r
            mag = k * np.exp(-centre_gap / rr) / dist
            ax += np.bincount(who, mag * d[:, 0], minlength=n)
            ay += np.bincount(who, mag * d[:, 1], minlength=n)
            room[self.d_owner] = np.minimum(room[self.d_owner], np.minimum.reduceat(centre_gap - radius, self.d_first))
        if len(self.g_person):
            who, ab, starts = self.e_person, self.e_ab, self.g_start
            pw = p[who]
            ap = pw - self.e_a
            t = np.clip((ap[:, 0] * ab[:, 0] + ap[:, 1] * ab[:, 1]) / self.e_ab2, 0.0, 1.0)
            q = self.e_a + t[:, None] * ab
            dist = np.hypot(pw[:, 0] - q[:, 0], pw[:, 1] - q[:, 1])
            best = np.minimum.reduceat(dist, starts)
            # The nearest point of each polygon: of the edges that reach the minimum (two at a corner,
            # which share it), their nearest points averaged.
            hit = (dist <= np.repeat(best, self.g_count) + 1e-12).astype(float)
            share = np.add.reduceat(hit, starts)
            qx = np.add.reduceat(q[:, 0] * hit, starts) / share
            qy = np.add.reduceat(q[:, 1] * hit, starts) / share
            g = self.g_person
            mag = k * np.exp(-best / rr) / np.maximum(best, 1e-12)
            ax += np.bincount(g, mag * (p[g, 0] - qx), minlength=n)
            ay += np.bincount(g, mag * (p[g, 1] - qy), minlength=n)
            room[self.g_owner] = np.minimum(room[self.g_owner], np.minimum.reduceat(best - radius, self.g_first))
        x, y = p[:, 0], p[:, 1]
        edges = np.stack([x - self.x0, self.x1 - x, y - self.y0, self.y1 - y], axis=1)
        mag = k * np.exp(-edges / rr)
        ax += mag[:, 0] - mag[:, 1]
        ay += mag[:, 2] - mag[:, 3]
        return np.column_stack([ax, ay]), np.minimum(room, edges.min(axis=1) - radius)

    def segments_keep(self, a: np.ndarray, b: np.ndarray, keep: float) -> np.ndarray:
        """(m,) bool: every point of segment a[i]b[i] is at least ``keep`` from every footprint and the floor's edge."""
        d, _ = self.obstacles.segments_distance(a, b, keep)
        inside = ((np.minimum(a[:, 0], b[:, 0]) >= self.x0 + keep) & (np.maximum(a[:, 0], b[:, 0]) <= self.x1 - keep)
                  & (np.minimum(a[:, 1], b[:, 1]) >= self.y0 + keep) & (np.maximum(a[:, 1], b[:, 1]) <= self.y1 - keep))
        return inside & (d >= keep)


def _runs(who: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(first index of each run, its value) of sorted ``who``: where each person's candidates start, for one reduceat."""
    first = np.flatnonzero(np.r_[True, who[1:] != who[:-1]]) if len(who) else np.zeros(0, dtype=np.int64)
    return first, who[first]


def simulate(obstacles: Obstacles2D, bounds, starts: np.ndarray, places: np.ndarray, speeds: np.ndarray,
             radius: float, duration: float, dt: float = DT, model: SocialForce = SocialForce(),
             depart: Optional[np.ndarray] = None, groups: Optional[np.ndarray] = None,
             group_model: GroupForce = GroupForce()) -> np.ndarray:
    """(steps + 1, n, 2) positions of the people at t = 0, dt, 2 dt, ... up to ``duration``.

    ``obstacles`` are what people walk round (:func:`worldgen.people.places.people_footprints`
    as :class:`Obstacles2D`), ``starts`` (n, 2) free for the disc of ``radius + 2 SLACK``,
    ``places`` (n, k, 2) each person's places in order (NaN rows end a shorter list), ``speeds`` (n,)
    preferred speeds (m/s), ``depart`` (n,) when each sets off (s; until then it stands still),
    ``groups`` (n,) each person's group (-1: alone), whose members feel :func:`group_force` too.
    """
    starts = np.asarray(starts, dtype=float).reshape(-1, 2)
    n = len(starts)
    steps = int(round(duration / dt))
    out = np.zeros((steps + 1, n, 2))
    out[0] = starts
    if n == 0:
        return out
    walls = _Walls(obstacles, bounds)
    router = Router(_route_finder(ConfigSpace.build(obstacles, radius + SLACK, bounds), n, duration),
                     ConfigSpace.build(obstacles, radius, bounds), starts, places)
    keep = radius + 2 * SLACK
    leave = np.zeros(n) if depart is None else np.asarray(depart, dtype=float)
    v_max = model.v_max_ratio * np.asarray(speeds, dtype=float)
    p, v = starts.copy(), np.zeros((n, 2))
    cos_phi = math.cos(model.phi)
    for k in range(1, steps + 1):
        waiting = leave > (k - 1) * dt + 1e-9
        router.update(p, k - 1, waiting)
        to = router.target - p
        dist = np.hypot(to[:, 0], to[:, 1])
        e = np.where(dist[:, None] > 1e-9, to / np.maximum(dist, 1e-9)[:, None], 0.0)
        v0 = np.where(router.done | waiting, 0.0, speeds)
        acc = (v0[:, None] * e - v) / model.tau
        acc += _people_force(p, v, e, radius, model, cos_phi)
        if groups is not None:
            acc += group_force(p, v, e, groups, radius, group_model)
        if (k - 1) % LOOK == 0:
            walls.refresh(p, CUTOFF + LOOK * dt * float(v_max.max()))
        push, room = walls.push(p, radius, model.u0, model.r, CUTOFF)
        acc += push
        v_new = v + dt * acc
        speed = np.hypot(v_new[:, 0], v_new[:, 1])
        v_new *= np.minimum(1.0, v_max / np.maximum(speed, 1e-12))[:, None]
        # Before setting off and after its last place a person stands still (an obstacle to the others).
        v_new[router.done | waiting] = 0.0
        p_new = _keep_off(walls, p, p + dt * v_new, room - 2 * SLACK, keep)
        v = (p_new - p) / dt
        p = out[k] = p_new
    return out


def _route_finder(cs: ConfigSpace, n: int, duration: float) -> ExactPlanner:
    """The router of a walk of ``n`` people for ``duration`` s: the exact planner that costs less for it."""
    return exact_planner(cs, n * duration * QUERIES_PER_PERSON_S)


def _people_force(p: np.ndarray, v: np.ndarray, e: np.ndarray, radius: float, m: SocialForce,
                  cos_phi: float) -> np.ndarray:
    """(n, 2) the sum over the others of w f_ab, the elliptic repulsion of Helbing & Molnár."""
    n = len(p)
    if n < 2:
        return np.zeros((n, 2))
    dx, dy = p[:, 0, None] - p[None, :, 0], p[:, 1, None] - p[None, :, 1]  # r_ab = r_a - r_b
    sx, sy = m.horizon * v[None, :, 0], m.horizon * v[None, :, 1]  # b's step anticipated
    rx, ry = dx - sx, dy - sy
    n1 = np.maximum(np.sqrt(dx * dx + dy * dy), 1e-9)
    n2 = np.maximum(np.sqrt(rx * rx + ry * ry), 1e-9)
    b = 0.5 * np.sqrt(np.maximum((n1 + n2) ** 2 - (sx * sx + sy * sy), 1e-18))
    mag = (m.v0 / m.sigma) * np.exp(np.minimum(-(b - 2 * radius) / m.sigma, 20.0)) * (n1 + n2) / (4 * b)
    seen = -(e[:, 0, None] * dx + e[:, 1, None] * dy) >= n1 * cos_phi
    w = np.where(seen, mag, m.c * mag)
    np.fill_diagonal(w, 0.0)
    return np.column_stack([np.sum(w * (dx / n1 + rx / n2), axis=1), np.sum(w * (dy / n1 + ry / n2), axis=1)])


def _keep_off(walls: _Walls, p: np.ndarray, p_new: np.ndarray, room: np.ndarray, keep: float) -> np.ndarray:
    """The steps shortened (halved up to four times, else not taken) where the disc would come within
    ``keep`` of a footprint; ``room`` (n,) how far each may move with no test (its exact gap)."""
    length = np.hypot(*(p_new - p).T)
    check = np.flatnonzero(length >= room)
    if not len(check):
        return p_new
    out = p_new.copy()
    for share in (1.0, 0.5, 0.25, 0.125, 0.0625):
        if not len(check):
            break
        trial = p[check] + share * (p_new[check] - p[check])
        ok = walls.segments_keep(p[check], trial, keep)
        out[check[ok]] = trial[ok]
        check = check[~ok]
    out[check] = p[check]
    return out


def walk_people(scene: Scene, tasks: Sequence[Task], robot: Robot, params: Mapping[str, Any],
                rng: np.random.Generator) -> tuple[tuple[Mover, ...], Optional[str]]:
    """The people of ``params`` drawn (:func:`~worldgen.people.places.draw_people`) and walked:
    (movers with ``person=True``, None), or ((), reason) when they do not fit."""
    plan, reason = draw_people(scene, tasks, robot, params, rng)
    return ((), reason) if plan is None else (walk_plan(scene, tasks, robot, params, plan), None)


def walk_plan(scene: Scene, tasks: Sequence[Task], robot: Robot, params: Mapping[str, Any], plan) -> tuple[Mover, ...]:
    """The people of a drawn ``plan`` walked: movers with ``person=True`` (the costly half of :func:`walk_people`,
    which the pipeline runs only on a draw that passed its static checks)."""
    obstacles = Obstacles2D.from_footprints(people_footprints(scene, tasks, robot, widest_tube(params)))
    track = simulate(obstacles, scene.bounds, plan.starts, plan.places, plan.speeds, plan.radius, plan.duration,
                     depart=plan.depart, groups=plan.groups)
    times = np.array([round_float(k * DT) for k in range(len(track))])
    people = []
    for i in range(track.shape[1]):
        xy = np.round(track[:, i, :], 6)
        # A person standing still needs only the first and last row of the stay.
        still = np.all(xy[1:-1] == xy[:-2], axis=1) & np.all(xy[1:-1] == xy[2:], axis=1)
        keep = np.r_[True, ~still, True]
        rows = np.column_stack([times[keep], xy[keep]])
        # Mover takes the (k, 3) array as it is and stores it as rows (its __post_init__), faster than tuples here.
        people.append(Mover(f"person_{i}", plan.radius, PERSON_HEIGHT, rows, False,  # type: ignore[arg-type]
                            params["friction"], person=True))
    return tuple(people)
