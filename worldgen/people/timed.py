"""The certificate among people: a timed path along the proven static path that no person comes near, and
that a differential-drive robot within its limits can drive.

Method (docs/people.md): the robot keeps to its task's proven static path (its polyline, which keeps
``robot.clearance`` from every obstacle) and only chooses *when* to be where along it, within its
:class:`Limits`: top speed ``v``, turn rate ``omega`` and acceleration ``a``. Time is cut into steps of
:data:`DT`; in a step the robot moves ``u`` cells forward at constant speed, ``u`` a whole number from 0
to ``V = ceil(v / (a DT))``, and ``u`` changes by at most one from a step to the next. Each leg is cut into
equal cells no longer than ``v DT / V`` (0.1 % spare for the 6-decimal rows), so ``u`` cells a step is
never faster than ``v`` and one cell a step more or less is never a change of speed above ``a DT``. The
path turns on the spot: the robot comes to every corner at one cell a step at most, stops there, and
stands ``ceil(theta / (omega DT))`` steps while it turns the corner's angle ``theta`` (the first turn
from the spawn's heading onto the first leg), before it moves on; no step crosses a corner. A cell is
blocked at a step when the robot's centre there is closer than ``robot.inflation + person radius +
margin`` to any person's centre, with ``margin = MARGIN + TRACKING + w DT / 2`` and ``w`` the robot's top
speed plus the fastest any person walks: two positions that far apart at both ends of a step cannot
come closer than ``inflation + radius + MARGIN + TRACKING`` in between, each moving straight at
constant speed; :data:`TRACKING` is what a follower may lag or lead the schedule by (the shipped
:class:`~worldgen.envs.policies.TimedFollower`'s measured error, docs/people.md). A forward sweep over
the steps keeps the set of states (cell and speed, or corner and turn done) the robot can be in; the
first step it can stand at the goal is the arrival time, and the schedule is read back from the stored
sets.

The arrival time is optimal only among such schedules along this one static path at this resolution,
forward only; another route round the people, a finer grid or backing up could arrive earlier. It is
an upper bound on the earliest arrival, and the timed path a checkable witness (world.json's
``tasks[].timed_path``), not the optimum.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace
from typing import Optional, Sequence

import numpy as np

from worldgen.feasibility.report import Check, FeasibilityReport
from worldgen.people.behaviours import Tube, tube_of
from worldgen.people.blocked import free_cells, steps_within
from worldgen.people.corners import arc_clear, cap_moves, passed_moving

# The default turn rate (rad/s) and acceleration (m/s^2) of a small differential-drive base have one home,
# the parameters robot_turn_rate and robot_acceleration, read in worldgen.scene.robot (docs/people.md).
from worldgen.scene.robot import ACCELERATION, TURN_RATE

__all__ = ["DT", "MARGIN", "TRACKING", "SPARE", "TURN_RATE", "ACCELERATION", "MAX_LEVELS", "Limits", "limits_of",
           "TimedPath", "timed_path", "person_speed", "certify", "agents_of", "timed_check", "tube_steps", "turn_angles"]

#: Time step (s) of the sweep, and the shortest time between two rows of a timed path.
DT = 0.05
#: Distance (m) kept beyond contact at every instant, over and above the sampling bound.
MARGIN = 0.01
#: Distance (m) a follower may be off its schedule, kept beyond MARGIN: three times the shipped
#: TimedFollower's largest measured tracking error in the environment at its defaults (0.0099 m over 42
#: episodes, docs/people.md), and above tests/support/unicycle.py's (0.018 m on the presets).
TRACKING = 0.03
#: Share of the top speed and of the acceleration the cells leave spare, for the rounding of the rows.
SPARE = 1e-3
#: Most speed levels a step may have: beyond, the cells keep the acceleration and the top speed is not used.
MAX_LEVELS = 40
#: Time (s) the sweep goes on after the last person stops, beyond the time the path takes.
AFTER = 5.0
#: Steps whose free cells are worked out at once (6.4 s): the sweep rarely needs all of them.
FREE_CHUNK = 128


@dataclass(frozen=True)
class Limits:
    """What the robot can do: ``max_speed`` (m/s), ``turn_rate`` (rad/s, on the spot), ``acceleration``
    (m/s^2, speeding up and slowing down alike)."""

    max_speed: float
    turn_rate: float = TURN_RATE
    acceleration: float = ACCELERATION


def limits_of(params) -> Limits:
    """The robot's limits a world's resolved ``params`` state (the defaults where they are not recorded)."""
    return Limits(float(params["robot_speed"]), float(params.get("robot_turn_rate", TURN_RATE)),
                  float(params.get("robot_acceleration", ACCELERATION)))


@dataclass(frozen=True, eq=False)
class TimedPath:
    """``rows`` (k, 3) of t, x, y (t from 0, strictly increasing; straight between rows at constant
    speed); ``arrival`` the last row's time (s)."""

    rows: np.ndarray
    arrival: float


def person_speed(tracks: Sequence[np.ndarray]) -> float:
    """The fastest any person walks between two rows of its (k, 3) ``t, x, y`` track, m/s."""
    best = 0.0
    for traj in tracks:
        d = np.diff(traj, axis=0)
        if len(d):
            best = max(best, float(np.max(np.hypot(d[:, 1], d[:, 2]) / d[:, 0])))
    return best


def turn_angles(waypoints: np.ndarray, heading: float) -> np.ndarray:
    """(k - 1,) the angle (rad, 0 to pi) the robot turns on the spot at each waypoint but the goal: at the
    spawn from ``heading`` onto the first leg, at each corner from one leg onto the next."""
    d = np.diff(np.asarray(waypoints, dtype=float).reshape(-1, 2), axis=0)
    yaw = np.arctan2(d[:, 1], d[:, 0])
    before = np.concatenate([[heading], yaw[:-1]])
    return np.abs((yaw - before + math.pi) % (2 * math.pi) - math.pi)


# long: the sweep and its read-back share every array; apart they would pass a dozen of them around
def timed_path(waypoints: np.ndarray, tracks: Sequence[np.ndarray], radii: Sequence[float], inflation: float,
               limits, tubes: Optional[Sequence[Tube]] = None, heading: Optional[float] = None,
               tracking: float = TRACKING, loops: Optional[Sequence[bool]] = None,
               clear=None) -> Optional[TimedPath]:
    """The earliest timed path along ``waypoints`` (k, 2) within ``limits`` (a :class:`Limits`, or a top
    speed with the default turn rate and acceleration) that keeps the robot's disc (``inflation``) and
    every agent's (its (m, 3) track and radius) apart, or None. The robot starts at rest facing
    ``heading`` (rad; default: along the first leg).

    ``loops`` (one per track, default none): a looping track (a scripted mover's) repeats for ever; the
    others stand at their last row. The sweep gives the robot until the last person stops or the slowest
    loop has come round once, then the time the path takes and :data:`AFTER`; no schedule by then is None.

    ``tubes`` (one per person, default the recorded line): the robot keeps clear of the whole tube, every
    recorded position from ``t - tau`` to ``t + tau`` widened by ``d`` (:func:`worldgen.people.blocked.free_cells`).

    ``clear`` (a function of a corner's arc and the corner, True where the robot's disc along the arc keeps
    its clearance from the static geometry, :func:`worldgen.people.corners.arc_clear`): with it, small corners
    whose arc is clear are passed on the move; without it every corner is turned on the spot."""
    lim = limits if isinstance(limits, Limits) else Limits(float(limits))
    w = np.asarray(waypoints, dtype=float).reshape(-1, 2)
    if len(w) == 1:
        w = np.vstack([w, w])
    levels = min(MAX_LEVELS, max(1, math.ceil(lim.max_speed / (lim.acceleration * DT) - 1e-9)))
    ds = min(lim.max_speed * DT / levels, lim.acceleration * DT * DT) * (1 - SPARE)
    s, corner = _cells(w, ds)
    cum = np.concatenate([[0.0], np.cumsum(np.hypot(*np.diff(w, axis=0).T))])
    length = float(cum[-1])
    n_cells = len(s) - 1
    angles = turn_angles(w, math.atan2(*(w[1] - w[0])[::-1]) if heading is None else heading)
    turns = np.ceil(angles / (lim.turn_rate * DT) - 1e-9).astype(np.int64)
    turns[np.hypot(*np.diff(w, axis=0).T) == 0] = 0  # a leg of no length has no heading to turn to
    leg_ds = np.diff(s[corner]) / np.diff(corner)  # each leg's cell length (m)
    passed = passed_moving(w, lim.max_speed, lim.turn_rate, leg_ds, clear, DT)  # corners passed on the move
    turns[list(passed)] = 0
    spot = corner[:-1][turns > 0]  # the cells the robot stands on to turn, and for how many steps
    spot_steps = turns[turns > 0]
    passes, ok, extra = _moves(s, corner, leg_ds, cum, turns, levels, ds, passed)
    loops = [False] * len(tracks) if loops is None else [bool(x) for x in loops]
    end = max((float(t[-1, 0]) for t in tracks), default=0.0)
    # Beyond the drive at full speed: the stands to turn, and slowing to a stop and speeding up again at
    # every corner (V steps each way at most).
    steps = math.ceil((end + length / lim.max_speed + float(spot_steps.sum()) * DT + AFTER) / DT) + levels * len(corner)
    times = np.arange(steps + 1) * DT
    reach, window = _reaches(tracks, radii, tubes, inflation + MARGIN + tracking, lim.max_speed)
    span = int(spot_steps.max(initial=1))
    live = np.arange(span)[None, :] < spot_steps[:, None]
    # From this time on every person stands and every step's free cells are the last step's: a step whose
    # states are the step's before then has them for ever, and the goal is out of reach. A looping mover
    # never stands: with one, the sweep runs to its end.
    settled = math.inf if any(loops) else end + (int(window.max(initial=0)) + 1) * DT
    free = np.zeros((0, n_cells + 1), dtype=bool)
    # Per step: the (speed, cell) states, bit-packed (a long path holds some 10^4 cells at 11 speeds for
    # 10^3 steps), and the (spot, steps turned) states; ``cell`` is the last step's, unpacked.
    moving: list[np.ndarray] = []
    turning: list[np.ndarray] = []
    k_goal = None
    ok_t = np.ascontiguousarray(ok.T)  # the sweep works speed by speed: each speed's cells in a row
    cell = np.zeros((levels + 1, n_cells + 1), dtype=bool)
    for k in range(steps + 1):
        if k == len(free):
            free = np.concatenate([free, free_cells(w, cum, s, tracks, reach, times[k:k + FREE_CHUNK], DT, window,
                                                         loops, extra if passed else None)])
        here = free[k]
        prev, cell = cell, np.zeros((levels + 1, n_cells + 1), dtype=bool)
        turn = np.zeros((len(spot), span), dtype=bool)
        if k == 0:
            if len(spot) and spot[0] == 0:
                turn[0, 0] = here[0]
            else:
                cell[0, 0] = here[0]
        else:
            cell, turn = _advance(prev, turning[-1], here, passes, ok_t, live, spot, spot_steps)
            if times[k] > settled and np.array_equal(cell, prev) and np.array_equal(turn, turning[-1]):
                return None
        moving.append(np.packbits(cell))
        turning.append(turn)
        if cell[:2, n_cells].any():
            k_goal = k
            break
        if not (cell.any() or turn.any()):
            return None
    if k_goal is None:
        return None
    def states(step: int) -> np.ndarray:
        """(cell, speed) bool: the states of ``step``, unpacked one step at a time."""
        return np.unpackbits(moving[step], count=(levels + 1) * (n_cells + 1)).reshape(levels + 1, -1).T.astype(bool)

    cells = _read_back(states, len(moving), turning, spot, spot_steps, ok, passes, n_cells, levels)
    return TimedPath(_rows(w, cum, times[: k_goal + 1], s[np.array(cells)], s[corner]), k_goal * DT)


def _reaches(tracks, radii, tubes, keep: float, top: float) -> tuple[np.ndarray, np.ndarray]:
    """(how near each agent's recorded centre a cell is blocked (m), the steps either side of a step its tube
    spans): its radius, ``keep`` (the robot's inflation, MARGIN and the tracking margin), its tube's ``d``,
    and what the robot at ``top`` m/s and the fastest agent close between two steps."""
    tubes = list(tubes) if tubes is not None else [Tube(0.0, 0.0)] * len(tracks)
    reach = (np.asarray(radii, dtype=float) + keep + (top + person_speed(tracks)) * DT / 2
             + np.array([tube.d for tube in tubes], dtype=float).reshape(len(tracks)))
    window = np.array([tube_steps(tube.tau) for tube in tubes], dtype=np.int64).reshape(len(tracks))
    return reach, window


def _moves(s: np.ndarray, corner: np.ndarray, leg_ds: np.ndarray, cum: np.ndarray, turns: np.ndarray, levels: int,
           ds: float, passed: dict) -> tuple[dict, np.ndarray, np.ndarray]:
    """(the speeds that may follow one another through each corner passed without a stop, ``ok`` (cell,
    cells a step): the moves allowed, the more reach on each leg (m) beside a corner passed moving)."""
    n_cells = len(s) - 1
    # A corner passed without a turn joins legs of slightly different cells: which speed (in cells a step)
    # may follow which there, for the change in m/s to stay within one cell a step of the finest legs.
    lv = np.arange(levels + 1)
    passes = {int(corner[j]): np.abs(lv[None, :] * leg_ds[j] - lv[:, None] * leg_ds[j - 1]) <= ds * (1 + 1e-9)
              for j in range(1, len(corner) - 1) if turns[j] == 0}
    # A move of u cells from cell c may not cross a corner: c + u <= the first corner after c.
    nxt = np.append(corner, n_cells)[np.searchsorted(corner, np.arange(n_cells + 1), side="right")]
    ok = np.arange(n_cells + 1)[:, None] + np.arange(levels + 1)[None, :] <= nxt[:, None]
    extra = np.zeros(len(corner) - 1)
    for j, (cut, dev) in passed.items():
        extra[j - 1:j + 1] = np.maximum(extra[j - 1:j + 1], dev)  # the largest arc's, as worldgen check keeps it
        cap_moves(ok, s, corner, leg_ds, float(cum[j]), cut, DT)
    return passes, ok, extra


def _advance(prev: np.ndarray, was: np.ndarray, here: np.ndarray, passes: dict, ok_t: np.ndarray, live: np.ndarray,
             spot: np.ndarray, spot_steps: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """One step of the sweep: from the last step's (speed, cell) states ``prev`` and (spot, steps turned)
    states ``was`` to this step's, kept where the cells are ``here`` (free at this step's time)."""
    levels, n_cells = prev.shape[0] - 1, prev.shape[1] - 1
    cell = np.zeros_like(prev)
    turn = np.zeros_like(was)
    near = prev.copy()  # the speeds one level or less away from each next speed
    near[1:] |= prev[:-1]
    near[:-1] |= prev[1:]
    for c, fits in passes.items():
        near[:, c] = (prev[:, c][:, None] & fits).any(axis=0)
    near &= ok_t
    for u in range(levels + 1):
        cell[u, u:] = near[u, :n_cells + 1 - u]
    turn[:, 1:] = was[:, :-1] & live[:, 1:]
    turn[:, 0] = cell[1, spot]  # come to a corner at one cell a step, and stop there to turn
    cell[1:, spot] = False
    cell[0, spot] |= was[np.arange(len(spot)), spot_steps - 1]
    cell &= here[None, :]
    turn &= here[spot][:, None]
    return cell, turn


def _read_back(states, n_steps: int, turning, spot, spot_steps, ok, passes, goal: int, levels: int) -> list[int]:
    """The cell of every step, from 0 to the arrival, of one schedule the sweep's stored sets allow: from
    the goal back, each step's predecessor the first the sets hold (standing before moving, slower first)."""
    k = n_steps - 1
    state = ("cell", goal, int(np.flatnonzero(states(k)[goal, :2])[0]))
    cells = [goal]
    where = {int(c): j for j, c in enumerate(spot)}
    while k > 0:
        prev, was = states(k - 1), turning[k - 1]
        if state[0] == "turn":
            j, m = state[1], state[2]
            if m > 0:
                state = ("turn", j, m - 1)
            else:
                c = int(spot[j]) - 1
                u = next(u for u in range(0, min(2, levels) + 1) if prev[c, u] and ok[c, 1])
                state = ("cell", c, u)
        else:
            c, u = state[1], state[2]
            at = where.get(c)
            if at is not None and u == 0 and was[at, spot_steps[at] - 1]:
                state = ("turn", at, int(spot_steps[at]) - 1)
            else:
                src = c - u
                fits = passes.get(src)
                before = range(levels + 1) if fits is not None else range(max(0, u - 1), min(levels, u + 1) + 1)
                u0 = next(v for v in before if prev[src, v] and ok[src, u] and (fits is None or fits[v, u]))
                state = ("cell", src, u0)
        cells.append(int(spot[state[1]]) if state[0] == "turn" else state[1])
        k -= 1
    return cells[::-1]


def _cells(w: np.ndarray, ds: float) -> tuple[np.ndarray, np.ndarray]:
    """(arc length of every cell (m,), the cell index of every corner, spawn and goal included): each leg
    cut into equal cells no longer than ``ds``."""
    seg = np.hypot(*np.diff(w, axis=0).T)
    cum = np.concatenate([[0.0], np.cumsum(seg)])
    parts = [np.zeros(1)]
    corner = [0]
    for q, length in enumerate(seg):
        n = max(1, math.ceil(length / ds - 1e-9))
        parts.append(cum[q] + np.arange(1, n + 1) * (length / n))
        parts[-1][-1] = cum[q + 1]
        corner.append(corner[-1] + n)
    return np.concatenate(parts), np.array(corner)


def certify(report: FeasibilityReport, scene, tasks, robot, limits,
            behaviours: Optional[Sequence[str]] = None) -> FeasibilityReport:
    """``report`` with the check ``timed_path`` and each task's certificate among everything of the scene
    that moves (its people and its scripted movers, one kind of agent: each a disc on a known schedule,
    a mover's repeating), within ``limits`` (a :class:`Limits`, or a top speed with the default turn rate
    and acceleration), each from its spawn's heading. ``behaviours`` (one per person, in order) give the
    reacting people their tubes; a scripted mover is impassive.

    A task without a static path has no certificate either; the check fails then, and where the
    agents leave the robot no way through along its path.
    """
    lim = limits if isinstance(limits, Limits) else Limits(float(limits))
    agents, tracks, radii, loops, tubes = agents_of(scene, behaviours)
    clear = arc_clear(scene, robot)
    found, missing = [], []
    for task, path in zip(tasks, report.paths):
        timed = None if path is None else timed_path(path.waypoints, tracks, radii, robot.inflation, lim, tubes,
                                                     heading=float(task.spawn.yaw), loops=loops, clear=clear)
        found.append(timed)
        if timed is None:
            why = "no static path" if path is None else f"they leave no way through at <= {lim.max_speed:g} m/s"
            missing.append(f"{task.id}: {why}")
    return replace(report, checks=report.checks + (timed_check(agents, found, missing),), timed_paths=tuple(found))


def agents_of(scene, behaviours: Optional[Sequence[str]] = None) -> tuple[list, list, list, list, list]:
    """Everything of ``scene`` that moves, as a certificate takes it: (agents, (m, 3) tracks, radii, whether each
    loops (a mover's script; a person stands at its end), tubes (from ``behaviours``, one a person, in order))."""
    agents = list(scene.movers)
    reacting = iter(tube_of(b) for b in behaviours) if behaviours is not None else None
    return (agents, [np.asarray(m.trajectory, dtype=float) for m in agents], [m.radius for m in agents],
            [m.loop and not m.person for m in agents],
            [next(reacting) if reacting is not None and m.person else Tube(0.0, 0.0) for m in agents])


def timed_check(agents, found: Sequence[Optional[TimedPath]], missing: Sequence[str], off: Optional[int] = None) -> Check:
    """The ``timed_path`` check of the certificates ``found`` among ``agents``: failed with the tasks ``missing``
    one (each "id: why"), else passed at the latest arrival (``off``: how many are off the static path)."""
    people, movers = sum(1 for m in agents if m.person), sum(1 for m in agents if not m.person)
    parts = [f"{people} people"] * bool(people) + [f"{movers} mover{'s' * (movers != 1)}"] * bool(movers)
    among = " and ".join(parts) or "0 people"  # '3 people', '2 movers', '3 people and 2 movers'
    if missing:
        return Check("timed_path", False, None, f"no timed path among the {among} for " + "; ".join(missing))
    latest = max(t.arrival for t in found if t is not None)  # none missing: all found
    moved = "" if off is None else f" ({off} off the static path)"
    return Check("timed_path", True, latest, f"{len(found)} timed path(s) among {among}{moved}, latest arrival "
                 f"{latest:.2f} s")


def _at(w: np.ndarray, cum: np.ndarray, s: np.ndarray) -> np.ndarray:
    """(m, 2) the points at arc lengths ``s`` along the polyline."""
    return np.column_stack([np.interp(s, cum, w[:, 0]), np.interp(s, cum, w[:, 1])])


def tube_steps(tau: float) -> int:
    """Steps either side of a step whose recorded positions its tube of ``tau`` s must keep clear of
    (:func:`worldgen.people.blocked.steps_within` at :data:`DT`)."""
    return steps_within(tau, DT)


def _rows(w: np.ndarray, cum: np.ndarray, times: np.ndarray, profile: np.ndarray, corners: np.ndarray) -> np.ndarray:
    """(k, 3) t, x, y rows of the profile's samples (every corner is one: corners are passed at a
    step's end), less those a straight constant-speed leg between their neighbours already says. A row
    passing through a corner (arc lengths ``corners``) is always kept: a collinear one passed at one speed
    would otherwise go, leaving two rows on different legs, which ``worldgen check`` reads as a cut corner."""
    pts = _at(w, cum, profile)
    rows = np.column_stack([times, pts])
    vel = np.diff(pts, axis=0) / np.diff(times)[:, None]
    mid = profile[1:-1]
    through = np.isin(mid, corners) & (profile[:-2] != mid) & (profile[2:] != mid)
    same = np.all(np.abs(vel[1:] - vel[:-1]) < 1e-9, axis=1) & ~through
    keep = np.r_[True, ~same, True]
    return rows[keep]
