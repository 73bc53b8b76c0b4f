"""The barn generator: its cellular automaton against hand-worked grids, its boxes against its cells,
its quick refusal against the exact check, and its worlds through the whole pipeline and the command."""

from __future__ import annotations

import json
import math

import mujoco
import numpy as np
import pytest
import shapely
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st
from lxml import etree
from support.checks import recheck, reference_tools
from support.cli import run, world_dirs

import worldgen
from worldgen import feasibility
from worldgen.export.xml import safe_parser
from worldgen.generators import get, robot_from_params
from worldgen.generators.barn import field_grid, field_scene, layout
from worldgen.generators.cellular import crossing_blocked, merge_boxes, neighbours, smooth
from worldgen.seeding import attempt_rng

# Row 0 is the start end (bottom); off the grid the sides count as filled (the four corners too), the
# ends as empty.
HAND = np.array([
    [1, 0, 0, 0],
    [1, 1, 0, 0],
    [0, 0, 0, 1],
    [0, 0, 1, 1],
], dtype=bool)
# Worked by hand, cell by cell, from the rule above.
HAND_COUNTS = [
    [5, 3, 1, 3],
    [5, 2, 2, 4],
    [5, 3, 4, 5],
    [3, 1, 2, 5],
]


# -- the automaton -------------------------------------------------------------------------------

def test_neighbour_counts_match_the_hand_worked_grid():
    assert neighbours(HAND).tolist() == HAND_COUNTS


@pytest.mark.parametrize("birth, death, expected", [
    # BARN's rule: at least 5 fills, fewer than 2 empties; only (2, 0) changes (empty, 5 neighbours).
    (5, 2, [[1, 0, 0, 0], [1, 1, 0, 0], [1, 0, 0, 1], [0, 0, 1, 1]]),
    (4, 3, [[1, 0, 0, 0], [1, 0, 0, 1], [1, 0, 1, 1], [0, 0, 0, 1]]),
])
def test_one_smoothing_pass_matches_the_hand_worked_grid(birth, death, expected):
    assert smooth(HAND, birth, death).astype(int).tolist() == expected


def test_a_lone_cell_dies_and_a_full_grid_stays_full():
    lone = np.zeros((5, 5), dtype=bool)
    lone[2, 2] = True
    assert not smooth(lone, 5, 2).any()
    assert smooth(np.ones((4, 4), dtype=bool), 5, 2).all()


# -- the boxes -------------------------------------------------------------------------------------

@settings(max_examples=200, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(st.integers(1, 14).flatmap(lambda r: st.integers(1, 14).flatmap(
    lambda c: st.lists(st.booleans(), min_size=r * c, max_size=r * c).map(lambda v: np.array(v).reshape(r, c)))))
def test_boxes_cover_exactly_the_filled_cells_once(grid):
    painted = np.zeros(grid.shape, dtype=int)
    for r, c, h, w in merge_boxes(grid):
        assert h >= 1 and w >= 1
        painted[r:r + h, c:c + w] += 1
    assert painted.max(initial=0) <= 1  # disjoint
    assert np.array_equal(painted.astype(bool), grid)  # their union is the filled cells


@pytest.mark.parametrize("fill, passes", [(0.15, 2), (0.2, 4), (0.3, 2), (0.3, 4)])
def test_a_grown_field_needs_far_fewer_boxes_than_cells(fill, passes):
    spec = get("barn")
    params = spec.resolve(dict(fill_fraction=fill, smoothing_passes=passes))
    for seed in range(5):
        grid = field_grid(params, attempt_rng(seed, 0).spawn(2)[0])
        # Measured on these draws: 2.0 to 4.3 cells a box (over 300 BARN-like draws: 44,769 cells, 15,458 boxes).
        assert len(merge_boxes(grid)) <= grid.sum() / 2, (seed, int(grid.sum()))


def test_the_scene_s_boxes_are_the_filled_cells():
    spec = get("barn")
    params = spec.resolve(dict(fill_fraction=0.25, grid_cols=12, grid_rows=10, cell_size=0.2))
    grid = field_grid(params, np.random.default_rng(4))
    scene = field_scene(params, grid)
    boxes = [n for n in scene.nodes if n.role == "obstacle"]
    width, length, depth = layout(params)
    cells = shapely.union_all([shapely.box(-width / 2 + c * 0.2, -length / 2 + r * 0.2,
                                           -width / 2 + (c + 1) * 0.2, -length / 2 + (r + 1) * 0.2)
                               for r, c in zip(*np.nonzero(grid))])
    prints = shapely.union_all([shapely.box(n.pose.x - n.shape.size[0] / 2, n.pose.y - n.shape.size[1] / 2,
                                            n.pose.x + n.shape.size[0] / 2, n.pose.y + n.shape.size[1] / 2)
                                for n in boxes])
    assert cells.symmetric_difference(prints).area < 1e-9
    assert sum(n.shape.size[0] * n.shape.size[1] for n in boxes) == pytest.approx(grid.sum() * 0.04, abs=1e-9)
    assert all(n.pose.yaw == 0 and n.pose.z == n.shape.size[2] / 2 for n in boxes)
    assert scene.bounds == ((-1.2, -2.0), (1.2, 2.0))  # 10 rows of 0.2 m and two 1 m strips


# -- the quick refusal -----------------------------------------------------------------------------

def test_crossing_blocked_on_hand_built_fields():
    cell, inflation = 0.15, 0.25  # the default robot: a 0.5 m disc
    wall = np.zeros((6, 10), dtype=bool)
    wall[3] = True
    assert crossing_blocked(wall, cell, inflation)
    assert not crossing_blocked(np.zeros((6, 10), dtype=bool), cell, inflation)
    gap = wall.copy()
    gap[3, 3:7] = False  # 0.6 m: a 0.5 m disc passes, so the screen must let it through
    assert not crossing_blocked(gap, cell, inflation)
    slit = wall.copy()
    slit[3, 4] = False  # 0.15 m: certain to block
    assert crossing_blocked(slit, cell, inflation)


def test_every_draw_the_screen_refuses_the_exact_check_refuses_too():
    spec = get("barn")
    params = spec.resolve(dict(fill_fraction=0.3, smoothing_passes=2))
    robot = robot_from_params(params)
    refused = 0
    for attempt in range(30):
        rng = attempt_rng(11, attempt)
        draft = spec.build(params, rng)
        if draft.rejected != "field_blocked":
            continue
        refused += 1
        if refused > 4:  # each exact check costs tens of ms; four suffice
            break
        grid = field_grid(params, attempt_rng(11, attempt).spawn(2)[0])
        report = feasibility.check(field_scene(params, grid), draft.tasks, robot)
        assert not report.feasible, attempt
    assert refused > 4


@settings(max_examples=40, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(seed=st.integers(0, 2**32), fill=st.sampled_from([0.2, 0.3, 0.4, 0.5]), passes=st.integers(0, 4),
       cell=st.sampled_from([0.05, 0.1, 0.15, 0.3, 0.6]), cols=st.integers(6, 24), rows=st.integers(3, 20),
       radius=st.sampled_from([0.05, 0.2, 0.3]), clearance=st.sampled_from([0.0, 0.05]))
def test_the_screen_refuses_only_fields_the_exact_check_refuses(seed, fill, passes, cell, cols, rows, radius,
                                                                clearance):
    spec = get("barn")
    cols = max(cols, math.ceil((2 * (radius + clearance) + 0.01) / cell))  # room for the robot in the strips
    params = spec.resolve(dict(fill_fraction=fill, smoothing_passes=passes, cell_size=cell, grid_cols=cols,
                               grid_rows=rows, robot_radius=radius, clearance=clearance, end_depth=1.5))
    draft = spec.build(params, attempt_rng(seed, 0))
    if draft.rejected != "field_blocked":
        return
    grid = field_grid(params, attempt_rng(seed, 0).spawn(2)[0])
    assert not feasibility.check(field_scene(params, grid), draft.tasks, robot_from_params(params)).feasible


# -- whole worlds ----------------------------------------------------------------------------------

@pytest.mark.parametrize("seed, params", [(0, {}), (3, dict(fill_fraction=0.3, smoothing_passes=2)),
                                          (1, dict(n_tasks=3, walls=False, cell_size=0.2))])
def test_worlds_cross_the_field_and_carry_their_certificate(seed, params):
    world = worldgen.generate("barn", seed, **params)
    recheck(world)  # an independent re-check of every reference path
    width, length, depth = layout(world.params)
    for task in world.tasks:
        assert task.spawn.y == pytest.approx(-(length + depth) / 2, abs=1e-6) and task.spawn.yaw == 1.570796
        assert task.goal.y == pytest.approx((length + depth) / 2, abs=1e-6)
    meta = json.loads(world.to_json())
    assert meta["feasibility"]["feasible"] is True
    assert {c["name"] for c in meta["feasibility"]["checks"]} >= {"path_exists", "path_clearance"}
    assert set(meta["metrics"]["barn"]) == {"average_visibility", "characteristic_dimension", "closest_wall",
                                            "dispersion", "tortuosity"}
    assert 1 <= meta["metrics"]["difficulty_level"] <= 10


def test_more_tasks_move_no_obstacle():
    a = worldgen.generate("barn", 5)
    b = worldgen.generate("barn", 5, n_tasks=3)
    assert a.scene.content_hash() == b.scene.content_hash() and len(b.tasks) == 3


def test_every_export_parses_and_mujoco_loads_it(tmp_path):
    world = worldgen.generate("barn", 2)
    out = world.write(tmp_path)
    boxes = {n.name for n in world.scene.nodes if n.role == "obstacle"}
    sdf = etree.parse(str(out / "world.sdf"), safe_parser())
    assert boxes <= {m.get("name") for m in sdf.iter("model")} | {lk.get("name") for lk in sdf.iter("link")} \
        | {c.get("name") for c in sdf.iter("collision")}
    urdf = etree.parse(str(out / "world.urdf"), safe_parser())
    assert urdf.getroot().tag == "robot"
    model = mujoco.MjModel.from_xml_path(str(out / "world.mjcf.xml"))
    assert boxes <= {model.geom(i).name for i in range(model.ngeom)}
    assert (out / "map.pgm").read_bytes().startswith(b"P5") and (out / "preview.png").stat().st_size > 0
    from worldgen.verify import check_folder
    assert check_folder(out).ok  # `worldgen check`: regenerated byte for byte from world.json's params


def test_the_reference_tools_accept_a_world(tmp_path):
    reference_tools(worldgen.generate("barn", 4, fill_fraction=0.25), tmp_path)


# -- the command -----------------------------------------------------------------------------------

def test_the_command_lists_and_generates_the_same_bytes_twice(tmp_path):
    listed = run("list")
    assert listed.returncode == 0 and any(line.startswith("barn ") for line in listed.stdout.splitlines())
    for name in ("a", "b"):
        res = run("generate", "barn", "--seed", "0", "--count", "3", "--out", tmp_path / name)
        assert res.returncode == 0, res.stderr
    a, b = world_dirs(tmp_path / "a"), world_dirs(tmp_path / "b")
    assert len(a) == 3 and [p.name for p in a] == [p.name for p in b]
    for da, db in zip(a, b):
        for f in sorted(da.iterdir()):
            assert f.read_bytes() == (db / f.name).read_bytes(), f
        meta = json.loads((da / "world.json").read_text())
        assert meta["generator"] == "barn" and meta["feasibility"]["feasible"] and "barn" in meta["metrics"]


@pytest.mark.parametrize("setting, says", [
    ("fill_fraction=1.5", "parameter 'fill_fraction' must be in [0, 0.9]"),
    ("end_depth=0.3", "parameter 'end_depth' must be at least"),
    ("death_limit=6", "parameter 'birth_limit' must be at least death_limit = 6"),
    ("grid_cols=2.5", "parameter 'grid_cols' must be an integer"),
    ("smoothing=3", "unknown parameter 'smoothing'"),
])
def test_a_parameter_mistake_is_one_line(setting, says, tmp_path):
    res = run("generate", "barn", "--set", setting, "--out", tmp_path)
    assert res.returncode == 2 and says in res.stderr, res.stderr
    assert len(res.stderr.strip().splitlines()) == 1 and "Traceback" not in res.stderr
    assert world_dirs(tmp_path) == []


def test_a_field_too_full_to_cross_is_refused_with_the_reason(tmp_path):
    res = run("generate", "barn", "--set", "fill_fraction=0.9", "--set", "max_attempts=5", "--out", tmp_path)
    assert res.returncode == 3 and "field_blocked failed 5x" in res.stderr, res.stderr


def test_the_crossing_screen_agrees_with_scipy_s_dilation_and_labelling():
    """crossing_blocked grows the field and walks its free cells with numpy alone (scipy is not a core
    dependency); scipy.ndimage's binary_dilation and 8-connected label are the reference, on 500 random
    fields, cells and discs."""
    from scipy import ndimage

    rng = np.random.default_rng(11)
    for _ in range(500):
        rows, cols = rng.integers(2, 40, 2)
        grid = rng.random((rows, cols)) < rng.uniform(0.0, 0.6)
        cell, inflation = float(rng.uniform(0.05, 0.5)), float(rng.uniform(0.0, 1.0))
        reach = inflation - cell / math.sqrt(2.0)
        blocked = grid
        if reach >= 0:
            k = int(math.floor(reach / cell + 0.5)) + 1
            o = np.abs(np.arange(-k, k + 1))
            structure = np.hypot(np.maximum(o[None, :] - 0.5, 0) * cell, np.maximum(o[:, None] - 0.5, 0) * cell) <= reach
            blocked = ndimage.binary_dilation(grid, structure=structure) | grid
        labels, _ = ndimage.label(~blocked, structure=np.ones((3, 3), dtype=bool))
        expected = not (set(labels[0][labels[0] > 0].tolist()) & set(labels[-1][labels[-1] > 0].tolist()))
        assert crossing_blocked(grid, cell, inflation) == expected
