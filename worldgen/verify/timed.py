"""``worldgen check``'s ``timed`` check: a world's certificate among people and movers, re-proved from world.json.

The timed path (``tasks[].timed_path``, docs/people.md) is checked on its own terms, without the code
that found it (:mod:`worldgen.people.timed`): rows from the spawn at t = 0 to the goal at
``arrival_time``, times increasing, no faster than ``robot.max_speed``; the rows' polyline clear of the
static geometry by FCL (the regenerated scene, doors at their open limit, as the path was proven), whether
it keeps to the recorded path (``tasks[].path.waypoints``) or steps off it (a certificate off the path,
docs/people.md): the polyline is what the robot drives, and what is proven; and, sampled every
:data:`TIMED_STEP` s, every person's ``trajectory`` (straight between rows, standing after the last) and
every mover's (``dynamic_obstacles[]``: the same, repeating from its first row after its last where
``loop``) never closer than ``robot.radius + robot.clearance + radius`` plus ``w TIMED_STEP / 2``, ``w`` the
robot's top speed plus the fastest any person or mover walks: what two discs moving straight at those speeds
could close between two samples.

A person who reacts to the robot (``people[].behaviour``) may be anywhere in its ``tube``: within ``d``
of a position its trajectory has at a time within ``tau`` of now. Against such a person each sample
at t is checked against the exact distance to the trajectory's part from ``t - tau - h / 2`` to
``t + tau + h / 2`` (``h`` = :data:`TIMED_STEP`; every instant is within ``h / 2`` of a sample),
which must be at least ``robot.radius + robot.clearance + radius + d`` plus ``robot.max_speed h / 2``
(how far the robot moves in half a step). The tube itself must be its behaviour's
(:data:`worldgen.people.behaviours.TUBES`): a widened or narrowed tube fails.

Where world.json states the robot's limits (``robot.max_turn_rate``, ``robot.max_acceleration``,
``robot.tracking_margin``: worlds written since the limits exist) the rows must also be a schedule such a
robot drives: from one row interval to the next the speed changes by at most ``max_acceleration`` times
the shorter interval (at rest before t = 0 and after the goal); wherever the direction of travel turns
by an angle (at the spawn from the spawn's yaw) the robot stands at least that angle over
``max_turn_rate`` in between (:data:`TURN_SLACK` rad forgiven for the rounding of the rows); and every
distance above is kept with ``tracking_margin`` more. A turn of at most ``CUT_ANGLE`` at a waypoint of the
recorded path the rows pass through, coming along one of its legs and leaving along the next, needs no stand
where it is a corner passed moving (docs/people.md): the arc tangent to both legs is re-derived here from the
recorded path and limits (or one of its ``SHRINK`` shares), the arc must keep the clearance by FCL (along its
inscribed chords, with its bulge beyond them), the rows within its reach of the waypoint must be no faster
than its radius times ``max_turn_rate``, and while the schedule is within that reach every person is kept the
largest arc's deviation farther.
"""

from __future__ import annotations

import numpy as np

from worldgen.errors import EXIT_FAILED, WorldgenError

__all__ = ["TIMED_STEP", "ON_PATH", "TURN_SLACK", "TimedPathError", "check_timed"]

#: Time step (s) at which a timed path is sampled against every person (docs/people.md: 2 ms).
TIMED_STEP = 0.002
#: How far (m) a timed path's row may lie off the recorded path: world.json's rows are rounded to 6 decimals.
ON_PATH = 1e-5
#: Angle (rad) a turn may be short of its standing time: a 6-decimal row on a 2.5 mm step tilts it ~4e-4 rad.
TURN_SLACK = 1e-3


class TimedPathError(WorldgenError):
    """A timed path that does not hold: the message is the one line ``worldgen check`` prints. The world a user
    received fails its check, which is no usage mistake: the command's exit status is that of a failed check."""

    exit_status = EXIT_FAILED


# long: one pass over the tasks, each checked on every count in turn against the same agents and geometry
def check_timed(meta: dict, world) -> None:
    """Re-prove every task's timed path of world.json ``meta`` (``world``: its regenerated World, for the
    static geometry); raise :class:`TimedPathError` with one line at the first fault."""
    people = meta.get("people") or []
    movers = meta.get("dynamic_obstacles") or []
    if not (people or movers):
        return
    robot = meta["robot"]
    if "max_speed" not in robot:
        raise TimedPathError("the world has people or movers but robot.max_speed is missing: its timed paths "
                             "have no speed to be checked against")
    inflation, v_max = robot["radius"] + robot["clearance"], float(robot["max_speed"])
    inflation += float(robot.get("tracking_margin", 0.0))
    tracks = [(str(p["name"]), np.asarray(p["trajectory"], dtype=float).reshape(-1, 3), float(p["radius"]))
              for p in people + movers]
    loops = [False] * len(people) + [bool(m.get("loop", False)) for m in movers]
    tubes = [_tube(p) for p in people] + [None] * len(movers)
    fastest = max((_speeds(track).max(initial=0.0) for _, track, _ in tracks), default=0.0)
    colliders = None
    for task in meta["tasks"]:
        rows = task.get("timed_path")
        if rows is None:
            if meta["feasibility"]["feasible"] and task.get("path") is not None:
                raise TimedPathError(f"{task['id']} has no timed_path, but the world is recorded feasible among "
                                     "its people and movers")
            continue
        if task.get("path") is None:
            raise TimedPathError(f"{task['id']} has a timed_path but no path for it to follow")
        rows = np.asarray(rows, dtype=float).reshape(-1, 3)
        _timed_rows(task, rows, v_max)
        if colliders is None:
            from worldgen.feasibility.collision import Colliders
            from worldgen.scene.doors import open_scene

            colliders = Colliders(open_scene(world.scene))
        from worldgen.feasibility.verify import verify_path

        nearest = verify_path(colliders, world.robot, rows[:, 1:])
        if nearest.distance < world.robot.clearance - 1e-6:
            raise TimedPathError(f"{task['id']} timed_path comes {nearest.distance:.6f} m from {nearest.name}, "
                                 f"under the clearance {world.robot.clearance} m")
        limited = "max_turn_rate" in robot or "max_acceleration" in robot
        moving = _moving(task, rows, robot, colliders, world.robot) if limited else []
        # Between two samples a robot and a person, each straight at constant speed, close at most w h / 2.
        reach = (v_max + fastest) * TIMED_STEP / 2
        t = np.arange(0.0, rows[-1, 0] + TIMED_STEP, TIMED_STEP)
        me = _at(rows, t)
        cut = _cut_near(me, t, rows, moving)  # how far the robot may be off the schedule at each sample
        for (name, track, radius), tube, loop in zip(tracks, tubes, loops):
            if tube is not None:
                _check_tube(task["id"], name, me, t, track, inflation + radius + cut, tube, v_max)
                continue
            gap = np.hypot(*(me - _at(track, _looped(track, t) if loop else t)).T) - (inflation + radius + cut)
            k = int(np.argmin(gap))
            if gap[k] < reach:
                raise TimedPathError(f"{task['id']} timed_path at t = {t[k]:.3f} s comes "
                                     f"{gap[k] + radius + inflation + cut[k]:.4f} m from {name}'s centre, under "
                                     "robot.radius + robot.clearance (+ robot.tracking_margin) + its radius = "
                                     f"{inflation + radius + cut[k]:.4f} m (+ {reach:.4f} m between {TIMED_STEP:g} s samples)")
        if limited:
            _drivable(task, rows, float(robot["max_turn_rate"]), float(robot["max_acceleration"]),
                      {corner for corner, _, _ in moving})


def _tube(person: dict):
    """(d, tau) of a reacting person's tube, checked against its behaviour's; None for an impassive one."""
    from worldgen.people.behaviours import TUBES

    name, behaviour, tube = person["name"], person.get("behaviour"), person.get("tube")
    if behaviour is None and tube is None:
        return None
    if behaviour not in TUBES or tube is None:
        raise TimedPathError(f"{name} has behaviour {behaviour!r} and tube {tube!r}: a reacting person needs both, "
                             f"behaviour one of {', '.join(sorted(TUBES))}")
    want = TUBES[behaviour]
    if float(tube["d"]) != want.d or float(tube["tau"]) != want.tau:
        raise TimedPathError(f"{name}'s tube d = {tube['d']} m, tau = {tube['tau']} s is not its behaviour "
                             f"{behaviour}'s (d = {want.d} m, tau = {want.tau} s)")
    return float(tube["d"]), float(tube["tau"])


def _check_tube(task_id: str, name: str, me: np.ndarray, t: np.ndarray, track: np.ndarray, contact,
                tube: tuple, v_max: float) -> None:
    """Every sample of the robot at ``me`` (times ``t``) far enough from the person's whole tube (``contact``:
    the distance to keep, one for all samples or one each)."""
    from worldgen.people.behaviours import tube_distance

    d, tau = tube
    reach = v_max * TIMED_STEP / 2
    contact = np.broadcast_to(np.asarray(contact, dtype=float), t.shape)
    gap = tube_distance(me, t, track, tau + TIMED_STEP / 2) - (contact + d)
    k = int(np.argmin(gap))
    if gap[k] < reach:
        raise TimedPathError(f"{task_id} timed_path at t = {t[k]:.3f} s comes {gap[k] + contact[k]:.4f} m from "
                             f"{name}'s recorded positions within {tau:g} s of then, under robot.radius + "
                             f"robot.clearance (+ robot.tracking_margin) + its radius + its tube's d = "
                             f"{contact[k] + d:.4f} m (+ {reach:.4f} m between {TIMED_STEP:g} s samples)")


def _speeds(rows: np.ndarray) -> np.ndarray:
    d = np.diff(rows, axis=0)
    with np.errstate(divide="ignore"):  # rows not after the one before: an infinite speed, never a pass
        return np.where(d[:, 0] > 0, np.hypot(d[:, 1], d[:, 2]) / np.where(d[:, 0] > 0, d[:, 0], 1.0), np.inf)


def _looped(track: np.ndarray, t: np.ndarray) -> np.ndarray:
    """The times ``t`` within one pass of a looping script: its period is its last row's time."""
    period = float(track[-1, 0])
    return np.mod(t, period) if period > 0 else t


def _at(rows: np.ndarray, t: np.ndarray) -> np.ndarray:
    """(len(t), 2) positions along ``rows`` (t, x, y): straight between rows, standing before and after."""
    return np.column_stack([np.interp(t, rows[:, 0], rows[:, 1]), np.interp(t, rows[:, 0], rows[:, 2])])


def _timed_rows(task: dict, rows: np.ndarray, v_max: float) -> None:
    """From the spawn at t = 0 to the goal at arrival_time, times increasing, at most robot.max_speed."""
    tid = task["id"]
    if len(rows) < 1 or not np.all(np.isfinite(rows)):
        raise TimedPathError(f"{tid} timed_path needs finite [t, x, y] rows")
    if rows[0, 0] != 0.0 or np.hypot(*(rows[0, 1:] - task["spawn"][:2])) > ON_PATH:
        raise TimedPathError(f"{tid} timed_path starts at t = {rows[0, 0]:g} s at {rows[0, 1:].tolist()}, "
                             f"not at t = 0 at the spawn {task['spawn'][:2]}")
    if np.hypot(*(rows[-1, 1:] - task["goal"][:2])) > ON_PATH or rows[-1, 0] != task.get("arrival_time"):
        raise TimedPathError(f"{tid} timed_path ends at t = {rows[-1, 0]:g} s at {rows[-1, 1:].tolist()}, not at "
                             f"arrival_time {task.get('arrival_time')} s at the goal {task['goal'][:2]}")
    dt = np.diff(rows[:, 0])
    if np.any(dt <= 0):
        k = int(np.argmax(dt <= 0)) + 1
        raise TimedPathError(f"{tid} timed_path row {k} (t = {rows[k, 0]:g} s) does not come after the one before")
    speed = _speeds(rows)
    if len(speed) and speed.max() > v_max:
        k = int(np.argmax(speed))
        raise TimedPathError(f"{tid} timed_path goes {speed[k]:.6f} m/s from t = {rows[k, 0]:g} to {rows[k + 1, 0]:g} s, "
                             f"above robot.max_speed {v_max:g} m/s")


def _drivable(task: dict, rows: np.ndarray, turn_rate: float, acceleration: float, moving=frozenset()) -> None:
    """Speed changes within ``acceleration``; a stand of at least angle / ``turn_rate`` wherever the way turns,
    but at the rows of ``moving`` (indices: corners passed on the move, already checked by :func:`_moving`)."""
    tid = task["id"]
    dt = np.diff(rows[:, 0])
    step = np.diff(rows[:, 1:], axis=0)
    speed = np.hypot(*step.T) / dt
    # At rest before the first row and after the last: an interval without end on either side.
    v = np.concatenate([[0.0], speed, [0.0]])
    span = np.concatenate([[np.inf], dt, [np.inf]])
    # The rows are rounded to 6 decimals: a speed over an interval dt may be off by 1e-6 / dt either way.
    slack = 2e-6 / np.minimum(span[:-1], span[1:])
    over = np.abs(np.diff(v)) - acceleration * np.minimum(span[:-1], span[1:]) - slack
    if len(over) and over.max() > 0:
        k = int(np.argmax(over))
        at = rows[min(k, len(rows) - 1), 0]
        raise TimedPathError(f"{tid} timed_path changes speed from {v[k]:.6f} to {v[k + 1]:.6f} m/s at t = {at:g} s, "
                             f"faster than robot.max_acceleration {acceleration:g} m/s^2")
    heading, stood = float(task["spawn"][-1]), 0.0
    for k in range(len(dt)):
        if speed[k] * dt[k] <= 1e-6:  # standing (within the rounding)
            stood += dt[k]
            continue
        yaw = float(np.arctan2(step[k, 1], step[k, 0]))
        angle = abs((yaw - heading + np.pi) % (2 * np.pi) - np.pi)
        if angle - TURN_SLACK > stood * turn_rate and not (stood == 0.0 and k in moving):
            raise TimedPathError(f"{tid} timed_path turns {angle:.4f} rad at t = {rows[k, 0]:g} s after standing "
                                 f"{stood:g} s, faster than robot.max_turn_rate {turn_rate:g} rad/s")
        heading, stood = yaw, 0.0


def _moving(task: dict, rows: np.ndarray, robot: dict, colliders, body) -> list:
    """The corners the rows pass on the move, each (row index, waypoint, (reach, deviation)) of its largest
    arc (docs/people.md, "Corners passed moving"), re-derived from the recorded path: a turn of at most
    CUT_ANGLE at a waypoint the rows pass through without standing, some arc of SHRINK's that keeps the
    clearance (FCL along its inscribed chords, each keeping the arc's bulge beyond it more; ``body`` the
    robot) and whose rows within its reach of the waypoint are no faster than its radius times
    ``robot.max_turn_rate``. A turn there that fits no arc is left to :func:`_drivable`."""
    from worldgen.feasibility.verify import verify_path
    from worldgen.people.corners import CUT, CUT_ANGLE, SHRINK, arc_polyline

    wp = np.asarray(task["path"]["waypoints"], dtype=float).reshape(-1, 2)
    if len(wp) < 3:
        return []
    omega, top = float(robot["max_turn_rate"]), float(robot["max_speed"])
    d = np.diff(wp, axis=0)
    legs = np.hypot(d[:, 0], d[:, 1])
    yaw = np.arctan2(d[:, 1], d[:, 0])
    turn = np.zeros(len(wp))
    turn[1:-1] = np.abs((yaw[1:] - yaw[:-1] + np.pi) % (2 * np.pi) - np.pi)
    ok = (turn > 0) & (turn <= CUT_ANGLE)
    ok[1:-1] &= (legs[:-1] > 0) & (legs[1:] > 0)
    half = turn / 2
    with np.errstate(divide="ignore", invalid="ignore"):
        want = np.where(ok, np.minimum(top / omega, CUT / (1 / np.cos(half) - 1)) * np.tan(half), 0.0)
    speed = _speeds(rows)
    out = []
    for j in np.flatnonzero(want > 0):
        ell = min(want[j], legs[j - 1] * want[j] / (want[j - 1] + want[j]), legs[j] * want[j] / (want[j] + want[j + 1]))
        at = np.flatnonzero(np.hypot(*(rows[1:-1, 1:] - wp[j]).T) <= ON_PATH) + 1
        if not len(at) or np.hypot(*(rows[at[0] - 1, 1:] - wp[j])) <= ON_PATH:
            continue  # not passed through (it stands there, or never comes)
        k = int(at[0])
        if max(_seg_dist(rows[k - 1, 1:], wp[j - 1:j], wp[j:j + 1])[0],
               _seg_dist(rows[k + 1, 1:], wp[j:j + 1], wp[j + 1:j + 2])[0]) > ON_PATH:
            continue  # it comes or leaves off the path's legs there (a timed path off the path): no arc of the path's
        rho = ell / np.tan(half[j])
        for share in SHRINK:
            reach, cap = ell * share, rho * share * omega
            a, b = wp[j] - d[j - 1] / legs[j - 1] * reach, wp[j] + d[j] / legs[j] * reach
            near = _seg_dist(wp[j], rows[:-1, 1:], rows[1:, 1:]) <= reach
            points, bulge = arc_polyline(a, wp[j], b, rho * share)
            if np.all(speed[near] <= cap * (1 + 1e-6) + 2e-6 / np.diff(rows[:, 0])[near]) and \
                    verify_path(colliders, body, points).distance >= body.clearance + bulge - 1e-6:
                out.append((int(at[0]), wp[j], (float(ell), float(rho * (1 / np.cos(half[j]) - 1)))))
                break
    return out


def _seg_dist(p: np.ndarray, a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """(n,) the distance from point ``p`` to each segment ``a[i]``-``b[i]``."""
    ab = b - a
    u = np.clip(np.einsum("ij,ij->i", p - a, ab) / np.maximum(np.einsum("ij,ij->i", ab, ab), 1e-300), 0.0, 1.0)
    return np.hypot(*(a + u[:, None] * ab - p).T)


def _cut_near(me: np.ndarray, t: np.ndarray, rows: np.ndarray, moving: list) -> np.ndarray:
    """(len(me),) how far the robot may be off the schedule at each sample (times ``t``): the largest arc's
    deviation while the schedule, passing a corner on the move, is within its reach of it, else 0."""
    out = np.zeros(len(me))
    for k, corner, (reach, dev) in moving:
        inside = np.hypot(*(me - corner).T) <= reach + 1e-9
        # Only the pass itself: the samples within reach next to the corner's row, not a later return.
        mid = int(np.argmin(np.abs(t - rows[k, 0])))
        lo, hi = mid, mid
        while lo > 0 and inside[lo - 1]:
            lo -= 1
        while hi + 1 < len(t) and inside[hi + 1]:
            hi += 1
        out[lo:hi + 1] = np.maximum(out[lo:hi + 1], dev)
    return out
