"""Presets: each generates and is what its description says; every mistake in a preset file gets one
line naming the file and the key; the API and the CLI both reach them."""

from __future__ import annotations

import json
import math
from importlib import resources

import numpy as np
import pytest
from support.checks import ray, recheck
from support.cli import run, world_dirs

import worldgen
from worldgen import presets
from worldgen.errors import InfeasibleError, ParameterError

SHIPPED = ["clutter_50_boxes", "crowd_reacting", "door_crossing", "drl_arena", "empty_room", "group_in_corridor", "lidar_wall",
           "narrow_corridor", "person_crossing", "person_head_on", "person_in_doorway", "person_overtaking",
           "room_5_obstacles"]


def roles(world, role):
    return [n for n in world.scene.nodes if n.role == role]


def test_the_shipped_presets_are_the_files_in_templates():
    folder = resources.files("worldgen.templates").joinpath("presets")
    assert presets.names() == SHIPPED == sorted(p.name[:-5] for p in folder.iterdir() if p.name.endswith(".yaml"))
    for p in presets.all_presets():
        assert p.description and p.reproduces and p.source.endswith(f"{p.name}.yaml")


# -- each preset is what it says -------------------------------------------------------------

def test_empty_room():
    world = worldgen.generate_preset("empty_room")
    recheck(world)
    assert not roles(world, "obstacle") and len(roles(world, "wall")) == 4
    assert world.scene.bounds == ((-5.0, -5.0), (5.0, 5.0))
    t = world.tasks[0]
    assert (t.spawn.x, t.spawn.y) == (-4.5, -4.5)  # the corner start, 0.5 m in from both walls
    assert (t.goal.x - t.spawn.x, t.goal.y - t.spawn.y) == (5.0, 5.0)
    assert t.spawn.yaw == 0.0  # so (5, 5) is also the goal in the robot's odometry frame
    assert world.feasibility.paths[0].length == pytest.approx(5 * math.sqrt(2), abs=1e-6)


def test_room_with_5_obstacles():
    for seed in range(3):
        world = worldgen.generate_preset("room_5_obstacles", seed=seed)
        recheck(world)
        assert len(roles(world, "obstacle")) == 5 and world.scene.bounds == ((-5.0, -5.0), (5.0, 5.0))


def test_narrow_corridor_is_0_8_m_wide_and_says_so():
    world = worldgen.generate_preset("narrow_corridor")
    recheck(world)
    report = world.feasibility
    assert report.narrowest_passage == pytest.approx(0.8, abs=5e-6)
    assert world.metadata["feasibility"]["narrowest_passage"] == pytest.approx(report.narrowest_passage, abs=1e-6)
    (x0, y0), (x1, y1) = world.scene.bounds
    assert y1 - y0 == pytest.approx(0.8) and x1 - x0 == pytest.approx(10.0)


def test_door_crossing_path_crosses_the_closed_door_at_x_3():
    world = worldgen.generate_preset("door_crossing")
    meta = world.metadata
    door = meta["doors"][0]
    assert door["state"] == "closed"
    assert abs(door["passage"]["center"][0] - 3.0) <= 0.1  # the doorway, in a wall at x = 3
    task = meta["tasks"][0]
    assert task["goal"][:2] == [6.0, 0.0] and task["requires_door_open"] is True
    xs = np.array(task["path"]["waypoints"])[:, 0]
    assert xs.min() < 3.0 < xs.max()


def test_50_random_boxes_in_20_by_20():
    world = worldgen.generate_preset("clutter_50_boxes", seed=1)
    recheck(world)
    obstacles = roles(world, "obstacle")
    assert len(obstacles) == 50 and {o.shape.kind for o in obstacles} == {"box"}
    assert world.scene.bounds == ((-10.0, -10.0), (10.0, 10.0))
    assert all(o.shape.size[0] == o.shape.size[1] and o.pose.yaw == 0.0 for o in obstacles)  # the seed's draw


def test_drl_arena_draws_spawn_and_goal_within_4_5_m_where_free():
    for seed in range(6):
        world = worldgen.generate_preset("drl_arena", seed=seed)
        recheck(world)
        assert len(roles(world, "wall")) == 4 and {o.shape.kind for o in roles(world, "obstacle")} == {"box"}
        for pose in (world.tasks[0].spawn, world.tasks[0].goal):
            assert abs(pose.x) <= 4.5 and abs(pose.y) <= 4.5


def test_lidar_wall_is_2_m_straight_ahead():
    world = worldgen.generate_preset("lidar_wall")
    spawn = world.tasks[0].spawn
    d, name = ray(world, (spawn.x, spawn.y), spawn.yaw, 0.3)
    assert name == "target" and abs(d - 2.0) <= 1e-6


# -- every number a preset's texts quote is asserted ------------------------------------------
#
# Each claim is a pattern over the preset's description + reproduces text and a check of the
# world against the numbers it captures. Every number in the texts must fall inside some claim's
# match, so a preset whose text changes without its world (or the reverse) fails here.

N = r"(-?\d+(?:\.\d+)?)"


def _extent(world):
    (x0, y0), (x1, y1) = world.scene.bounds
    return x1 - x0, y1 - y0


def _odom_goal(world):
    """The goal in the odometry frame: from the spawn, x along the robot's heading."""
    t = world.tasks[0]
    dx, dy = t.goal.x - t.spawn.x, t.goal.y - t.spawn.y
    c, s = math.cos(t.spawn.yaw), math.sin(t.spawn.yaw)
    return c * dx + s * dy, -s * dx + c * dy


def _boxes(world):
    return [o for o in roles(world, "obstacle") if o.shape.kind == "box"]


def _lidar(world):
    return world.metadata["sensors"]["lidar"]


def _drawn_within(world, h):
    return all(abs(p.x) <= h and abs(p.y) <= h for t in world.tasks for p in (t.spawn, t.goal))


def _spans(values, lo, hi):
    """Values drawn from uniform(lo, hi): all inside, and both ends approached (50 draws: within 0.1 of
    each end of a 0.7 m range but for odds of 2 x (6/7)^50 < 1e-3)."""
    return min(values) >= lo and max(values) <= hi and min(values) < lo + 0.1 and max(values) > hi - 0.1


def _line(world):
    """The first task's straight line: spawn S, goal G, unit direction u, left normal n, length L."""
    t = world.tasks[0]
    s, g = np.array([t.spawn.x, t.spawn.y]), np.array([t.goal.x, t.goal.y])
    u = (g - s) / np.hypot(*(g - s))
    return s, g, u, np.array([-u[1], u[0]]), float(np.hypot(*(g - s)))


def _walker(world):
    """The scenario's person: (its rows (k, 3), its radius)."""
    person = next(m for m in world.scene.movers if m.person)
    return np.array(person.trajectory), person.radius


def _on_line(world):
    """The rows of the head-on person while it walks on the robot's line (lateral offset under 1 um)."""
    rows, _ = _walker(world)
    s, _, u, n, _ = _line(world)
    off = (rows[:, 1:] - s) @ n
    first_off = np.flatnonzero(np.abs(off) >= 1e-6)
    return rows[: first_off[0] if len(first_off) else len(rows)]


def _headings(rows, u):
    """Angle (degrees) between each moving step of ``rows`` and ``u``."""
    d = np.diff(rows[:, 1:], axis=0)
    moving = np.hypot(*d.T) > 1e-9
    d = d[moving] / np.hypot(*d[moving].T)[:, None]
    return np.degrees(np.arccos(np.clip(d @ u, -1, 1)))


def _steady_speed(rows, v):
    """Once up to speed (2 s after setting off: within exp(-4) of v0) the person walks at ``v`` (median of
    its steps), never over 1.3 v."""
    speed = np.hypot(*np.diff(rows[:, 1:], axis=0).T) / np.diff(rows[:, 0])
    off = rows[int(np.argmax(speed > 1e-9)), 0]
    steady = (speed > 1e-9) & (rows[1:, 0] > off + 2.0)
    return speed.max() <= 1.3 * v + 1e-4 and abs(float(np.median(speed[steady])) - v) < 1e-3


def _crossing_time(world):
    rows, _ = _walker(world)
    s, _, _, n, _ = _line(world)
    off = (rows[:, 1:] - s) @ n
    i = int(np.flatnonzero(off >= 0)[0])
    a, b = rows[i - 1], rows[i]
    return a[0] + (0 - off[i - 1]) / (off[i] - off[i - 1]) * (b[0] - a[0]), a[1:] + (b[1:] - a[1:]) * (0 - off[i - 1]) / (
        off[i] - off[i - 1])


def _must_yield(world):
    """Driving the line at full speed meets the person; the certificate arrives later than that would."""
    rows, radius = _walker(world)
    s, _, u, _, length = _line(world)
    v = world.params["robot_speed"]
    t = np.arange(0.0, length / v, 0.01)
    me = s + np.outer(np.minimum(v * t, length), u)
    them = np.column_stack([np.interp(t, rows[:, 0], rows[:, 1]), np.interp(t, rows[:, 0], rows[:, 2])])
    meets = np.hypot(*(me - them).T).min() < world.robot.inflation + radius
    return meets and world.feasibility.timed_paths[0].arrival > length / v + 1.0


def _people(world):
    """Every person's rows (k, 3), in order."""
    return [np.array(m.trajectory) for m in world.scene.movers if m.person]


def _lateral(world, rows):
    """Signed distance (m) of each row to the left of the first task's line."""
    s, _, _, n, _ = _line(world)
    return (rows[:, 1:] - s) @ n


def _along(world, rows):
    """Distance (m) of each row along the first task's line from its spawn."""
    s, _, u, _, _ = _line(world)
    return (rows[:, 1:] - s) @ u


def _overtakes(world):
    """Behind a robot driving the line at full speed at the start, ahead of it at the end: it passes it."""
    rows, _ = _walker(world)
    _, _, _, _, length = _line(world)
    v = world.params["robot_speed"]
    t = np.arange(0.0, rows[-1, 0], 0.01)
    me = np.minimum(v * t, length)
    them = np.interp(t, rows[:, 0], _along(world, rows))
    return them[0] < me[0] and them[-1] > me[-1]


def _pass_time(world):
    """When the overtaking person's centre passes a robot driving the line at full speed (s)."""
    rows, _ = _walker(world)
    t = np.arange(0.0, rows[-1, 0], 0.01)
    gap = np.interp(t, rows[:, 0], _along(world, rows)) - np.minimum(world.params["robot_speed"] * t, _line(world)[4])
    return float(t[np.argmax(gap > 0)])


def _top_speed(rows):
    return float(np.max(np.hypot(*np.diff(rows[:, 1:], axis=0).T) / np.diff(rows[:, 0])))


def _passing_speed(world, rows):
    """Median speed (m/s) of a person's steps while it is between the goal and the spawn."""
    along = _along(world, rows)
    inside = (along[:-1] < world.feasibility.paths[0].length) & (along[1:] > 0)
    speed = np.hypot(*np.diff(rows[:, 1:], axis=0).T) / np.diff(rows[:, 0])
    return float(np.median(speed[inside]))


def _group_spread(world, dt=0.01):
    """The largest distance (m) of a member from the group's centre, sampled every ``dt`` over the walk."""
    from worldgen.scene.motion import positions_at

    tracks = _people(world)
    t = np.arange(0.0, max(r[-1, 0] for r in tracks) + dt, dt)
    pos = positions_at(tracks, [False] * len(tracks), t)
    return float(np.hypot(*(pos - pos.mean(axis=1, keepdims=True)).transpose(2, 0, 1)).max())


def _passing_headings(world):
    """Headings (degrees from the robot's) of every member's steps while it walks between the goal and the spawn."""
    _, _, u, _, length = _line(world)
    out = []
    for rows in _people(world):
        along = _along(world, rows)
        inside = (along[:-1] < length) & (along[1:] > 0)
        out.append(_headings(rows[np.r_[inside, False] | np.r_[False, inside]], u))
    return np.concatenate(out)


CLAIMS = {
    "crowd_reacting": [
        (rf"{N} people walking for {N} s", lambda w, k, t: len(_people(w)) == k and w.params["people_duration"] == t
         and [p.get("behaviour") for p in w.metadata["people"]] == ["regular", "surprised", "scared", "curious"] * 2),
        (rf"{N} x {N} m walled room with {N} random obstacles",
         lambda w, a, b, k: _extent(w) == (a, b) and len(roles(w, "obstacle")) == k and len(roles(w, "wall")) == 4),
    ],
    "person_overtaking": [
        (rf"along its {N} m straight path in an empty {N} x {N} m room",
         lambda w, length, a, b: _line(w)[4] == pytest.approx(length) and _extent(w) == (a, b)
         and len(w.feasibility.paths[0].waypoints) == 2),
        (r"overtaking the robot from behind", _overtakes),
        (rf"radius {N} m, {N} m/s", lambda w, r, v: _walker(w)[1] == r and _steady_speed(_walker(w)[0], v)),
        (rf"more than twice the robot's top speed, robot_speed {N} m/s",
         lambda w, v: w.params["robot_speed"] == v and w.params["person_speed"][0] > 2 * v),
        (rf"starts {N} m behind the robot's spawn and\s+{N} m to the left of its path",
         lambda w, back, side: np.allclose(_walker(w)[0][0, 1:], _line(w)[0] - back * _line(w)[2] + side * _line(w)[3],
                                           atol=1e-6)),
        (rf"heading {N} degrees from the robot's, within {N} degrees",
         lambda w, deg, tol: np.all(np.abs(_headings(_walker(w)[0], _line(w)[2]) - deg) <= tol)),
        (rf"keeps between {N} and {N} m to the left of the path",
         lambda w, lo, hi: lo - 1e-6 <= _lateral(w, _walker(w)[0]).min() and _lateral(w, _walker(w)[0]).max() <= hi),
        (rf"to {N} m beyond the goal",
         # Reached within ARRIVE (0.2 m) of the point beyond the goal, in its lane.
         lambda w, d: np.hypot(*(_walker(w)[0][-1, 1:] - (_line(w)[1] + d * _line(w)[2]
                                                         + _lateral(w, _walker(w)[0][:1])[0] * _line(w)[3]))) < 0.2),
        (rf"passes a robot driving at full speed {N} s after the start",
         lambda w, t: abs(_pass_time(w) - t) <= 0.05),
    ],
    "group_in_corridor": [
        (rf"group of {N} people", lambda w, k: len(_people(w)) == k == w.params["group_size"]),
        (rf"along a {N} x {N} m walled corridor", lambda w, a, b: _extent(w) == (a, b) and len(roles(w, "wall")) == 4),
        (rf"radius {N} m,\s+preferred speed {N} m/s", lambda w, r, v: all(m.radius == r for m in w.scene.movers)
         and w.params["person_speed"] == [v, v] and all(_top_speed(rows) <= 1.3 * v + 1e-4 for rows in _people(w))),
        (rf"slow to about {N} m/s", lambda w, v: all(abs(_passing_speed(w, rows) - v) <= 0.02 for rows in _people(w))),
        (rf"abreast, {N} m apart and centred\s+{N} m to the left of the robot's {N} m straight path",
         lambda w, gap, side, length: _line(w)[4] == pytest.approx(length)
         and np.allclose(sorted(_lateral(w, rows[:1])[0] for rows in _people(w)), [side - gap, side, side + gap], atol=1e-6)),
        (rf"{N} m from its wall", lambda w, d: w.tasks[0].spawn.y - w.scene.bounds[0][1] == pytest.approx(d)
         == w.tasks[0].goal.y - w.scene.bounds[0][1]),
        (rf"{N} m short of its goal",
         lambda w, d: all(_along(w, rows[:1])[0] == pytest.approx(_line(w)[4] - d, abs=1e-6) for rows in _people(w))),
        (rf"heading {N} degrees from the\s+robot's, within {N} degrees",
         lambda w, deg, tol: np.all(np.abs(_passing_headings(w) - deg) <= tol)),
        (rf"to\s+{N} m behind its spawn",
         # All past the spawn; the group's centre within ARRIVE (0.2 m) of that far behind it along the line.
         lambda w, d: all(_along(w, rows[-1:])[0] < 0 for rows in _people(w))
         and abs(np.mean([_along(w, rows[-1:])[0] for rows in _people(w)]) + d) < 0.2),
        (rf"each within {N} m of the group's centre", lambda w, d: _group_spread(w) <= d),
        (r"passing it on its left", lambda w: all(_lateral(w, rows).min() > w.robot.inflation + 0.25 for rows in _people(w))),
    ],
    "person_in_doorway": [
        (rf"open {N} m doorway at x = {N} m",
         lambda w, width, x: w.metadata["doors"][0]["state"] == "open"
         and w.metadata["doors"][0]["passage"]["width"] == pytest.approx(width)
         and w.metadata["doors"][0]["passage"]["center"][0] == pytest.approx(x)),
        (rf"robot's path from \({N}, {N}\) to \({N}, {N}\)",
         lambda w, sx, sy, gx, gy: (w.tasks[0].spawn.x, w.tasks[0].spawn.y, w.tasks[0].goal.x, w.tasks[0].goal.y)
         == (sx, sy, gx, gy)),
        (rf"steps aside after {N} s", lambda w, t: _walker(w)[0][1, 0] == t),
        (rf"radius {N} m\) stands still in the middle of the doorway for {N} s",
         lambda w, r, t: _walker(w)[1] == r and _walker(w)[0][1, 0] == t
         and np.allclose(_walker(w)[0][:2, 1:], [w.metadata["doors"][0]["passage"]["center"]] * 2, atol=1e-6)),
        (rf"walks at\s+{N} m/s", lambda w, v: w.params["person_speed"] == [v, v]
         and np.max(np.hypot(*np.diff(_walker(w)[0][:, 1:], axis=0).T) / np.diff(_walker(w)[0][:, 0])) <= 1.3 * v + 1e-4),
        (rf"to {N} m beyond the doorway and {N} m to the right of the robot's path",
         lambda w, ahead, side: np.hypot(*(_walker(w)[0][-1, 1:] - (np.array(w.metadata["doors"][0]["passage"]["center"])
                                                                  + ahead * _line(w)[2] - side * _line(w)[3]))) < 0.2),
        (rf"\(robot_speed {N} m/s\)", lambda w, v: w.params["robot_speed"] == v),
        (r"the robot must wait", _must_yield),
    ],
    "person_head_on": [
        (rf"along its {N} m straight path in an empty {N} x {N} m room",
         lambda w, length, a, b: _line(w)[4] == pytest.approx(length) and _extent(w) == (a, b)
         and len(w.feasibility.paths[0].waypoints) == 2),
        (r"the robot must yield", _must_yield),
        (rf"radius {N} m, {N} m/s", lambda w, r, v: _walker(w)[1] == r and _steady_speed(_on_line(w), v)),
        (rf"starts on the robot's path {N} m short of its goal",
         lambda w, d: np.allclose(_walker(w)[0][0, 1:], _line(w)[1] - d * _line(w)[2], atol=1e-6)),
        (rf"heading opposite to the robot's \({N} degrees\)",
         lambda w, deg: np.all(np.abs(_headings(_on_line(w), _line(w)[2]) - deg) < 1e-3)),
        (rf"to {N} m short of the robot's spawn, then round the robot to {N} m behind it",
         # On the line until within ARRIVE (0.2 m) plus one step (0.15 m) of the point short of the spawn ...
         lambda w, a, b: a <= (_on_line(w)[-1, 1:] - _line(w)[0]) @ _line(w)[2] <= a + 0.35
         # ... and at the end within ARRIVE of the point behind it.
         and np.hypot(*(_walker(w)[0][-1, 1:] - (_line(w)[0] - b * _line(w)[2]))) < 0.2),
    ],
    "person_crossing": [
        (rf"robot's {N} m straight path at right angles at its midpoint, in an empty {N} x {N} m room",
         lambda w, length, a, b: _line(w)[4] == pytest.approx(length) and _extent(w) == (a, b)
         and np.hypot(*(_crossing_time(w)[1] - (_line(w)[0] + _line(w)[2] * length / 2))) < 1e-6),
        (rf"radius {N} m, {N} m/s", lambda w, r, v: _walker(w)[1] == r and _steady_speed(_walker(w)[0], v)),
        (rf"walks from {N} m to the right of the robot's path to {N} m to its left",
         lambda w, a, b: np.allclose(_walker(w)[0][0, 1:], _line(w)[0] + _line(w)[2] * _line(w)[4] / 2 - a * _line(w)[3],
                                     atol=1e-6)
         and np.hypot(*(_walker(w)[0][-1, 1:] - (_line(w)[0] + _line(w)[2] * _line(w)[4] / 2 + b * _line(w)[3]))) < 0.2),
        (rf"crossing it at {N} degrees", lambda w, deg: np.all(np.abs(_headings(_walker(w)[0], _line(w)[2]) - deg) < 1e-3)),
        (rf"top speed \(robot_speed {N} m/s: {N} s after the start\)",
         lambda w, v, t: w.params["robot_speed"] == v and t == pytest.approx(_line(w)[4] / 2 / v)
         and abs(_crossing_time(w)[0] - t) <= 0.1),
    ],
    "empty_room": [
        (rf"{N} x {N} m", lambda w, a, b: _extent(w) == (a, b)),
        (rf"start at \({N}, {N}\)", lambda w, x, y: (w.tasks[0].spawn.x, w.tasks[0].spawn.y) == (x, y)),
        (rf"yaw {N}\b", lambda w, yaw: w.tasks[0].spawn.yaw == yaw),
        (rf"(?<!world )goal(?: at)? \({N}, {N}\)", lambda w, x, y: _odom_goal(w) == pytest.approx((x, y), abs=1e-9)),
        (rf"\({N}, {N}\) in the odometry frame", lambda w, x, y: _odom_goal(w) == pytest.approx((x, y), abs=1e-9)),
        (rf"world goal \({N}, {N}\) = spawn \+ \({N}, {N}\)",
         lambda w, gx, gy, dx, dy: (w.tasks[0].goal.x, w.tasks[0].goal.y) == (gx, gy)
         == (w.tasks[0].spawn.x + dx, w.tasks[0].spawn.y + dy)),
        (rf"start {N} m in from the \({N}, {N}\) corner",
         lambda w, d, cx, cy: w.scene.bounds[0] == (cx, cy)
         and (w.tasks[0].spawn.x - cx, w.tasks[0].spawn.y - cy) == (d, d)),
        (rf"straight line, {N} m", lambda w, length: w.feasibility.paths[0].length == pytest.approx(length, abs=5e-4)
         and len(w.feasibility.paths[0].waypoints) == 2),
    ],
    "clutter_50_boxes": [
        (rf"{N} random boxes", lambda w, n: len(_boxes(w)) == len(roles(w, "obstacle")) == n),
        (rf"generate {N} obstacles", lambda w, n: len(roles(w, "obstacle")) == n),
        (rf"{N} x {N} m area", lambda w, a, b: _extent(w) == (a, b) and len(roles(w, "wall")) == 4),
        (rf"square footprint of side uniform\({N}, {N}\) m",
         lambda w, lo, hi: all(b.shape.size[0] == b.shape.size[1] for b in _boxes(w))
         and _spans([b.shape.size[0] for b in _boxes(w)], lo, hi)),
        (rf"height of uniform\({N}, {N}\) m", lambda w, lo, hi: _spans([b.shape.size[2] for b in _boxes(w)], lo, hi)),
        (rf"yaw {N}\b", lambda w, yaw: all(b.pose.yaw == yaw for b in _boxes(w))),
        (rf"base at z = {N}", lambda w, z: all(w.scene.aabb(b.name)[0][2] == pytest.approx(z, abs=1e-9) for b in _boxes(w))),
    ],
    "lidar_wall": [
        (rf"{N} m wide wall", lambda w, width: w.scene.aabb("target")[1][1] - w.scene.aabb("target")[0][1]
         == pytest.approx(width, abs=1e-9)),
        (rf"{N} m straight ahead", lambda w, d: w.scene.aabb("target")[0][0] - w.tasks[0].spawn.x == pytest.approx(d)),
        (r"ranges\[0\]", lambda w: _lidar(w)["angle_min"] == 0.0),
        (r"ranges\[i\] at angle_min \+ i \* increment",
         lambda w: _lidar(w)["angle_max"] == pytest.approx(2 * math.pi * (_lidar(w)["samples"] - 1) / _lidar(w)["samples"],
                                                            abs=1e-6)),
        (rf"wall at {N} m", lambda w, d: _lidar(w)["ranges"][0] == pytest.approx(d, abs=1e-6)),
        (rf"plane x = {N}", lambda w, x: w.scene.aabb("target")[0][0] == pytest.approx(x, abs=1e-9)),
        (rf"lidar_angle_min {N}", lambda w, a: w.params["lidar_angle_min"] == a == _lidar(w)["angle_min"]),
        (rf"reads {N} m, within its {N} cm tolerance", lambda w, d, cm: abs(_lidar(w)["ranges"][0] - d) < cm / 100),
    ],
    "narrow_corridor": [
        (rf"Straight {N} m corridor", lambda w, length: _extent(w)[0] == pytest.approx(length)),
        (rf"{N} m wide", lambda w, width: _extent(w)[1] == pytest.approx(width)),
        (rf"radius {N} m, clearance\s+{N} m", lambda w, r, c: (w.robot.radius, w.robot.clearance) == (r, c)),
        (rf"leaves {N} m on each side",
         lambda w, side: (_extent(w)[1] - 2 * w.robot.inflation) / 2 == pytest.approx(side, abs=1e-9)),
        (rf"narrowest_passage is {N} m, the exact gap\s+between the walls \(to within {N} m",
         lambda w, width, tol: w.metadata["metrics"]["narrowest_passage"] == pytest.approx(width, abs=tol)),
    ],
    "room_5_obstacles": [
        (rf"{N} x {N} m walled room", lambda w, a, b: _extent(w) == (a, b) and len(roles(w, "wall")) == 4),
        (rf"with {N} randomly placed boxes and cylinders",
         lambda w, n: len(roles(w, "obstacle")) == n and {o.shape.kind for o in roles(w, "obstacle")} <= {"box", "cylinder"}),
    ],
    "drl_arena": [
        (rf"{N} x {N} m (?:walled )?room", lambda w, a, b: _extent(w) == (a, b) and len(roles(w, "wall")) == 4),
        (rf"{N} random boxes", lambda w, n: len(_boxes(w)) == len(roles(w, "obstacle")) == n),
        (rf"\+-{N} m", lambda w, h: _drawn_within(w, h)),
    ],
    "door_crossing": [
        (rf"door(?:way)? at x = {N} m", lambda w, x: w.metadata["doors"][0]["passage"]["center"][0] == pytest.approx(x)),
        (rf"beyond it at \({N}, {N}\)", lambda w, x, y: (w.tasks[0].goal.x, w.tasks[0].goal.y) == (x, y)
         and w.tasks[0].spawn.x < w.metadata["doors"][0]["passage"]["center"][0] < x),
        (rf"crosses x = {N}", lambda w, x: min(p[0] for p in w.feasibility.paths[0].waypoints) < x
         < max(p[0] for p in w.feasibility.paths[0].waypoints)),
    ],
}


@pytest.mark.parametrize("name", SHIPPED)
def test_every_number_a_preset_quotes_holds(name):
    import re

    preset = presets.load(name)
    text = f"{preset.description} {preset.reproduces}"
    covered = set()
    for seed in range(3):
        world = worldgen.generate_preset(name, seed=seed)
        for pattern, holds in CLAIMS[name]:
            found = list(re.finditer(pattern, text))
            assert found, f"{name}: the text no longer says {pattern!r}"
            for m in found:
                covered.update(range(*m.span()))
                numbers = [float(g) for g in m.groups()]
                assert holds(world, *numbers), f"{name} seed {seed}: {m.group(0)!r} does not hold"
    unclaimed = [m.group(0) for m in re.finditer(r"\d+(?:\.\d+)?", text) if not set(range(*m.span())) <= covered]
    assert not unclaimed, f"{name}: numbers quoted but not asserted: {unclaimed}"


# -- the API ---------------------------------------------------------------------------------

def test_overrides_win_and_the_world_regenerates_without_the_preset():
    world = worldgen.generate_preset("narrow_corridor", seed=5, width=1.0, shape="L")
    assert world.generator == "corridor" and world.params["width"] == 1.0 and world.params["shape"] == "L"
    again = worldgen.generate(world.generator, seed=5, **world.metadata["params"])
    assert again.content_hash == world.content_hash


def test_a_preset_file_by_path(tmp_path):
    path = tmp_path / "mine.yaml"
    path.write_text("name: mine\ndescription: d\nreproduces: r\ngenerator: corridor\n"
                    "params: {shape: zigzag, segments: [3, 3, 3], turns: [left, right]}\n")
    world = worldgen.generate_preset(str(path))
    assert world.params["turns"] == "left,right" and world.params["segments"] == [3.0, 3.0, 3.0]


# -- bad preset files: one line naming the file and the key ----------------------------------

GOOD = {"name": "p", "description": "d", "reproduces": "r", "generator": "cluttered", "params": "{n_obstacles: 3}"}


def _text(**changes):
    fields = {**GOOD, **changes}
    return "".join(f"{k}: {v}\n" for k, v in fields.items() if v is not None)


@pytest.mark.parametrize("text,pattern", [
    (_text(extra="1"), r"preset file '.*p.yaml': unknown key 'extra'; allowed: name, description, reproduces, generator, params$"),
    (_text(reproduces=None), r"preset file '.*p.yaml': key 'reproduces' is missing$"),
    (_text(name="other"), r"preset file '.*p.yaml': key 'name' must equal the file's name 'p', got 'other'$"),
    (_text(description="''"), r"preset file '.*p.yaml': key 'description' must be a non-empty string"),
    (_text(params="[1, 2]"), r"preset file '.*p.yaml': key 'params' must be a mapping"),
    (_text(params="{n_obstacles: -1}"),
     r"preset file '.*p.yaml': key 'params' \(generator 'cluttered'\): parameter 'n_obstacles' must be in \[0, 5000\], got -1$"),
    (_text(params="{colour: red}"), r"preset file '.*p.yaml': key 'params' \(generator 'cluttered'\): unknown parameter 'colour'"),
    (_text(generator="maze"), r"preset file '.*p.yaml': key 'params' \(generator 'maze'\): unknown generator 'maze'"),
    ("name: p\n  description: [unclosed\n", r"preset file '.*p.yaml' is not valid YAML at line \d+"),
    ("- just\n- a list\n", r"preset file '.*p.yaml' must hold a mapping with keys name, description"),
    ("!!python/object/apply:os.system [echo hi]\n", r"preset file '.*p.yaml' is not valid YAML"),  # safe_load only
])
def test_bad_preset_files_get_one_line_naming_file_and_key(tmp_path, text, pattern):
    path = tmp_path / "p.yaml"
    path.write_text(text)
    with pytest.raises(worldgen.WorldgenError, match=pattern) as err:
        presets.load(str(path))
    assert "\n" not in str(err.value)


def test_unknown_preset_names_the_available_ones(tmp_path):
    with pytest.raises(ParameterError, match=r"^unknown preset 'nope'; available: clutter_50_boxes, crowd_reacting, door_crossing"):
        worldgen.generate_preset("nope")
    with pytest.raises(ParameterError, match=r"^preset file '.*missing.yaml' does not exist$"):
        worldgen.generate_preset(str(tmp_path / "missing.yaml"))
    with pytest.raises(ParameterError, match=r"^parameter 'width' must be in \[0.05, 50\], got -1"):
        worldgen.generate_preset("narrow_corridor", width=-1)
    with pytest.raises(InfeasibleError, match=r"^corridor width 0.8 m cannot pass a 0.45 m radius robot"):
        worldgen.generate_preset("narrow_corridor", robot_radius=0.45)


# -- the command line, end to end ------------------------------------------------------------

def test_cli_presets_lists_every_name_with_its_description():
    done = run("presets")
    assert done.returncode == 0, done.stderr
    lines = done.stdout.splitlines()
    assert [line.split()[0] for line in lines] == SHIPPED
    for line, preset in zip(lines, presets.all_presets()):
        assert line.endswith(preset.description)
    as_json = json.loads(run("presets", "--json").stdout)
    assert [p["name"] for p in as_json] == SHIPPED and as_json[0]["generator"] == "cluttered"


def test_cli_generate_with_a_preset_and_an_override(tmp_path):
    done = run("generate", "--preset", "narrow_corridor", "--set", "length=6", "--seed", "2", "--out", tmp_path)
    assert done.returncode == 0, done.stderr
    (folder,) = world_dirs(tmp_path)
    meta = json.loads((folder / "world.json").read_text())
    assert meta["generator"] == "corridor" and meta["params"]["width"] == 0.8 and meta["params"]["length"] == 6.0
    assert meta["seed"] == 2 and meta["world_id"].startswith("corridor-s2-")
    assert folder.name == f"narrow_corridor--{meta['world_id']}" and meta["preset"] == "narrow_corridor"


@pytest.mark.parametrize("args,message,status", [
    (["--preset", "nope"], "error: unknown preset 'nope'; available: clutter_50_boxes", 2),
    (["cluttered", "--preset", "empty_room"], "error: give either GENERATOR or --preset, not both", 2),
    ([], "error: give a GENERATOR (see 'worldgen list') or --preset NAME (see 'worldgen presets')", 2),
    # Well formed, but no such world exists: status 3.
    (["--preset", "narrow_corridor", "--set", "robot_radius=0.45"],
     "error: corridor width 0.8 m cannot pass a 0.45 m radius robot with 0.05 m clearance (needs >= 1.0 m)", 3),
    (["--preset", "lidar_wall", "--set", "target_distance=0.1"], "error: parameter 'target_distance' must be at least", 2),
])
def test_cli_preset_mistakes_get_one_line_and_status_2_or_3(tmp_path, args, message, status):
    done = run("generate", *args, "--out", tmp_path / "out")
    assert done.returncode == status and done.stderr.startswith(message), done.stderr
    assert len(done.stderr.strip().splitlines()) == 1 and not (tmp_path / "out").exists()


def test_cli_allow_infeasible_writes_the_too_narrow_corridor(tmp_path):
    done = run("generate", "--preset", "narrow_corridor", "--set", "robot_radius=0.45", "--set", "max_attempts=1",
               "--allow-infeasible", "--out", tmp_path)
    assert done.returncode == 0, done.stderr
    (folder,) = world_dirs(tmp_path)
    meta = json.loads((folder / "world.json").read_text())
    assert meta["feasibility"]["feasible"] is False
    assert "spawn_free" in {c["name"] for c in meta["feasibility"]["checks"] if not c["ok"]}


# -- a preset's world says so: world.json `preset`, folder <preset>--<world_id> ---------------

def test_a_preset_world_records_its_preset_and_names_its_folder(tmp_path):
    from worldgen.export.metadata import validate
    from worldgen.verify import check_folder

    world = worldgen.generate_preset("room_5_obstacles", seed=2)
    plain = worldgen.generate(world.generator, 2, **world.params)
    assert world.preset == "room_5_obstacles" and plain.preset is None
    # The id is the scene's, however it was asked for; only the folder and world.json name the preset.
    assert world.world_id == plain.world_id and world.world_id.startswith("cluttered-s2-")
    assert world.metadata["preset"] == "room_5_obstacles" and "preset" not in plain.metadata
    validate(world.metadata)
    folder = world.write(tmp_path, preview=False)
    assert folder.name == f"room_5_obstacles--{world.world_id}"
    assert json.loads((folder / "world.json").read_text())["preset"] == "room_5_obstacles"
    assert check_folder(folder).ok, check_folder(folder)  # regenerates byte for byte, preset included
    assert plain.write(tmp_path, preview=False).name == plain.world_id


def test_cli_names_preset_folders_apart(tmp_path):
    for name in ("empty_room", "room_5_obstacles", "drl_arena"):
        result = run("generate", "--preset", name, "--seed", "1", "--out", tmp_path, "--formats", "mjcf")
        assert result.returncode == 0, result.stderr
    names = sorted(p.name for p in world_dirs(tmp_path))
    assert [n.split("--")[0] for n in names] == ["drl_arena", "empty_room", "room_5_obstacles"]
    for n in names:
        meta = json.loads((tmp_path / n / "world.json").read_text())
        assert n == f"{meta['preset']}--{meta['world_id']}" and meta["generator"] == "cluttered"


def test_pack_folders_of_preset_entries(tmp_path):
    from worldgen.pack.build import build_pack
    from worldgen.pack.recipe import parse_recipe

    recipe = parse_recipe("formats: [mjcf]\nseeds: 2\nworlds:\n  - preset: empty_room\n    seeds: 1\n"
                          "  - preset: drl_arena\n  - generator: cluttered\n    params: {n_obstacles: 3}\n", "r.yaml")
    build_pack(recipe, tmp_path / "pack")
    pack = worldgen.Pack.open(tmp_path / "pack")
    folders = [w.folder for w in pack]
    assert [f.split("/")[1].split("--")[0] for f in folders[:3]] == ["empty_room", "drl_arena", "drl_arena"]
    assert folders[3] == f"worlds/{pack[3].world_id}"
    for w in pack:
        meta = json.loads(w.read("world.json"))
        assert w.folder == "worlds/" + (f"{meta['preset']}--" if "preset" in meta else "") + w.world_id
        assert w.path.is_dir()
    index = (tmp_path / "pack" / "index.csv").read_text().splitlines()
    assert [line.split(",")[6] for line in index[1:]] == folders  # after seed, level, request_seed
    verified = run("pack", "verify", tmp_path / "pack")
    assert verified.returncode == 0, verified.stdout + verified.stderr


def test_a_mistyped_preset_name_gets_a_suggestion():
    from worldgen.presets import load

    with pytest.raises(ParameterError, match=r"^unknown preset 'empty_rom' \(did you mean 'empty_room'\?\); available: "):
        load("empty_rom")
