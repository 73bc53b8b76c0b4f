"""A route off the static path: where a robot that turns on the spot can be, step by step, among agents on
known schedules (the witness :mod:`worldgen.people.offpath` reads an off-path certificate's route from).

On a task's grid (:mod:`worldgen.people.grid`: cells ``h`` apart, steps of ``dt``) the robot is in a cell
facing one of 8 headings (multiples of 45 degrees). In a step it waits, or moves one cell along its heading
(a diagonal cell is ``h sqrt 2`` away, :data:`~worldgen.people.grid.PACE` of the top speed in a step, the axes
being slower still); it turns 45 degrees on the spot in :func:`turn_steps` steps, the turn itself at the
stated turn rate plus the time a stop and a start cost at the stated acceleration. So the witness is slower
than the robot everywhere, which lets the exact sweep along its route keep up with it.

A cell is free of an agent at a step when its centre is farther than the agent's reach from every position
the agent's tube allows round the step (:class:`Agents`). The reach is the certificate's (robot inflation,
the agent's radius and tube, MARGIN and the tracking margin, and what both close in half a step) plus
``room``: how far the exact sweep may drift from the witness's timing and still find the cell clear.

None of this is the certificate: the route is proven again by FCL and timed by the exact sweep
(:func:`worldgen.people.timed.timed_path`), which alone decides. A forward sweep keeps the (heading, cell)
states the robot can be in; the first step one of the goal's cells is held
gives the route, read back as the cells where the heading changes. Two things end it early: no state left,
and (once every person stands) no free cell of the goal's connected to a state through cells no standing
person covers. :func:`lattice_reachable` asks the same of a robot that turns in no time (one state a cell,
8 times fewer): where even it finds no way, the turning sweep is not run.
"""

from __future__ import annotations

import math
from typing import Optional, Sequence

import numpy as np

from worldgen.people.grid import DT, Floor
from worldgen.people.timed import DT as CERTIFICATE_DT
from worldgen.scene.motion import positions_at

__all__ = ["HEADINGS", "Agents", "turn_steps", "lattice_reachable", "lattice_route"]

#: The 8 headings as (rows, columns) a move shifts: heading k is k x 45 degrees from +x (rows are y, columns x).
HEADINGS = ((0, 1), (1, 1), (1, 0), (1, -1), (0, -1), (-1, -1), (-1, 0), (-1, 1))
#: Steps whose agents' blocked cells are worked out at once.
_CHUNK = 64


def turn_steps(angle: float, limits, dt: float = DT) -> int:
    """Steps of ``dt`` s a turn of ``angle`` rad on the spot takes within ``limits``
    (:class:`~worldgen.people.timed.Limits`), with the stop before it and the start after it (``max_speed /
    acceleration`` between them)."""
    return math.ceil(angle / (limits.turn_rate * dt) - 1e-9) + math.ceil(limits.max_speed / (limits.acceleration * dt))


class Agents:
    """Where the agents block a :class:`Floor`, step by step: a cell is blocked when an agent (``tracks`` (k, 3)
    ``t, x, y``, ``radii``, ``tubes``, ``loops``) is within its reach, ``keep`` (the robot's inflation and what
    the certificate keeps beyond it) + its radius + its tube's ``d`` + ``room`` + what the robot at ``top`` m/s
    and the fastest agent close in half a step, at a step of its tube's window round the step.

    The spawn's cell is blocked only within the certificate's own reach (no room, its own step): the robot
    stands exactly there until it sets off, in the witness as in the certificate, and a mover that starts
    0.6 m from it (movers start ``robot.inflation + radius`` from it) would else block the witness at t = 0."""

    def __init__(self, floor: Floor, tracks: Sequence[np.ndarray], radii: Sequence[float], tubes,
                 loops: Sequence[bool], keep: float, room: float, top: float):
        fastest = max([_fastest(t) for t in tracks], default=0.0)
        self.floor, self.tracks, self.loops = floor, list(tracks), [bool(x) for x in loops]
        dt = floor.dt
        self.reach = np.array([keep + room + float(r) + float(tube.d) + (top + fastest) * dt / 2
                               for r, tube in zip(radii, tubes)])
        self._at_spawn = (np.array([floor.ends[0][0]]), np.array([floor.ends[0][1]]))
        self._spawn_reach = np.array([keep + float(r) + float(tube.d) + (top + fastest) * CERTIFICATE_DT / 2
                                      for r, tube in zip(radii, tubes)])
        self.window = np.array([0 if tube.tau <= 0 else math.ceil(tube.tau / dt + 0.5 - 1e-9) for tube in tubes],
                               dtype=int)
        self._blocked = np.zeros((0,) + floor.static.shape, dtype=bool)
        still = [not loop for loop in self.loops]
        # From this step on every person stands (after its last row and its tube's time): the cells they cover
        # stay covered, and the goal is reachable through the rest (the loops only take more) or never.
        self.settled = math.ceil(max([float(t[-1, 0]) for t, s in zip(self.tracks, still) if s] + [0.0]) / dt) \
            + int(self.window.max(initial=0)) + 1
        self._still = np.array(still, dtype=bool)

    def free(self, k: int) -> np.ndarray:
        """(ny, nx) the cells free of the static world and of every agent at step ``k``."""
        while k >= len(self._blocked):
            k0 = len(self._blocked)
            more = _blocked(self.floor.xs, self.floor.ys, self.tracks, self.loops, self.reach, self.window, k0,
                            _CHUNK, self.floor.dt)
            more[(slice(None),) + self.floor.spawn] = _blocked(*self._at_spawn, self.tracks, self.loops,
                                                               self._spawn_reach, self.window, k0, _CHUNK,
                                                               self.floor.dt)[:, 0, 0]
            self._blocked = np.concatenate([self._blocked, more])
        return self.floor.static & ~self._blocked[k]

    def lasting(self) -> np.ndarray:
        """(ny, nx) the cells free of the static world and of every person standing where it ends, for ever."""
        who = np.flatnonzero(self._still)
        tracks, none, still = [self.tracks[j] for j in who], np.zeros(len(who), dtype=int), [False] * len(who)
        stand = _blocked(self.floor.xs, self.floor.ys, tracks, still, self.reach[who], none, self.settled, 1,
                         self.floor.dt)[0]
        stand[self.floor.spawn] = _blocked(*self._at_spawn, tracks, still, self._spawn_reach[who], none, self.settled,
                                           1, self.floor.dt)[0, 0, 0]
        return self.floor.static & ~stand


def lattice_reachable(agents: Agents, steps: int) -> bool:
    """Whether a robot that turns in no time reaches the goal's cells within ``steps`` steps (each a wait or
    a move to one of the 8 neighbours): where it does not, no witness of :func:`lattice_route` does."""
    floor = agents.floor
    now = np.zeros(floor.static.shape, dtype=bool)
    now[floor.spawn] = True
    for k in range(steps + 1):
        if k:
            grown = now.copy()
            for di, dj in HEADINGS:
                grown |= _shifted(now, di, dj)
            now = grown
        now &= agents.free(k)
        if (now & floor.at_goal).any():
            return True
        if not now.any() or (k == agents.settled and not _reaches_goal(now[None], agents.lasting(), floor.at_goal)):
            return False
    return False


def lattice_route(agents: Agents, yaw: float, limits, steps: int) -> Optional[np.ndarray]:
    """(m, 2) the route (the spawn, every cell where the witness turns, the goal) of the earliest witness that
    starts at rest facing ``yaw`` and turns within ``limits`` (:func:`turn_steps`), within ``steps`` steps;
    None where there is none."""
    floor = agents.floor
    offset = [abs((k * math.pi / 4 - yaw + math.pi) % (2 * math.pi) - math.pi) for k in range(8)]
    first = [math.ceil(a / (limits.turn_rate * floor.dt) - 1e-9) for a in offset]  # steps to face heading k first
    got = _sweep(agents, first, turn_steps(math.pi / 4, limits, floor.dt), steps)
    if got is None:
        return None
    pts = np.array([[floor.xs[j], floor.ys[i]] for i, j in got])
    pts[0] = floor.ends[0]
    return _corners(np.vstack([pts, np.asarray(floor.ends[1], dtype=float)[None]]))


def _sweep(agents: Agents, first, turn: int, steps: int) -> Optional[list[tuple[int, int]]]:
    """The cells of the earliest witness (see the module's docstring) within ``steps`` steps, or None."""
    floor = agents.floor
    static, at_goal, spawn = floor.static, floor.at_goal, floor.spawn
    shape = (8,) + static.shape
    movable = static[None] & np.stack([_shifted(static, -di, -dj) for di, dj in HEADINGS])  # moves stay on free floor
    held: list[np.ndarray] = []  # per step, the (8, ny, nx) states, bit-packed
    frees: list[np.ndarray] = []  # per step, the free cells, bit-packed
    recent: list[np.ndarray] = []  # the last ``turn`` steps' states, unpacked
    run = np.zeros(static.shape, dtype=np.int32)  # steps each cell has been free in a row, up to this one
    left, right = [(d - 1) % 8 for d in range(8)], [(d + 1) % 8 for d in range(8)]
    last = max(first)  # until then the spawn still seeds headings it has turned to
    for k in range(steps + 1):
        free = agents.free(k)
        run = np.where(free, run + 1, 0)
        now = np.zeros(shape, dtype=bool)
        if k:
            before = recent[-1]
            now |= before
            moved = before & movable
            for d, (di, dj) in enumerate(HEADINGS):
                now[d] |= _shifted(moved[d], di, dj)
            if k >= turn:
                back = recent[-turn]
                now |= (back[left] | back[right]) & (run > turn)[None]
        for d in range(8):
            if k == first[d]:
                now[d, spawn[0], spawn[1]] |= bool(run[spawn] > k)
        now &= free[None]
        held.append(np.packbits(now))
        frees.append(np.packbits(free))
        recent = (recent + [now])[-max(turn, 1):]
        if (now & at_goal[None]).any():
            return _read_back(lambda step: _unpacked(held[step], shape),
                              lambda step: _unpacked(frees[step], static.shape), k, movable, turn, first, spawn,
                              at_goal)
        if k >= last and (not now.any() or (k == max(agents.settled, last)
                                            and not _reaches_goal(now, agents.lasting(), at_goal))):
            return None
    return None


def _fastest(track: np.ndarray) -> float:
    d = np.diff(np.asarray(track, dtype=float), axis=0)
    return float(np.max(np.hypot(d[:, 1], d[:, 2]) / np.maximum(d[:, 0], 1e-12))) if len(d) else 0.0


def _blocked(xs, ys, tracks, loops, reach, window, k0: int, n: int, dt: float) -> np.ndarray:
    """(n, ny, nx) bool: the cells some agent is within its reach of at steps ``k0`` to ``k0 + n - 1``, an agent
    with a tube at any step of its ``window`` round the step."""
    out = np.zeros((n, len(ys), len(xs)), dtype=bool)
    for j, track in enumerate(tracks):
        w = int(window[j])
        ks = np.arange(k0 - w, k0 + n + w)
        pos = positions_at([np.asarray(track, dtype=float)], [bool(loops[j])], np.maximum(ks, 0) * dt)[:, 0]
        raw = np.zeros((len(ks), len(ys), len(xs)), dtype=bool)
        r = float(reach[j])
        for s, (px, py) in enumerate(pos):
            j0, j1 = np.searchsorted(xs, px - r), np.searchsorted(xs, px + r, side="right")
            i0, i1 = np.searchsorted(ys, py - r), np.searchsorted(ys, py + r, side="right")
            if i0 >= i1 or j0 >= j1:
                continue
            dx, dy = xs[j0:j1] - px, ys[i0:i1] - py
            raw[s, i0:i1, j0:j1] |= dy[:, None] ** 2 + dx[None, :] ** 2 < r * r
        out |= _any_within(raw, 2 * w + 1) if w else raw
    return out


def _any_within(raw: np.ndarray, span: int) -> np.ndarray:
    """(len(raw) - span + 1, ...) bool: whether any of ``span`` consecutive steps of ``raw`` holds, by doubling
    (each pass ORs the runs of the one before with their shift: log2(span) passes of bool arrays)."""
    acc, run = raw, 1
    while 2 * run <= span:
        acc = acc[:-run] | acc[run:]
        run *= 2
    n = len(raw) - span + 1
    return acc[:n] | acc[span - run:span - run + n]


def _reaches_goal(states: np.ndarray, free: np.ndarray, at_goal: np.ndarray) -> bool:
    """Whether a cell of ``at_goal`` is 8-connected to a cell of ``states`` (any heading) through ``free``
    cells: once every agent stands still, the lattice can reach no other cell."""
    comp = states.any(axis=0) & free
    while not (comp & at_goal).any():
        grown = comp.copy()
        for di, dj in HEADINGS:
            grown |= _shifted(comp, di, dj)
        grown &= free
        if np.array_equal(grown, comp):
            return False
        comp = grown
    return True


def _unpacked(packed: np.ndarray, shape: tuple) -> np.ndarray:
    return np.unpackbits(packed, count=int(np.prod(shape))).reshape(shape).astype(bool)


def _shifted(a: np.ndarray, di: int, dj: int) -> np.ndarray:
    """``a`` moved ``di`` rows and ``dj`` columns (what leaves the grid is lost, what enters is False)."""
    out = np.zeros_like(a)
    ny, nx = a.shape
    out[max(di, 0):ny + min(di, 0), max(dj, 0):nx + min(dj, 0)] = a[max(-di, 0):ny - max(di, 0),
                                                                    max(-dj, 0):nx - max(dj, 0)]
    return out


def _read_back(states, frees, k: int, movable, turn: int, first, spawn: tuple[int, int], at_goal
               ) -> list[tuple[int, int]]:
    """The cells of one witness, the spawn's first, from step ``k``'s state at the goal back (``states`` and
    ``frees``: a step's (8, ny, nx) states and (ny, nx) free cells): each step's predecessor a move along the
    heading where the stored states allow one, else a wait, else a turn."""
    d, i, j = (int(v) for v in np.argwhere(states(k) & at_goal[None])[0])
    cells = [(i, j)]

    def stood(i: int, j: int, lo: int, hi: int) -> bool:
        return all(frees(s)[i, j] for s in range(lo, hi + 1))

    while k > 0:
        if (i, j) == spawn and k == first[d] and stood(i, j, 0, k):
            break  # it stood at the spawn from t = 0, turning to this heading
        di, dj = HEADINGS[d]
        pi, pj = i - di, j - dj
        prev = states(k - 1)
        inside = 0 <= pi < prev.shape[1] and 0 <= pj < prev.shape[2]
        if inside and prev[d, pi, pj] and movable[d, pi, pj]:
            i, j, k = pi, pj, k - 1
            cells.append((i, j))
        elif prev[d, i, j]:
            k -= 1
        else:
            back = states(k - turn)
            d = next(e for e in ((d - 1) % 8, (d + 1) % 8) if back[e, i, j] and stood(i, j, k - turn, k))
            k -= turn
    return cells[::-1]


def _corners(pts: np.ndarray) -> np.ndarray:
    """``pts`` less repeated points and points on the straight line between their neighbours."""
    keep = np.r_[True, np.any(np.abs(np.diff(pts, axis=0)) > 1e-12, axis=1)]
    pts = pts[keep]
    if len(pts) < 3:
        return pts
    d = np.diff(pts, axis=0)
    cross = d[:-1, 0] * d[1:, 1] - d[:-1, 1] * d[1:, 0]
    dot = np.einsum("ij,ij->i", d[:-1], d[1:])
    straight = (np.abs(cross) <= 1e-12 * np.hypot(*d[:-1].T) * np.hypot(*d[1:].T)) & (dot > 0)
    return pts[np.r_[True, ~straight, True]]
