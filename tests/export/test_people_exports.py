"""People in the three formats agree within 1 mm at any time: world.json's rows (walked straight between
rows, linearly in time), the SDF actors (as libsdformat reads them, played by a reference of gz-common's
actor interpolation) and the MJCF mocap bodies (stepped in MuJoCo, driven by drive_mocap).

Gazebo cannot run here, so the SDF side is a reference interpolator written from gz-common and gz-math:
``TrajectoryInfo::SetWaypoints`` makes one key frame per waypoint (times from the first) and a
``PoseAnimation`` with the trajectory's tension (clamped to [0, 1]); ``Animation::KeyFramesAtTime`` finds
the key frames k, k+1 around a time and the fraction s = (t - t_k) / (t_k+1 - t_k); the position is
``Spline::Interpolate(k, s)``, the cubic Hermite segment between the two points with tangents
``(1 - tension) x (p_k+1 - p_k-1) / 2`` (one-sided halves at the ends; a closed path, first point equal
to the last within 1 mm per coordinate as gz-math's ``Vector3 ==`` has it, wraps); a time past the end is
the end, or for a looping script (``Animation::Time``) the time modulo the script's length.
"""

from __future__ import annotations

import json
import math

import mujoco
import numpy as np
import pytest
from support.reftools_sdf import dump_sdf

import worldgen
from worldgen.errors import WorldgenError
from worldgen.export.actor_path import TENSION, WAYPOINT_TOLERANCE, actor_waypoints
from worldgen.export.sdf import HOLD_SECONDS
from worldgen.scene.motion import drive_mocap, positions_at

#: Agreement promised between the formats (m).
MM = 1e-3
PEOPLE = {"size": [8.0, 8.0], "n_obstacles": 8, "n_people": 4, "people_duration": 20.0}
#: Tension 1 (zero tangents) eases each segment: it lags or leads by at most sqrt(3) / 18 of the segment.
EASE = math.sqrt(3.0) / 18.0


def gz_actor_positions(waypoints: np.ndarray, tension: float, times: np.ndarray, loop: bool = False) -> np.ndarray:
    """(len(times), 3): where gz-common puts an actor whose script has ``waypoints`` ((k, 4) ``t, x, y, z``)."""
    times = np.asarray(times, dtype=float)
    key_t = waypoints[:, 0] - waypoints[0, 0]
    p = waypoints[:, 1:4]
    k = len(p)
    if k == 1:
        return np.repeat(p, len(times), axis=0)
    scale = 1.0 - min(max(tension, 0.0), 1.0)
    m = np.zeros_like(p)
    m[1:-1] = 0.5 * (p[2:] - p[:-2])
    if np.all(np.abs(p[0] - p[-1]) <= 1e-3):  # closed: the start's tangent wraps, the end takes it
        m[0] = m[-1] = 0.5 * (p[1] - p[-2])
    else:
        m[0], m[-1] = 0.5 * (p[1] - p[0]), 0.5 * (p[-1] - p[-2])
    m *= scale
    t = np.fmod(times, key_t[-1]) if loop else np.clip(times, 0.0, key_t[-1])
    # lower_bound, then back one unless the time is on a key frame: key frame i <= t < key frame i + 1.
    i = np.clip(np.searchsorted(key_t, t, side="right") - 1, 0, k - 2)
    s = (t - key_t[i]) / (key_t[i + 1] - key_t[i])
    s = s[:, None]
    h00, h10, h01, h11 = 2 * s**3 - 3 * s**2 + 1, s**3 - 2 * s**2 + s, -2 * s**3 + 3 * s**2, s**3 - s**2
    return h00 * p[i] + h10 * m[i] + h01 * p[i + 1] + h11 * m[i + 1]


def linear(rows: np.ndarray, times: np.ndarray) -> np.ndarray:
    """(len(times), 2): world.json's walk, straight and at constant speed between rows, standing after the last."""
    return np.column_stack([np.interp(times, rows[:, 0], rows[:, 1]), np.interp(times, rows[:, 0], rows[:, 2])])


def sample_times(waypoints: np.ndarray, rows: np.ndarray, rng: np.random.Generator) -> np.ndarray:
    """At least 1,000 times over the walk: random ones, every row and waypoint, and in every waypoint segment
    the fractions 1/4, 1/3, 1/2, 2/3, 3/4 (a Catmull-Rom segment strays most near 1/3, 1/2 or 2/3: its
    offset from the chord is h10(s) e0 + h11(s) e1, extreme at s = 1/3 and 2/3)."""
    t0, t1 = waypoints[:-1, 0], waypoints[1:, 0]
    inner = [t0 + (t1 - t0) * s for s in (0.25, 1 / 3, 0.5, 2 / 3, 0.75)]
    return np.concatenate([rng.uniform(0.0, rows[-1, 0], 1000), rows[:, 0], waypoints[:, 0], *inner])


@pytest.fixture(scope="module")
def folder(tmp_path_factory):
    world = worldgen.generate("cluttered", seed=4, **PEOPLE)
    return world.write(tmp_path_factory.mktemp("people_exports"), preview=False)


def test_the_reference_interpolator_on_hand_checked_cases():
    line = np.array([[0.0, 0.0, 0.0, 0.0], [1.0, 1.0, 0.0, 0.0], [2.0, 2.0, 0.0, 0.0], [3.0, 3.0, 0.0, 0.0]])
    # Catmull-Rom (tension 0) walks evenly spaced collinear points at constant speed between the ends.
    np.testing.assert_allclose(gz_actor_positions(line, 0.0, [1.25, 1.5, 1.9])[:, 0], [1.25, 1.5, 1.9], atol=1e-12)
    # Tension 1: zero tangents, each segment eased, 3 s^2 - 2 s^3 of the way at fraction s.
    s = 0.5 - math.sqrt(3.0) / 6.0
    got = gz_actor_positions(line, 1.0, [1.0 + s, 1.5, 2.0, 7.0])[:, 0]
    np.testing.assert_allclose(got, [1.0 + 3 * s**2 - 2 * s**3, 1.5, 2.0, 3.0], atol=1e-12)
    assert 1.0 + s - got[0] == pytest.approx(EASE, abs=1e-12)  # the furthest it lags: sqrt(3) / 18 of the leg
    # A time on a key frame is that key frame's point.
    corner = np.array([[0.0, 0.0, 0.0, 0.0], [2.0, 1.0, 0.0, 0.0], [4.0, 1.0, 1.0, 0.0]])
    np.testing.assert_allclose(gz_actor_positions(corner, 0.0, [2.0])[0], [1.0, 0.0, 0.0], atol=1e-12)


def test_actor_waypoints_keep_the_rows_lie_on_the_legs_and_keep_within_the_tolerance():
    # A start, a right-angle turn, a 4.9 s stay, a turn back and an end.
    rows = np.array([[0.0, 0.0, 0.0], [0.1, 0.13, 0.0], [0.2, 0.26, 0.0], [0.3, 0.26, 0.12], [5.2, 0.26, 0.12],
                     [5.3, 0.13, 0.12], [5.4, 0.0, 0.12]])
    way = actor_waypoints(rows)
    assert {tuple(r) for r in rows} <= {tuple(w) for w in way}
    assert np.all(np.diff(way[:, 0]) > 0)
    np.testing.assert_allclose(linear(rows, way[:, 0]), way[:, 1:], atol=1e-6)
    assert not np.any((way[:, 0] > 0.3) & (way[:, 0] < 5.2))  # nothing added inside the stay
    times = np.linspace(0.0, 6.0, 60001)
    gap = np.hypot(*(gz_actor_positions(with_z(way), TENSION, times)[:, :2] - linear(rows, times)).T)
    assert gap.max() <= WAYPOINT_TOLERANCE + 2e-6
    stay = (times >= 0.3) & (times <= 5.2)
    assert np.hypot(*(gz_actor_positions(with_z(way), TENSION, times[stay])[:, :2] - rows[3, 1:]).T).max() <= MM
    # The rows alone: Catmull-Rom rounds the turns and overshoots into the stay by centimetres.
    raw = np.hypot(*(gz_actor_positions(with_z(rows), TENSION, times)[:, :2] - linear(rows, times)).T)
    assert raw.max() > 10 * MM


def test_a_straight_walk_from_standing_to_standing_keeps_within_the_tolerance_with_few_waypoints():
    rows = np.column_stack([np.arange(51) * 0.1, np.arange(51) * 0.12, np.zeros(51)])  # 6 m at 1.2 m/s
    way = actor_waypoints(rows)
    times = np.linspace(0.0, 6.0, 6001)
    gap = np.hypot(*(gz_actor_positions(with_z(way), TENSION, times)[:, :2] - linear(rows, times)).T)
    assert gap.max() <= WAYPOINT_TOLERANCE + 2e-6
    # The rows alone start and stop 9 mm off (Catmull-Rom's end tangents are half the end legs).
    raw = np.hypot(*(gz_actor_positions(with_z(rows), TENSION, times)[:, :2] - linear(rows, times)).T)
    assert raw.max() > 5 * MM
    # Tension 1 needed ceil(0.12 m x EASE / 0.9 mm) = 13 parts a leg, 651 waypoints; this takes under 4 a leg.
    assert math.ceil(0.12 * EASE / WAYPOINT_TOLERANCE) == 13 and len(way) < 4 * 50


def test_a_walk_too_fast_to_cut_finely_enough_is_an_error_not_a_silent_offset():
    # A right-angle turn 20 us after a 10 m leg: no part shorter than 10 us can be written (times keep 6
    # decimals), so no cut keeps within the tolerance there.
    rows = np.array([[0.0, 0.0, 0.0], [0.00002, 10.0, 0.0], [0.00004, 10.0, 10.0]])
    with pytest.raises(WorldgenError, match=r"^actor waypoints: no cut keeps within 0\.0009 m of the walk near t = "):
        actor_waypoints(rows)


def with_z(rows: np.ndarray) -> np.ndarray:
    return np.column_stack([rows, np.zeros(len(rows))])


def test_sdf_actors_as_libsdformat_reads_them_follow_world_json_within_a_millimetre(folder):
    meta = json.loads((folder / "world.json").read_text())
    actors = dump_sdf(folder / "world.sdf")["actors"]  # also: libsdformat accepts the file
    rng = np.random.default_rng(0)
    assert len(meta["people"]) == 4
    worst = raw_worst = 0.0
    for person in meta["people"]:
        rows = np.array(person["trajectory"])
        actor = actors[person["name"]]
        # Written looping, with a last leg standing at the last row for HOLD_SECONDS: a script that does not
        # loop hangs Gazebo Sim once a rendering sensor plays it (docs/gazebo.md).
        assert actor["loop"] and list(actor["trajectories"]) == [0]
        script = actor["trajectories"][0]
        assert script["tension"] == TENSION == 0.0
        waypoints = np.array(script["waypoints"])[:, :4]
        assert waypoints[-1, :3].tolist() == [rows[-1, 0] + HOLD_SECONDS, rows[-1, 1], rows[-1, 2]]
        assert waypoints[0, 0] == 0.0 and np.all(waypoints[:, 3] == 0.0)
        times = sample_times(waypoints, rows, rng)
        assert len(times) >= 1000
        gap = np.hypot(*(gz_actor_positions(waypoints, script["tension"], times)[:, :2] - linear(rows, times)).T)
        worst = max(worst, float(gap.max()))
        # Played from the rows alone, an eased actor (tension 1) would lag by cm, a Catmull-Rom one by mm.
        raw_eased = np.hypot(*(gz_actor_positions(with_z(rows), 1.0, times)[:, :2] - linear(rows, times)).T)
        raw_worst = max(raw_worst, float(np.hypot(*(gz_actor_positions(with_z(rows), 0.0, times)[:, :2]
                                                     - linear(rows, times)).T).max()))
        assert raw_eased.max() > 5 * MM
    assert worst <= MM, worst
    assert raw_worst > MM, raw_worst


def test_sdf_actors_of_scripted_movers_follow_world_json_within_a_millimetre_loop_after_loop(tmp_path):
    folder = worldgen.generate("cluttered", seed=3, size=[10.0, 10.0], n_obstacles=6, n_movers=3).write(
        tmp_path, preview=False)
    meta = json.loads((folder / "world.json").read_text())
    actors = dump_sdf(folder / "world.sdf")["actors"]
    movers = meta["dynamic_obstacles"]
    assert len(movers) == 3
    for mover in movers:
        rows = np.array(mover["trajectory"])
        actor = actors[mover["name"]]
        assert actor["loop"] and mover["loop"]
        waypoints = np.array(actor["trajectories"][0]["waypoints"])[:, :4]
        period = rows[-1, 0]
        times = np.concatenate([sample_times(waypoints, rows, np.random.default_rng(2)) + lap * period
                                for lap in range(3)])
        want = positions_at([rows], [True], times)[:, 0]
        got = gz_actor_positions(waypoints, actor["trajectories"][0]["tension"], times, loop=True)[:, :2]
        assert np.hypot(*(got - want).T).max() <= MM
        # One waypoint per row, eased (the export before): metres off mid-leg.
        eased = gz_actor_positions(with_z(rows), 1.0, times, loop=True)[:, :2]
        assert np.hypot(*(eased - want).T).max() > 0.1


def test_mjcf_mocap_bodies_stepped_in_mujoco_follow_world_json_within_a_millimetre(folder):
    meta = json.loads((folder / "world.json").read_text())
    model = mujoco.MjModel.from_xml_path(str(folder / "world.mjcf.xml"))
    data = mujoco.MjData(model)
    bodies = {p["name"]: model.body(p["name"]).id for p in meta["people"]}
    assert all(model.body_mocapid[b] >= 0 for b in bodies.values())
    end = max(p["trajectory"][-1][0] for p in meta["people"])
    times = np.sort(np.random.default_rng(1).uniform(0.0, end + 2.0, 1200))  # past the end: standing
    worst = 0.0
    for t in times:
        drive_mocap(model, data, meta, float(t))
        mujoco.mj_step(model, data)
        for p in meta["people"]:
            rows = np.array(p["trajectory"])
            got = data.xpos[bodies[p["name"]]]
            want = linear(rows, np.array([t]))[0]
            worst = max(worst, float(np.hypot(*(got[:2] - want))))
            assert got[2] == pytest.approx(p["height"] / 2, abs=1e-9)
    assert worst <= MM, worst
