"""The certificate among people (tasks[].timed_path): checked independently from world.json alone at a
fine time step against every person, against a hand-checked wait, and against a brute-force search."""

from __future__ import annotations

import math

import numpy as np
import pytest

import worldgen
from worldgen.errors import InfeasibleError
from worldgen.export import metadata
from worldgen.people.timed import CELLS_PER_STEP, DT, MARGIN, SPARE, person_speed, timed_path

#: The fine step (s) of the independent check.
H = 0.002


def _interp(rows: np.ndarray, t: np.ndarray) -> np.ndarray:
    return np.column_stack([np.interp(t, rows[:, 0], rows[:, 1]), np.interp(t, rows[:, 0], rows[:, 2])])


def _verify(meta: dict) -> int:
    """Check every task's timed path of a world.json dict on its own terms; the number checked."""
    robot = meta["robot"]
    inflation, v_max = robot["radius"] + robot["clearance"], robot["max_speed"]
    people = [(np.array(p["trajectory"]), p["radius"]) for p in meta["people"]]
    w = v_max + max(float(np.max(np.hypot(*np.diff(t[:, 1:], axis=0).T) / np.diff(t[:, 0]))) for t, _ in people)
    checked = 0
    for task in meta["tasks"]:
        rows = np.array(task["timed_path"])
        assert rows[0, 0] == 0.0 and np.all(np.diff(rows[:, 0]) > 0)
        assert rows[-1, 0] == task["arrival_time"]
        np.testing.assert_allclose(rows[0, 1:], task["spawn"][:2], atol=1e-6)
        np.testing.assert_allclose(rows[-1, 1:], task["goal"][:2], atol=1e-6)
        speed = np.hypot(*np.diff(rows[:, 1:], axis=0).T) / np.diff(rows[:, 0])
        assert speed.max() <= v_max
        # Every row lies on the proven static path (so between rows the robot stays on it too: rows hold
        # each corner the path turns at).
        wp = np.array(task["path"]["waypoints"])
        a, b = wp[:-1], wp[1:]
        for x, y in rows[:, 1:]:
            ab, ap = b - a, np.array([x, y]) - a
            u = np.clip(np.einsum("ij,ij->i", ap, ab) / np.maximum(np.einsum("ij,ij->i", ab, ab), 1e-300), 0, 1)
            assert np.hypot(*(a + u[:, None] * ab - [x, y]).T).min() < 1e-5
        for c in wp[1:-1]:  # the robot passes each corner at a row: it never cuts one
            assert np.hypot(*(rows[:, 1:] - c).T).min() < 1e-5
        # Against every person at a fine step; between two samples the distance can dip at most w H / 2.
        t = np.arange(0.0, rows[-1, 0] + H, H)
        me = _interp(rows, t)
        for traj, radius in people:
            them = _interp(traj, t)
            gap = np.hypot(*(me - them).T) - (inflation + radius)
            assert gap.min() >= w * H / 2, (task["id"], gap.min())
        checked += 1
    return checked


@pytest.mark.parametrize("generator,params", [
    ("cluttered", {"size": [8.0, 8.0], "n_obstacles": 10, "n_people": 6, "people_duration": 20.0, "n_tasks": 2}),
    ("door", {"n_people": 3, "people_duration": 20.0}),
])
def test_timed_paths_pass_an_independent_check_from_world_json_alone(generator, params):
    checked = 0
    for seed in range(4):
        meta = worldgen.generate(generator, seed=seed, **params).metadata
        metadata.validate(meta)
        checked += _verify(meta)
    assert checked >= 4


@pytest.mark.parametrize("preset", ["person_head_on", "person_crossing", "person_overtaking", "group_in_corridor",
                                    "person_in_doorway"])
def test_every_encounter_preset_carries_a_timed_path_that_passes_the_independent_check(preset):
    meta = worldgen.generate_preset(preset).metadata
    metadata.validate(meta)
    assert _verify(meta) == 1 and meta["feasibility"]["feasible"]


def _straight_wait_case(stand_until: float):
    """A 10 m straight path at 0.5 m/s; a person (r 0.25) stands on it at x = 5 until ``stand_until``,
    then walks straight off sideways at 1 m/s for 3 m."""
    waypoints = np.array([[0.0, 0.0], [10.0, 0.0]])
    rows = [[0.0, 5.0, 0.0], [stand_until, 5.0, 0.0], [stand_until + 3.0, 5.0, 3.0]]
    person = np.array(rows[1:] if stand_until == 0 else rows)
    return waypoints, [person], [0.25]


def test_a_person_in_the_way_makes_the_robot_wait_as_long_as_hand_worked_out():
    waypoints, tracks, radii = _straight_wait_case(15.0)
    inflation, v = 0.25, 0.5
    found = timed_path(waypoints, tracks, radii, inflation, v)
    assert found is not None
    # The robot must not be at x = 5 until the person is R' = inflation + radius + MARGIN + w DT / 2 off the
    # line (w = 0.5 + 1 m/s), at t* = 15 + R' s; from there 5 m remain: arrival >= t* + 10 s. Waiting at
    # x = 5 - R' and leaving at t* costs at most R' / v more, plus a step of the grid either way.
    reach = inflation + 0.25 + MARGIN + (v + 1.0) * DT / 2
    t_star = 15.0 + reach
    assert t_star + 10.0 - DT <= found.arrival <= t_star + 10.0 + reach / v + 2 * DT
    # Without the person in the way (gone at t = 0 + 3 s, long before the robot gets there) it drives through.
    free = timed_path(waypoints, _straight_wait_case(0.0)[1], radii, inflation, v)
    assert free is not None and abs(free.arrival - 10.0 / v) <= DT + 1e-9


def test_no_timed_path_when_a_person_stands_on_the_goal():
    waypoints = np.array([[0.0, 0.0], [4.0, 0.0]])
    person = np.array([[0.0, 4.2, 0.0], [10.0, 4.2, 0.0]])
    assert timed_path(waypoints, [person], [0.25], 0.25, 0.5) is None


def _brute_force(waypoints, tracks, radii, inflation, v) -> float | None:
    """Earliest arrival by breadth-first search over (step, cell), every cell measured against every person."""
    w = np.asarray(waypoints, dtype=float)
    ds = v * DT / CELLS_PER_STEP * (1 - SPARE)
    xy, leg = [w[0]], [{0}]  # each cell's point and the legs it lies on (a corner on two)
    for q in range(len(w) - 1):
        n = max(1, math.ceil(math.hypot(*(w[q + 1] - w[q])) / ds - 1e-9))
        leg[-1].add(q)
        for m in range(1, n + 1):
            xy.append(w[q] + (w[q + 1] - w[q]) * m / n)
            leg.append({q})
    n = len(xy) - 1
    length = float(np.sum(np.hypot(*np.diff(w, axis=0).T)))
    speed = person_speed(tracks)
    reach = [r + inflation + MARGIN + (v + speed) * DT / 2 for r in radii]
    end = max(t[-1, 0] for t in tracks) + length / v + 5.0

    cells = np.array(xy)
    moves = [[j for j in range(max(0, i - CELLS_PER_STEP), min(n, i + CELLS_PER_STEP) + 1)
              if all(leg[m] & leg[i] & leg[j] for m in range(min(i, j), max(i, j) + 1))] for i in range(n + 1)]

    def free_at(k: int) -> np.ndarray:
        """Every cell against every person at step k."""
        ok = np.ones(n + 1, dtype=bool)
        for traj, rr in zip(tracks, reach):
            p = np.array([np.interp(k * DT, traj[:, 0], traj[:, c]) for c in (1, 2)])
            ok &= np.hypot(*(cells - p).T) > rr
        return ok

    front = {0} if free_at(0)[0] else set()
    k = 0
    while front and k * DT <= end:
        k += 1
        ok = free_at(k)
        front = {j for i in front for j in moves[i] if ok[j]}
        if n in front:
            return k * DT
    return None


def test_the_certificate_agrees_with_brute_force_on_small_worlds():
    rng = np.random.default_rng(3)
    agreed = waits = 0
    for _ in range(12):
        waypoints = np.array([[0.0, 0.0], [2.0, 0.3], [3.0, 1.5]])
        tracks = []
        for _ in range(2):
            a = rng.uniform([0.0, -1.5], [3.0, 2.5])
            b = rng.uniform([0.0, -1.5], [3.0, 2.5])
            t1 = rng.uniform(1.0, 6.0)
            tracks.append(np.array([[0.0, *a], [t1, *a], [t1 + math.hypot(*(b - a)) / 1.2, *b]]))
        found = timed_path(waypoints, tracks, [0.25, 0.25], 0.25, 0.5)
        brute = _brute_force(waypoints, tracks, [0.25, 0.25], 0.25, 0.5)
        assert (found is None) == (brute is None)
        if found is not None:
            assert abs(found.arrival - brute) < 1e-9, (found.arrival, brute)
            length = float(np.sum(np.hypot(*np.diff(waypoints, axis=0).T)))
            waits += found.arrival > length / 0.5 + DT
        agreed += 1
    assert agreed == 12 and waits >= 2  # some of them made the robot wait


def test_a_draw_without_a_timed_path_is_refused_and_counted():
    # A 1.5 m corridor: the robot cannot pass a person in it along its path, and people end up standing in it.
    with pytest.raises(InfeasibleError) as err:
        worldgen.generate("corridor", seed=0, max_attempts=2, length=10.0, n_people=3, people_duration=20.0)
    assert "timed_path failed 2x" in str(err.value) and "no timed path among the people" in str(err.value)
    w = worldgen.generate("corridor", seed=0, max_attempts=1, allow_infeasible=True, length=10.0, n_people=3,
                          people_duration=20.0)
    meta = w.metadata
    metadata.validate(meta)
    assert not meta["feasibility"]["feasible"] and meta["tasks"][0]["timed_path"] is None
    assert meta["tasks"][0]["arrival_time"] is None and meta["tasks"][0]["path"] is not None


def test_the_certificate_agrees_with_brute_force_on_a_generated_world():
    w = worldgen.generate("cluttered", seed=1, size=[5.0, 5.0], n_obstacles=3, n_people=3, people_duration=10.0)
    people = [m for m in w.scene.movers if m.person]
    tracks = [np.array(m.trajectory) for m in people]
    radii = [m.radius for m in people]
    path = w.feasibility.paths[0].waypoints
    found = w.feasibility.timed_paths[0]
    assert found.arrival == timed_path(path, tracks, radii, w.robot.inflation, 0.5).arrival
    assert abs(found.arrival - _brute_force(path, tracks, radii, w.robot.inflation, 0.5)) < 1e-9
    assert found.arrival > float(np.sum(np.hypot(*np.diff(path, axis=0).T))) / 0.5 + 1.0  # the people held it up
