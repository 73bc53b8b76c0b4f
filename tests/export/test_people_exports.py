"""People in the three formats agree within 1 mm at any time: world.json's rows (walked straight between
rows, linearly in time), the SDF actors (as libsdformat reads them, played by a reference of gz-common's
actor interpolation) and the MJCF mocap bodies (stepped in MuJoCo, driven by drive_mocap).

Gazebo cannot run here, so the SDF side is a reference interpolator written from gz-common and gz-math:
``TrajectoryInfo::SetWaypoints`` makes one key frame per waypoint (times from the first) and a
``PoseAnimation`` with the trajectory's tension (clamped to [0, 1]); ``Animation::KeyFramesAtTime`` finds
the key frames k, k+1 around a time and the fraction s = (t - t_k) / (t_k+1 - t_k); the position is
``Spline::Interpolate(k, s)``, the cubic Hermite segment between the two points with tangents
``(1 - tension) x (p_k+1 - p_k-1) / 2`` (one-sided halves at the ends; a closed path, first point equal
to the last, wraps); a time past the end is the end (no loop).
"""

from __future__ import annotations

import json
import math

import mujoco
import numpy as np
import pytest
from support.reftools_sdf import dump_sdf

import worldgen
from worldgen.export.sdf import EASE, WAYPOINT_TOLERANCE, actor_waypoints
from worldgen.scene.motion import drive_mocap

#: Agreement promised between the formats (m).
MM = 1e-3
PEOPLE = {"size": [8.0, 8.0], "n_obstacles": 8, "n_people": 4, "people_duration": 20.0}


def gz_actor_positions(waypoints: np.ndarray, tension: float, times: np.ndarray) -> np.ndarray:
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
    if np.array_equal(p[0], p[-1]):  # closed: the start's tangent wraps, the end takes it
        m[0] = m[-1] = 0.5 * (p[1] - p[-2])
    else:
        m[0], m[-1] = 0.5 * (p[1] - p[0]), 0.5 * (p[-1] - p[-2])
    m *= scale
    t = np.clip(times, 0.0, key_t[-1])
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
    """At least 1,000 times over the walk: random ones, every row and waypoint, and the two instants of every
    waypoint segment where an eased segment is furthest from the straight walk (s = 1/2 -+ sqrt(3) / 6)."""
    t0, t1 = waypoints[:-1, 0], waypoints[1:, 0]
    worst = [t0 + (t1 - t0) * (0.5 + sign * math.sqrt(3.0) / 6.0) for sign in (-1, 1)]
    return np.concatenate([rng.uniform(0.0, rows[-1, 0], 1000), rows[:, 0], waypoints[:, 0], *worst])


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


def test_actor_waypoints_keep_the_rows_and_lie_on_the_legs():
    rows = np.array([[0.0, 0.0, 0.0], [0.1, 0.13, 0.0], [5.0, 0.13, 0.0], [5.1, 0.13, 0.1], [5.2, 0.0, 0.1]])
    way = actor_waypoints(rows)
    assert {tuple(r) for r in rows} <= {tuple(w) for w in way}
    assert np.all(np.diff(way[:, 0]) > 0)
    np.testing.assert_allclose(linear(rows, way[:, 0]), way[:, 1:], atol=1e-6)
    parts = np.hypot(*np.diff(way[:, 1:], axis=0).T)
    assert parts.max() * EASE <= WAYPOINT_TOLERANCE + 1e-6
    # ceil(length x EASE / tolerance) parts a leg: 0.13 m -> 14, 0.1 m -> 11; a stay needs none.
    assert len(way) == 14 + 1 + 11 + 14 + 1


def test_sdf_actors_as_libsdformat_reads_them_follow_world_json_within_a_millimetre(folder):
    meta = json.loads((folder / "world.json").read_text())
    actors = dump_sdf(folder / "world.sdf")["actors"]  # also: libsdformat accepts the file
    rng = np.random.default_rng(0)
    assert len(meta["people"]) == 4
    worst = 0.0
    for person in meta["people"]:
        rows = np.array(person["trajectory"])
        actor = actors[person["name"]]
        assert not actor["loop"] and list(actor["trajectories"]) == [0]
        script = actor["trajectories"][0]
        assert script["tension"] == 1.0
        waypoints = np.array(script["waypoints"])[:, :4]
        assert waypoints[0, 0] == 0.0 and np.all(waypoints[:, 3] == 0.0)
        times = sample_times(waypoints, rows, rng)
        assert len(times) >= 1000
        gap = np.hypot(*(gz_actor_positions(waypoints, script["tension"], times)[:, :2] - linear(rows, times)).T)
        worst = max(worst, float(gap.max()))
        # Played from the rows alone (the export before it cut the legs), the eased actor would lag by cm.
        raw = np.column_stack([rows, np.zeros(len(rows))])
        raw_gap = np.hypot(*(gz_actor_positions(raw, 1.0, times)[:, :2] - linear(rows, times)).T)
        assert raw_gap.max() > 5 * MM
    assert worst <= MM, worst


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
