"""worldgen.groundtruth.barn_metrics against numbers computed by BARN's own code.

The reference numbers in data/barn_reference.json are facts obtained once by running BARN's
``difficulty_quant.py`` (dperille/jackal-map-creation at commit 947fe6f, unmodified) under
Python 2.7.18 with numpy 1.16.6: ``DifficultyMetrics(grid, path, radius).avg_all_metrics()`` on the
grids and paths stored beside them (the grids as hex rows of packed bits). The cases are hand grids
for the edge cases (a grid without walls, a path along every border and through every corner, a
dispersion radius larger than the map, path cells on walls, BARN's dispersion quirk, radius 0, a path
ending where it starts) and three worlds' maps at 0.1 m (cluttered, door, corridor): each world's
BARN inputs as ``barn.world_inputs`` makes them (C-space, radius 3) and its uninflated map with the
same chain (radius 20). BARN's code itself is not in this repository.
"""

from __future__ import annotations

import json
import math
from pathlib import Path

import numpy as np
import pytest

import worldgen
from worldgen.errors import ParameterError
from worldgen.groundtruth import barn, barn_metrics, truth

REFERENCE = json.loads((Path(__file__).parent / "data" / "barn_reference.json").read_text())
CASES = {case["name"]: case for case in REFERENCE["cases"]}


def grid_of(case) -> np.ndarray:
    rows, cols = case["shape"]
    bits = [np.unpackbits(np.frombuffer(bytes.fromhex(row), dtype=np.uint8))[:cols] for row in case["grid"]]
    grid = np.array(bits, dtype=np.uint8)
    assert grid.shape == (rows, cols)
    return grid


@pytest.mark.parametrize("name", sorted(CASES))
def test_equals_barns_own_code(name):
    case = CASES[name]
    ours = barn_metrics(grid_of(case), case["path"], case["radius"])
    if case["barn"] == "ZeroDivisionError":  # BARN divides by a zero chord: no tortuosity
        assert ours["tortuosity"] is None
        return
    for key, value in case["barn"].items():
        assert ours[key] == pytest.approx(value, rel=0, abs=1e-9), key


def test_the_cases_cover_what_they_claim():
    """The stored cases exercise the edge cases the module docs name (a check on the data itself)."""
    assert CASES["no_walls"]["barn"]["closest_wall"] == 2.0  # Python 2's (6 - 1) / 2
    assert CASES["radius_beyond_map"]["radius"] > max(CASES["radius_beyond_map"]["shape"])
    rows, cols = CASES["borders"]["shape"]
    path = np.array(CASES["borders"]["path"])
    assert {0, rows - 1} <= set(path[:, 0]) and {0, cols - 1} <= set(path[:, 1])
    on = grid_of(CASES["on_walls"])[tuple(np.array(CASES["on_walls"]["path"]).T)]
    assert on.any() and not on.all()
    big = [c for c in CASES.values() if c["shape"][0] * c["shape"][1] > 40_000]
    assert big and all(len(c["path"]) > 300 for c in big)


def test_dispersion_quirk_is_barns():
    """A wall 12 rows up and 6 columns left is seen along (-2, -1), which BARN counts one a step;
    its mirror image 12 down and 6 right is not seen along (2, 1), which counts two."""
    grid = np.zeros((31, 31), dtype=np.uint8)
    grid[3, 9] = 1
    assert barn_metrics(grid, [(15, 15)], 8)["dispersion"] == 2.0
    mirror = np.zeros_like(grid)
    mirror[27, 21] = 1
    assert barn_metrics(mirror, [(15, 15)], 8)["dispersion"] == 0.0
    assert barn_metrics(mirror, [(15, 15)], 16)["dispersion"] == 2.0  # twice the radius reaches it


def test_cspace_is_barns_window():
    """A C-space cell is a wall when the k x k window whose top-left corner it is meets a wall."""
    rng = np.random.default_rng(5)
    occ = rng.random((17, 23)) < 0.08
    for k in (1, 2, 3, 5, 17):
        got = barn.cspace(occ, k)
        want = np.array([[occ[r:r + k, c:c + k].any() for c in range(23 - k + 1)] for r in range(17 - k + 1)])
        assert got.shape == want.shape and (got == want).all()
    with pytest.raises(ParameterError, match="kernel"):
        barn.cspace(occ, 18)


def test_chain_is_8_connected_through_the_cells():
    pts = [(0, 0), (7, 3), (7, -4), (2, -4), (2, -4), (-5, 2)]
    out = barn.chain(pts)
    steps = np.abs(np.diff(out, axis=0))
    assert steps.max() == 1 and (steps.sum(axis=1) >= 1).all()  # one of the 8 moves each
    assert [tuple(p) for p in pts[:1]] == [tuple(out[0])] and tuple(out[-1]) == pts[-1]
    assert all(any((out == p).all(axis=1)) for p in pts)
    # A segment and its reverse give the same cells.
    assert {tuple(p) for p in barn.chain([(0, 0), (3, 8)])} == {tuple(p) for p in barn.chain([(3, 8), (0, 0)])}


def test_rejects_bad_inputs_in_one_line():
    grid = np.zeros((4, 5))
    with pytest.raises(ParameterError, match="inside the 4 x 5 grid"):
        barn_metrics(grid, [(0, 0), (4, 0)], 3)
    with pytest.raises(ParameterError, match="path_cells"):
        barn_metrics(grid, [], 3)
    with pytest.raises(ParameterError, match="path_cells"):
        barn_metrics(grid, [(0.5, 1.0)], 3)
    with pytest.raises(ParameterError, match="grid"):
        barn_metrics([1, 0], [(0, 0)], 3)
    with pytest.raises(ParameterError, match="grid"):
        barn_metrics([[0, 1], [0]], [(0, 0)], 3)
    with pytest.raises(ParameterError, match="disp_radius"):
        barn_metrics(grid, [(0, 0)], math.inf)


@pytest.mark.parametrize("generator,seed", [("cluttered", 3), ("door", 2)])
def test_world_json_records_barns_metrics_of_the_written_map(tmp_path, generator, seed):
    """metrics.barn is barn_metrics on the inputs made from map.pgm as written and the task's path."""
    world = worldgen.generate(generator, seed=seed)
    folder = world.write(tmp_path, preview=False)
    meta = json.loads((folder / "world.json").read_text())
    raw = (folder / "map.pgm").read_bytes().split(maxsplit=4)
    cols, rows = int(raw[1]), int(raw[2])
    image = np.frombuffer(raw[4][: rows * cols], dtype=np.uint8).reshape(rows, cols)
    occupied = (image == 0)[::-1]  # row 0 at the bottom, as world_inputs takes it
    res, origin = meta["occupancy"]["resolution"], meta["occupancy"]["origin"][:2]
    waypoints = meta["tasks"][0]["path"]["waypoints"]
    grid, cells = barn.world_inputs(occupied, origin, res, meta["robot"]["radius"], waypoints)
    k = barn.kernel_cells(meta["robot"]["radius"], res)
    assert grid.shape == (rows - k + 1, cols - k + 1)
    want = barn_metrics(grid, cells, barn.DISP_RADIUS)
    for key, value in meta["metrics"]["barn"].items():
        assert value == pytest.approx(want[key], abs=1e-6), key
    assert meta["metrics"]["barn"] == {k: round(v, 6) for k, v in truth.barn(world).items()}


def test_without_a_path_every_barn_metric_is_null():
    world = worldgen.generate("cluttered", seed=0, infeasible=True)
    assert world.metadata["metrics"]["barn"] == dict.fromkeys(barn.NAMES)


def test_barn_inputs_of_a_world_are_what_metrics_barn_uses():
    world = worldgen.generate("door", seed=3)
    grid, cells = truth.barn_inputs(world)
    assert barn_metrics(grid, cells, barn.DISP_RADIUS) == truth.barn(world)  # one task: no averaging
    raw, raw_cells = truth.barn_inputs(world, kernel=1)
    assert (raw == truth.occupancy_map(world).occupied[::-1]).all()
    half = barn.kernel_cells(world.robot.radius, truth.occupancy_map(world).resolution) // 2
    assert (cells == raw_cells - half).all()  # this path keeps clear of the map's edge: no cell clipped
    with pytest.raises(ParameterError, match="task must be in"):
        truth.barn_inputs(world, task=1)
    with pytest.raises(worldgen.errors.InfeasibleError, match="no reference path"):
        truth.barn_inputs(worldgen.generate("cluttered", seed=0, infeasible=True))


def _walked(occ, r, c, dr, dc) -> int:
    """Free cells from (r, c) along (dr, dc) before a wall or the grid's edge, one step at a time."""
    n = 0
    while 0 <= r + (n + 1) * dr < occ.shape[0] and 0 <= c + (n + 1) * dc < occ.shape[1] \
            and not occ[r + (n + 1) * dr, c + (n + 1) * dc]:
        n += 1
    return n


def test_free_runs_and_closest_wall_against_walking_and_every_wall():
    """The binary searches and the column window (barn._free_runs, barn._closest_wall) against the plain
    definitions: a walk step by step, and the nearest of every wall cell, on random grids."""
    rng = np.random.default_rng(30)
    for _ in range(300):
        rows, cols = (int(v) for v in rng.integers(1, 40, 2))
        # Sparse grids too: there the nearest wall is often off every line through the cell.
        occ = rng.random((rows, cols)) < rng.choice([0.0, 0.005, 0.01, 0.02, 0.05, 0.1, 0.3, 0.6])
        r, c = rng.integers(0, rows, 40), rng.integers(0, cols, 40)
        wall = occ[r, c]
        runs = barn._free_runs(occ, r, c)
        assert len(runs) == 8
        for (dr, dc), got in runs.items():
            want = [-1 if w else _walked(occ, int(i), int(j), dr, dc) for i, j, w in zip(r, c, wall)]
            assert got.tolist() == want, (dr, dc)
        got = barn._closest_wall(occ, r, c, wall, runs)
        wr, wc = np.nonzero(occ)
        for k in range(len(r)):
            if not occ.any():
                want = float((rows - 1) // 2)
            else:
                want = 0.0 if wall[k] else math.sqrt(int(((wr - r[k]) ** 2 + (wc - c[k]) ** 2).min()))
            assert got[k] == want
