"""People who react to the robot, step by step, each inside its tube (docs/people.md).

A reacting person is not integrated freely: its position is ``r(s) + o``, ``r`` its recorded trajectory
(world.json ``people[].trajectory``, straight between rows, standing before the first and after the
last), ``s`` its *phase* (the recorded time it is at) and ``o`` its *offset*. The tube of
:mod:`worldgen.people.behaviours` is then two bounds, enforced at every step: ``|s - t| <= tau`` and
``|o| <= d``. A reaction that would break either is clipped onto it, and the clip counted
(:attr:`Reactions.clips`). Between two steps the phase and the offset are interpolated linearly, so
the person is inside its tube at every instant, not only at the steps (both bounds are convex).

Each step the robot's position and velocity come in; each person's wanted velocity is the social
force model's (:class:`~worldgen.people.crowd.SocialForce` values): relaxation with ``tau_sf`` toward
the recorded velocity (phase catching up with the clock at up to :data:`RATE_MAX`, the offset
returning over :data:`RETURN` s), plus its behaviour's term:

- ``regular``: the robot is one more pedestrian: Helbing & Molnár's elliptic repulsion, the robot's
  disc and its velocity in it, and a sideways part as strong (ours: head-on, the paper's force only
  brakes; this steps aside, to the side away from the robot, to the right when dead ahead);
- ``scared``: as regular, plus HuNavSim's push away from the robot, ``20 R / gap`` (``R`` the
  obstacle range, 0.2 m), and no faster than 0.6 m/s while the robot is within 3 m (HuNavSim's);
- ``surprised``: stands still while the robot is within 4 m (HuNavSim's), at most
  :data:`STOP_SHARE` of its ``tau``; then, and once the robot has left, it goes on as regular;
- ``curious``: while the robot is within 10 m, for at most :data:`STOP_SHARE` of its ``tau``, walks
  toward it at ``1.8 dist / 10`` m/s (HuNavSim's), standing within 1.5 m of it; then goes on as regular.

The step is then split into phase (along the recorded velocity, never back) and offset. Walls: the
offset is also held to the recorded position's exact clearance from every footprint, so a person
stepping aside stays off walls. People do not react to one another (their recorded walks already
do). A :class:`Reactions` is a pure function of its inputs: same robot poses, same positions.
"""

from __future__ import annotations

import math
from typing import Optional, Sequence

import numpy as np

from worldgen.people.behaviours import BEHAVIOURS, Tube
from worldgen.people.crowd import SocialForce

__all__ = ["Reactions", "RATE_MAX", "RETURN", "STOP_SHARE", "SURPRISE_RANGE", "SCARED_RANGE", "CURIOUS_RANGE",
           "CURIOUS_STOP", "SNAP", "wall_gap_of"]

#: The fastest a lagging person's phase runs to catch up with the clock (the model's v_max ratio).
RATE_MAX = 1.3
#: Time (s) over which an offset would be walked back to the recorded line.
RETURN = 1.0
#: Share of its tau a surprised or curious person spends reacting before it goes on (the rest is room
#: to catch up, so that the tube's phase bound is not what ends the reaction).
STOP_SHARE = 0.8
#: HuNavSim's distances (m, centre to centre): surprised sees the robot within 4 m, scared within 3 m,
#: curious within 10 m and stands 1.5 m from it.
SURPRISE_RANGE, SCARED_RANGE, CURIOUS_RANGE, CURIOUS_STOP = 4.0, 3.0, 10.0, 1.5
_SCARED_SPEED = 0.6
#: How close (s of phase, m of offset) to its recorded trajectory a person out of the robot's reach is put
#: back on it: a jump of at most about 6 mm (inside the tube: the recorded position now is in it).
SNAP = 0.003
_SHIFT = 1e4  # s between two people's tracks in the one array of all (longer than any walk: 600 s)


class Reactions:
    """The reacting people of one world: ``tracks`` (k, 3) ``t, x, y`` each, ``radii``, ``behaviours``
    (names of :data:`BEHAVIOURS`), ``tubes``; ``wall_gap(xy) -> (m,)`` the exact clearance of points
    from every footprint and the floor's edge (None: no walls)."""

    def __init__(self, tracks: Sequence[np.ndarray], radii: Sequence[float], behaviours: Sequence[str],
                 tubes: Sequence[Tube], wall_gap=None, model: SocialForce = SocialForce()):
        self.tracks = [np.asarray(t, dtype=float).reshape(-1, 3) for t in tracks]
        self.n = len(self.tracks)
        self.radius = np.asarray(radii, dtype=float).reshape(self.n)
        self.kind = np.array([BEHAVIOURS.index(b) for b in behaviours], dtype=np.int64).reshape(self.n)
        self.d = np.array([t.d for t in tubes], dtype=float).reshape(self.n)
        self.tau = np.array([t.tau for t in tubes], dtype=float).reshape(self.n)
        self.model = model
        # How far each reacts from: its behaviour's range, the robot's repulsion's (negligible beyond 4 m).
        self._range = np.array([(-np.inf, 4.0, SURPRISE_RANGE, 4.0, CURIOUS_RANGE)[k] for k in self.kind])
        # All the tracks in one array, person i's times shifted by i * _SHIFT: one search finds everyone's leg.
        times, xy, vel, room, first = [], [], [], [], [0]
        for i, (track, r) in enumerate(zip(self.tracks, self.radius)):
            dt = np.maximum(np.diff(track[:, 0]), 1e-12)
            step = np.diff(track[:, 1:], axis=0)
            gap = np.full(len(track), np.inf) if wall_gap is None else wall_gap(track[:, 1:]) - r
            # Any point of a leg is within half its length of one end: its clearance is at least this.
            leg_room = np.minimum(gap[:-1], gap[1:]) - np.hypot(step[:, 0], step[:, 1]) / 2
            times.append(track[:, 0] + i * _SHIFT)
            xy.append(track[:, 1:])
            vel.append(np.vstack([step / dt[:, None], np.zeros((1, 2))]))
            room.append(np.maximum(np.r_[leg_room, gap[-1]], 0.0))
            first.append(first[-1] + len(track))
        self._t, self._xy = np.concatenate(times), np.vstack(xy)
        self._vel, self._room = np.vstack(vel), np.concatenate(room)
        self._first, self._last = np.array(first[:-1]), np.array(first[1:]) - 1
        self._t0 = np.array([t[0, 0] for t in self.tracks])
        self._t1 = np.array([t[-1, 0] for t in self.tracks])
        speeds = np.hypot(self._vel[:, 0], self._vel[:, 1])
        self.v_cap = np.array([max(0.5, model.v_max_ratio * float(speeds[a:b + 1].max()))
                               for a, b in zip(self._first, self._last)])
        self.reset()

    def reset(self) -> None:
        """Back to t = 0, everyone on its recorded start."""
        n = self.n
        self.t = 0.0
        self.s, self.o, self.v = np.zeros(n), np.zeros((n, 2)), np.zeros((n, 2))
        self._prev_s, self._prev_o = self.s.copy(), self.o.copy()
        self.busy = np.zeros(n)  # s spent surprised or curious
        self.spent = np.zeros(n, dtype=bool)  # the reaction is over: regular from now on
        #: Per person, the steps at which the tube clipped a reaction.
        self.clips = np.zeros(n, dtype=np.int64)
        #: Whether each person is on its recorded trajectory (phase = clock, no offset): where nobody
        #: reacts, a step is the recorded walk and costs one look-up (:meth:`step`).
        self.on_track = np.ones(n, dtype=bool)
        self.calm = True  # everyone on track through the last step
        self.p, self._u, _ = self._state(self.s)

    # -- the recorded trajectory ----------------------------------------------------------------------
    def _locate(self, s: np.ndarray, who: np.ndarray):
        """(leg (global row index), share of the way along it) of person ``who[k]`` at phase ``s[k]``."""
        # np.minimum / np.maximum rather than np.clip: a step is a hundred small operations, and clip's
        # Python wrapper costs more than the arithmetic.
        sc = np.minimum(np.maximum(s, self._t0[who]), self._t1[who]) + who * _SHIFT
        k = np.minimum(np.maximum(np.searchsorted(self._t, sc, side="right") - 1, self._first[who]),
                       np.maximum(self._last[who] - 1, self._first[who]))
        span = self._t[np.minimum(k + 1, len(self._t) - 1)] - self._t[k]
        share = np.minimum(np.maximum((sc - self._t[k]) / np.where(span > 0, span, 1.0), 0.0), 1.0)
        return k, share

    def _at(self, s: np.ndarray, who: np.ndarray) -> np.ndarray:
        k, share = self._locate(s, who)
        nxt = np.minimum(k + 1, self._last[who])
        return self._xy[k] + share[:, None] * (self._xy[nxt] - self._xy[k])

    def _state(self, s: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """(recorded position (n, 2), recorded velocity (n, 2), wall room (n,)) of everyone at phase ``s``."""
        who = np.arange(self.n)
        k, share = self._locate(s, who)
        nxt = np.minimum(k + 1, self._last)
        xy = self._xy[k] + share[:, None] * (self._xy[nxt] - self._xy[k])
        before, after = s < self._t0, s >= self._t1
        u = np.where((before | after)[:, None], 0.0, self._vel[k])
        room = np.where(after, self._room[self._last], np.where(before, self._room[self._first], self._room[k]))
        return xy, u, room

    def positions(self, shares) -> np.ndarray:
        """(len(shares), n, 2) where each person is at each share (0 to 1) of the way through the last
        step (phase and offset interpolated: inside the tube at every instant)."""
        f = np.asarray(shares, dtype=float).reshape(-1, 1)
        s = self._prev_s[None, :] + f * (self.s - self._prev_s)[None, :]
        out = self._prev_o[None] + f[:, :, None] * (self.o - self._prev_o)[None]
        who = np.broadcast_to(np.arange(self.n), s.shape)
        return out + self._at(s.reshape(-1), who.reshape(-1)).reshape(out.shape)

    # -- one step -------------------------------------------------------------------------------------
    def step(self, dt: float, robot_xy, robot_v, robot_radius: float) -> np.ndarray:
        """Advance every person by ``dt`` s against the robot at ``robot_xy`` moving at ``robot_v`` (m/s);
        the (n, 2) positions at the step's end."""
        t1 = self.t + dt
        self._prev_s, self._prev_o = self.s.copy(), self.o.copy()
        if not self.n:
            self.t = t1
            return self.p
        m = self.model
        p, s, o, u = self.p, self.s, self.o, self._u
        rel = p - np.asarray(robot_xy, dtype=float)[None, :]
        dist = np.maximum(np.hypot(rel[:, 0], rel[:, 1]), 1e-9)
        near = dist < self._range + float(np.hypot(*robot_v)) * m.horizon
        if not near.any() and self.on_track.all():  # nobody reacts: the recorded walk
            self.calm = True
            self.t, self.s = t1, np.full(self.n, t1)
            self.p, self._u, _ = self._state(self.s)
            self.v = self._u
            return self.p
        self.calm = False
        rate = np.minimum(np.maximum(1.0 + (self.t - s) / RETURN, 0.0), RATE_MAX)
        want = rate[:, None] * u - o / RETURN
        force, heading, seen = self._robot_force(rel, dist, u, np.asarray(robot_v, dtype=float), robot_radius)
        kind = np.where(self.spent & (self.kind >= 2) & (self.kind != 3), 1, self.kind)
        scared = (kind == 3) & (dist < SCARED_RANGE)
        if scared.any():
            gap = np.maximum(dist - self.radius - robot_radius, 1e-3)
            force[scared] += ((20.0 * m.r / gap) / dist)[scared, None] * rel[scared]
            fast = np.hypot(want[:, 0], want[:, 1])
            want[scared] *= np.minimum(1.0, _SCARED_SPEED / np.maximum(fast, 1e-9))[scared, None]
        force = self._aside(force, rel, heading, seen)
        acc = (want - self.v) / m.tau + np.where((kind == 1)[:, None] | scared[:, None], force, 0.0)
        curious = (kind == 4) & (dist < CURIOUS_RANGE)
        if curious.any():
            toward = -rel / dist[:, None] * (1.8 * dist / CURIOUS_RANGE)[:, None]
            toward[dist <= CURIOUS_STOP] = 0.0
            acc[curious] = ((toward - self.v) / m.tau)[curious]
        v = self.v + dt * acc
        speed = np.hypot(v[:, 0], v[:, 1])
        v *= np.minimum(1.0, self.v_cap / np.maximum(speed, 1e-12))[:, None]
        surprised = (kind == 2) & (dist < SURPRISE_RANGE)
        v[surprised] = 0.0
        reacting = surprised | curious
        self.busy += np.where(reacting, dt, 0.0)
        self.spent |= (self.busy > 0) & (~reacting | (self.busy >= STOP_SHARE * self.tau))
        self._advance(t1, p, s, u, v * dt, rate, dt, near)
        return self.p

    def _advance(self, t1: float, p, s, u, move, rate, dt: float, near) -> None:
        """Split ``move`` into phase and offset, clip both onto the tube, and count the clips; a person out
        of the robot's reach within :data:`SNAP` of its recorded trajectory is put back on it."""
        uu = u[:, 0] * u[:, 0] + u[:, 1] * u[:, 1]
        ds = np.where(uu > 1e-12, (move[:, 0] * u[:, 0] + move[:, 1] * u[:, 1]) / np.maximum(uu, 1e-12), rate * dt)
        s_new = s + np.minimum(np.maximum(ds, 0.0), 2.0 * RATE_MAX * dt)
        lo, hi = t1 - self.tau, t1 + self.tau
        clipped = (s_new < lo - 1e-9) | (s_new > hi + 1e-9)
        s_new = np.minimum(np.maximum(s_new, lo), hi)
        xy, u_new, room = self._state(s_new)
        o_new = p + move - xy
        room = np.minimum(self.d, room)
        size = np.hypot(o_new[:, 0], o_new[:, 1])
        over = size > room
        clipped |= size > self.d + 1e-9
        o_new[over] *= (room / np.maximum(size, 1e-300))[over, None]
        self.clips += clipped & (self.kind != 0)
        # Impassive: the recorded trajectory, exactly; back on track: out of reach and within SNAP of it.
        back = (self.kind == 0) | (~near & (np.abs(s_new - t1) < SNAP) & (np.hypot(o_new[:, 0], o_new[:, 1]) < SNAP))
        self.on_track = back
        if back.any():
            s_new = np.where(back, t1, s_new)
            o_new = np.where(back[:, None], 0.0, o_new)
            xy, u_new, _ = self._state(s_new)
        p_new = xy + o_new
        self.v = (p_new - p) / dt
        self.t, self.s, self.o, self.p, self._u = t1, s_new, o_new, p_new, u_new

    def _robot_force(self, rel, dist, u, robot_v, robot_radius: float):
        """((n, 2) Helbing & Molnár's elliptic repulsion from the robot (its disc, its velocity) on each
        person, weighted by the field of view; each one's heading (n, 2); whether it sees the robot (n,))."""
        m = self.model
        step = m.horizon * robot_v
        ahead = rel - step[None, :]
        n2 = np.maximum(np.hypot(ahead[:, 0], ahead[:, 1]), 1e-9)
        b = 0.5 * np.sqrt(np.maximum((dist + n2) ** 2 - float(step @ step), 1e-18))
        mag = (m.v0 / m.sigma) * np.exp(np.minimum(-(b - self.radius - robot_radius) / m.sigma, 20.0))
        mag *= (dist + n2) / (4 * b)
        f = mag[:, None] * (rel / dist[:, None] + ahead / n2[:, None])
        heading = u / np.maximum(np.hypot(u[:, 0], u[:, 1]), 1e-12)[:, None]
        seen = -(heading[:, 0] * rel[:, 0] + heading[:, 1] * rel[:, 1]) >= dist * math.cos(m.phi)
        return f * np.where(seen, 1.0, m.c)[:, None], heading, seen

    @staticmethod
    def _aside(f, rel, heading, seen) -> np.ndarray:
        """``f`` plus a sideways part as strong where the robot is in view: away from the side the robot is
        on, to the right when it is dead ahead."""
        right = np.column_stack([heading[:, 1], -heading[:, 0]])
        side = np.sign(right[:, 0] * rel[:, 0] + right[:, 1] * rel[:, 1])
        side[side == 0] = 1.0
        return f + (np.hypot(f[:, 0], f[:, 1]) * side)[:, None] * right * seen[:, None]


def wall_gap_of(obstacles, bounds) -> Optional[object]:
    """``xy -> (m,)``: the exact distance from points to the nearest footprint of ``obstacles``
    (:class:`~worldgen.feasibility.geometry.Obstacles2D`) or the edge of ``bounds``."""
    (x0, y0), (x1, y1) = bounds

    def gap(xy: np.ndarray) -> np.ndarray:
        xy = np.asarray(xy, dtype=float).reshape(-1, 2)
        edge = np.minimum.reduce([xy[:, 0] - x0, x1 - xy[:, 0], xy[:, 1] - y0, y1 - xy[:, 1]])
        if len(obstacles):
            return np.minimum(edge, obstacles.points_distance(xy)[0])
        return edge

    return gap
