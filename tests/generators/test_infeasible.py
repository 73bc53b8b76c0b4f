"""Infeasible worlds on purpose (``infeasible=True``): the goal walled in, for negative tests.

The world comes back (and is written) with ``feasibility.feasible`` false, and
the failed check is the route, not the start or the goal. That the goal really
is cut off is re-checked here with shapely, from world.json's entities alone.
"""

from __future__ import annotations

import json
import math
import subprocess
import sys
from pathlib import Path

import pytest
import shapely
from support.reftools_sdf import check_sdf
from support.reftools_urdf import check_urdf

import worldgen
from worldgen.export import metadata

_SCRIPT = Path(sys.executable).with_name("worldgen")
WORLDGEN = [str(_SCRIPT)] if _SCRIPT.exists() else [sys.executable, "-m", "worldgen"]
SMALL = {"size": [8, 8], "n_obstacles": 8}


def _footprint(entity):
    """The floor shadow of a box or upright cylinder entity, from world.json only."""
    x, y, _, _, _, yaw = entity["pose"]
    shape = entity["shape"]
    if shape["type"] == "cylinder":
        return shapely.Point(x, y).buffer(shape["radius"], quad_segs=32)
    sx, sy = shape["size"][:2]
    c, s = math.cos(yaw), math.sin(yaw)
    return shapely.Polygon([(x + c * px - s * py, y + s * px + c * py)
                            for px, py in ((-sx / 2, -sy / 2), (sx / 2, -sy / 2), (sx / 2, sy / 2), (-sx / 2, sy / 2))])


def _reachable(meta, task) -> bool:
    """Is the goal in the same piece of free floor as the spawn, for the inflated footprint?"""
    robot = meta["robot"]
    inflation = robot["radius"] + robot["clearance"]
    (x0, y0), (x1, y1) = meta["bounds"]["min"], meta["bounds"]["max"]
    blocked = shapely.union_all([_footprint(e).buffer(inflation) for e in meta["entities"]
                                 if e["role"] not in ("floor", "marker")])
    free = shapely.box(x0 + inflation, y0 + inflation, x1 - inflation, y1 - inflation).difference(blocked)
    parts = list(getattr(free, "geoms", [free]))
    spawn, goal = shapely.Point(task["spawn"][:2]), shapely.Point(task["goal"][:2])
    home = [p for p in parts if p.intersects(spawn)]
    assert home, "the spawn itself is not on free floor"
    return home[0].intersects(goal)


@pytest.mark.parametrize("seed, n_tasks", [(0, 1), (3, 1), (7, 2), (12, 3)])
def test_asked_for_infeasible_gets_a_walled_in_goal_and_says_why(seed, n_tasks):
    world = worldgen.generate("cluttered", seed=seed, infeasible=True, n_tasks=n_tasks, **SMALL)
    meta = world.metadata
    metadata.validate(meta)
    checks = {c["name"]: c for c in meta["feasibility"]["checks"]}
    assert meta["feasibility"]["feasible"] is False
    assert checks["path_exists"]["ok"] is False and "no path" in checks["path_exists"]["detail"]
    for ok in ("inside_bounds", "spawn_free", "goal_free"):
        assert checks[ok]["ok"] is True, ok
    assert meta["params"]["infeasible"] is True
    rings = [e for e in meta["entities"] if e["name"].startswith("goal_block_")]
    assert len(rings) == 4 * n_tasks and all(e["role"] == "wall" for e in rings)
    for task in meta["tasks"]:
        assert task["path"] is None
        assert not _reachable(meta, task)


def test_the_same_request_without_the_flag_is_feasible_and_reachable():
    world = worldgen.generate("cluttered", seed=3, **SMALL)
    meta = world.metadata
    assert meta["feasibility"]["feasible"] is True and meta["params"]["infeasible"] is False
    assert _reachable(meta, meta["tasks"][0])
    assert not any(e["name"].startswith("goal_block_") for e in meta["entities"])


def test_infeasible_worlds_are_deterministic_and_keep_the_obstacles():
    a = worldgen.generate("cluttered", seed=3, infeasible=True, **SMALL)
    b = worldgen.generate("cluttered", seed=3, infeasible=True, **SMALL)
    plain = worldgen.generate("cluttered", seed=3, **SMALL)
    assert a.to_json() == b.to_json()
    assert a.scene.nodes[:len(plain.scene.nodes)] == plain.scene.nodes and a.tasks == plain.tasks


def run(*args) -> subprocess.CompletedProcess:
    return subprocess.run(WORLDGEN + [str(a) for a in args], capture_output=True, text=True, timeout=120)


@pytest.mark.parametrize("extra", [[], ["--allow-infeasible"]])
def test_cli_writes_an_infeasible_world_end_to_end(tmp_path, extra):
    out = tmp_path / "out"
    done = run("generate", "cluttered", "--seed", "5", "--set", "infeasible=true", "--set", "size=8,8",
               "--set", "n_obstacles=8", "--set", "n_movers=1", "--out", out, *extra)
    assert done.returncode == 0, done.stderr
    (folder,) = [p for p in out.iterdir() if p.is_dir()]
    assert "infeasible" in done.stdout and "path_exists" in done.stdout
    meta = json.loads((folder / "world.json").read_text())
    metadata.validate(meta)
    assert meta["feasibility"]["feasible"] is False
    assert [c["name"] for c in meta["feasibility"]["checks"] if not c["ok"]][0] == "path_exists"
    assert len(meta["dynamic_obstacles"]) == 1
    ok, messages = check_sdf(folder / "world.sdf")
    assert ok, "\n".join(messages)
    check_urdf(folder / "world.urdf")
    import mujoco
    mujoco.MjModel.from_xml_path(str(folder / "world.mjcf.xml"))


def test_cli_rejects_a_bad_flag_value_in_one_line(tmp_path):
    done = run("generate", "cluttered", "--set", "infeasible=perhaps", "--out", tmp_path / "out")
    assert done.returncode == 2
    assert done.stderr.strip() == "error: parameter 'infeasible' must be true or false, got 'perhaps'"
    assert not (tmp_path / "out").exists() or not any((tmp_path / "out").iterdir())


def test_api_rejects_a_bad_flag_value_in_one_line():
    with pytest.raises(worldgen.ParameterError, match=r"^parameter 'infeasible' must be true or false, got 1$"):
        worldgen.generate("cluttered", seed=0, infeasible=1)


def _generator_names():
    from worldgen.generators import names

    return names()


@pytest.mark.parametrize("name", _generator_names())
def test_every_registered_generator_can_be_asked_for_an_infeasible_world_with_movers(name):
    world = worldgen.generate(name, seed=1, infeasible=True, n_movers=1)
    meta = world.metadata
    metadata.validate(meta)
    assert meta["feasibility"]["feasible"] is False
    failed = [c["name"] for c in meta["feasibility"]["checks"] if not c["ok"]]
    assert failed and failed[0] == "path_exists", failed
    assert len(meta["dynamic_obstacles"]) == 1
