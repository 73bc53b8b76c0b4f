"""Waypoints that make a Gazebo actor follow a timed polyline (world.json's rows) within a tolerance.

Gazebo (gz-common ``PoseAnimation``, used by Gazebo classic's and Gazebo Sim's actors) plays an actor's
``<trajectory>`` as a gz-math ``Spline``: key frame k at its waypoint's time, and between key frames k and
k + 1 the cubic Hermite segment from p_k to p_k+1, at fraction s = (t - t_k) / (t_k+1 - t_k). The tangent
at p_k is ``(1 - tension) x (p_k+1 - p_k-1) / 2``; at an open end it is half the end segment; when the
first and last points agree within 1 mm per coordinate (gz-math's ``Vector3 ==``) the spline is closed
and the end tangents wrap.

worldgen writes ``tension="0"`` (Catmull-Rom; also what a Gazebo that ignores the tension plays). Then
a segment whose displacement D_k equals its neighbours' is exactly the straight walk at constant speed;
otherwise the actor is off it by h10(s) e0 + h11(s) e1, e0 = (D_k-1 - D_k) / 2, e1 = (D_k+1 - D_k) / 2,
at most a quarter of the larger |e| (h10 - h11 = s - s^2). Time does not enter: only how the
displacements change. So the parts must change slowly along the walk: at a row where the direction
turns by du (a unit-vector change; 1 where it starts or stops) the parts next to it are about
C / du long, and away from it they grow by at most a share of C per part (a size field over the
distance walked, h^2 = h_r^2 + 2 g |sigma - sigma_r|, integrated in closed form). Every row is a
waypoint; the added ones lie on world.json's legs; a leg that stays in place gets none. Each result is
checked the way gz-common plays it (:func:`worst_deviation`); the rows of legs whose parts still stray
beyond the tolerance get a finer, slower-growing field and the legs are cut again, until none does.

Keeping the rows costs: a 0.1 s leg cut into n parts next to one cut into n + 1 changes the part by
L / (n (n + 1)), a jump Catmull-Rom only smooths when n >= 4 or so, so a walk that needs cutting
anywhere ends up with 3 to 4 waypoints a row (a straight walk from standing to standing too).
"""

from __future__ import annotations

import numpy as np

from worldgen.errors import WorldgenError

__all__ = ["TENSION", "WAYPOINT_TOLERANCE", "actor_waypoints", "spline_positions", "worst_deviation"]

#: The ``tension`` of every actor trajectory written: Catmull-Rom tangents.
TENSION = 0.0
#: The most (m) an actor may stray from world.json's walk; 0.1 mm under the 1 mm the formats promise to
#: agree within, for the 6-decimal rounding of times and poses and the sampled check below.
WAYPOINT_TOLERANCE = 0.9e-3
#: Displacement change (m) allowed between neighbouring parts, as a multiple of the tolerance: a
#: deviation is at most |e| / 4 = |dD| / 8, so 8 is the bound, tightened where the check says so.
_STEP = 8.0
#: Fractions of a part where the check plays the spline (the deviation is a cubic in s, smooth: 31
#: interior samples find its largest value within a fraction of a per cent).
_S = np.linspace(0.0, 1.0, 33)[1:-1]
_H10, _H11 = _S**3 - 2 * _S**2 + _S, _S**3 - _S**2
_ROUNDS = 40
#: The shortest part (s): ten times the 1 us that times are rounded to.
_TICK = 1e-5
#: How fast parts may grow away from a turn, as a share of the allowed displacement change per part.
_GROW = 0.75


def spline_positions(waypoints: np.ndarray, times: np.ndarray, loop: bool = False,
                     tension: float = TENSION) -> np.ndarray:
    """(len(times), 2): where gz-common puts an actor whose trajectory has ``waypoints`` ((k, 3) t, x, y)."""
    way = np.asarray(waypoints, dtype=float)
    p, key = way[:, 1:3], way[:, 0] - way[0, 0]
    times = np.asarray(times, dtype=float)
    if len(p) == 1:
        return np.repeat(p, len(times), axis=0)
    m = _tangents(p, tension)
    t = np.mod(times, key[-1]) if loop and key[-1] > 0 else np.clip(times, 0.0, key[-1])
    i = np.clip(np.searchsorted(key, t, side="right") - 1, 0, len(p) - 2)
    s = ((t - key[i]) / (key[i + 1] - key[i]))[:, None]
    return _hermite(p[i], p[i + 1], m[i], m[i + 1], s)


def worst_deviation(waypoints: np.ndarray, rows: np.ndarray) -> np.ndarray:
    """(k - 1,) the largest distance (m) on each waypoint part between the actor and world.json's walk
    (``rows``; every row is a waypoint). The spline minus the part's chord is h10 e0 + h11 e1 (the Hermite
    segment with both tangents equal to the chord is the chord), taken at :data:`_S`; the chord minus the
    walk is linear along the part, so at most the larger of its ends' rounding offsets."""
    way, rows = np.asarray(waypoints, dtype=float), np.asarray(rows, dtype=float)
    if len(way) < 2:
        return np.zeros(0)
    p = way[:, 1:3]
    m, chord = _tangents(p, TENSION), np.diff(p, axis=0)
    e0, e1 = m[:-1] - chord, m[1:] - chord
    bend = np.hypot(_H10[:, None] * e0[:, 0] + _H11[:, None] * e1[:, 0],
                    _H10[:, None] * e0[:, 1] + _H11[:, None] * e1[:, 1]).max(axis=0)
    off = np.hypot(np.interp(way[:, 0], rows[:, 0], rows[:, 1]) - p[:, 0],
                   np.interp(way[:, 0], rows[:, 0], rows[:, 2]) - p[:, 1])
    return bend + np.maximum(off[:-1], off[1:])


def actor_waypoints(trajectory, loop: bool = False, tolerance: float = WAYPOINT_TOLERANCE) -> np.ndarray:
    """(k, 3) ``t, x, y`` waypoints (6 decimals, deterministic) whose spline keeps within ``tolerance`` of
    the rows' straight walk at every time; ``loop``: the rows are a closed loop walked again and again."""
    rows = np.asarray(trajectory, dtype=float)
    length = np.hypot(*np.diff(rows[:, 1:], axis=0).T)
    if len(rows) < 2 or not length.any():
        return np.round(rows, 6)
    # Directions of the legs (0 for a stay), and at each row how much the direction changes: parts there
    # may be |dD| / |du| long. An open end is a change to or from standing still.
    u = np.diff(rows[:, 1:], axis=0) / np.where(length > 0, length, 1.0)[:, None]
    before = np.vstack([u[-1:] if loop else np.zeros((1, 2)), u])
    after = np.vstack([u, u[:1] if loop else np.zeros((1, 2))])
    turn = np.hypot(*(after - before).T)
    bound = _STEP * tolerance
    local = np.divide(bound, turn, out=np.full(len(rows), np.inf), where=turn > 1e-12)
    grow = np.full(len(length), _GROW * bound)
    sigma = np.concatenate([[0.0], np.cumsum(length)])
    for _ in range(_ROUNDS):
        way, capped = _cut(rows, sigma, _field(sigma, local, grow, loop), grow)
        bad = worst_deviation(way, rows) > tolerance
        if not bad.any():
            return way
        # The legs holding a straying part: shorter parts at their rows, growing more slowly.
        leg = np.unique(np.searchsorted(rows[:, 0], way[:-1, 0][bad], side="right") - 1)
        if capped[leg].any():
            break
        ends = np.unique(np.concatenate([leg, leg + 1]))
        local[ends] = np.minimum(local[ends], _field(sigma, local, grow, loop)[ends]) / 2
        grow[leg] /= 2
        if loop:
            local[0] = local[-1] = min(local[0], local[-1])
    raise WorldgenError(f"actor waypoints: no cut keeps within {tolerance} m of the walk near t = "
                        f"{rows[leg[0], 0]:g} s (legs too short in time for how sharply it turns)")


def _tangents(p: np.ndarray, tension: float) -> np.ndarray:
    scale = 1.0 - min(max(tension, 0.0), 1.0)
    m = np.empty_like(p)
    m[1:-1] = 0.5 * (p[2:] - p[:-2])
    if np.all(np.abs(p[0] - p[-1]) <= 1e-3):  # gz-math's Vector3 == : closed, the start wraps, the end copies it
        m[0] = m[-1] = 0.5 * (p[1] - p[-2])
    else:
        m[0], m[-1] = 0.5 * (p[1] - p[0]), 0.5 * (p[-1] - p[-2])
    return m * scale


def _hermite(p0, p1, m0, m1, s):
    s2, s3 = s * s, s * s * s
    return (2 * s3 - 3 * s2 + 1) * p0 + (s3 - 2 * s2 + s) * m0 + (3 * s2 - 2 * s3) * p1 + (s3 - s2) * m1


def _field(sigma: np.ndarray, local: np.ndarray, grow: np.ndarray, loop: bool) -> np.ndarray:
    """The part length wanted at each row: its own, or a neighbour's grown along the walk
    (h^2 + 2 g d composes, so one pass each way is the minimum over all rows; a loop goes round twice)."""
    n = len(sigma)
    h2 = np.square(np.minimum(local, 1e9))
    reach = 2 * grow * np.diff(sigma)  # what h^2 may grow by over each leg
    if loop:  # the loop's rows three times over, the middle copy taken
        h2 = np.concatenate([h2[:-1]] * 3 + [h2[-1:]])
        reach = np.tile(reach, 3)
    # min over j of h2_j + |R_i - R_j|, R the reach walked so far: a running minimum each way.
    walked = np.concatenate([[0.0], np.cumsum(reach)])
    h2 = np.minimum(walked + np.minimum.accumulate(h2 - walked),
                    np.minimum.accumulate((h2 + walked)[::-1])[::-1] - walked)
    out = np.sqrt(h2)
    return out[n - 1:2 * n - 1] if loop else out


def _cut(rows: np.ndarray, sigma: np.ndarray, h: np.ndarray, grow: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The rows plus, in each moving leg [a, b] (distances walked), the points that cut it into equal
    shares of the integral of d sigma / h, h = min(sqrt(h_a^2 + 2 g (sigma - a)), sqrt(h_b^2 + 2 g (b - sigma)));
    and which legs got fewer parts than that asked for (one per :data:`_TICK` at most)."""
    a, b, g = sigma[:-1], sigma[1:], grow
    ha, hb = np.minimum(h[:-1], 1e9), np.minimum(h[1:], 1e9)
    cross = np.clip((hb**2 - ha**2) / (4 * g) + (a + b) / 2, a, b)  # where the two branches meet
    left = (np.sqrt(ha**2 + 2 * g * (cross - a)) - ha) / g
    total = left + (np.sqrt(hb**2 + 2 * g * (b - cross)) - hb) / g
    # At most one part per _TICK of time, so that no two rounded times meet (and a hopeless leg stays finite).
    most = np.maximum(1, np.floor(np.diff(rows[:, 0]) / _TICK))
    wanted = np.where(b > a, np.maximum(1, np.ceil(total - 1e-9)), 1)
    parts = np.minimum(wanted, most).astype(np.int64)
    leg = np.repeat(np.arange(len(a)), parts)
    k = np.arange(parts.sum()) - np.repeat(np.cumsum(parts) - parts, parts)  # 0 .. parts - 1 in each leg
    phi, g, ha, hb = k * (total / parts)[leg], g[leg], ha[leg], hb[leg]
    at = np.where(phi <= left[leg], a[leg] + ((g * phi + ha) ** 2 - ha**2) / (2 * g),
                  b[leg] - ((g * (total[leg] - phi) + hb) ** 2 - hb**2) / (2 * g))
    share = np.where(k == 0, 0.0, np.clip((at - a[leg]) / np.where(b > a, b - a, 1.0)[leg], 0.0, 1.0))
    out = rows[leg] + share[:, None] * (rows[leg + 1] - rows[leg])
    out[k == 0] = rows[:-1]  # the rows themselves, exactly
    out = np.round(np.vstack([out, rows[-1:]]), 6)
    # Never two waypoints at one (rounded) time: an added point that would share one goes, a row stays.
    row = np.concatenate([k == 0, [True]])
    same = np.diff(out[:, 0]) <= 0
    return out[row | ~(np.concatenate([[False], same]) | np.concatenate([same, [False]]))], wanted > most
