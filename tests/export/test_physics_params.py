"""Physics per world: friction, step size and real-time factor reach every format.

A parameter sweep ("friction in 0.6, 0.8, 1.0, 1.2") must give worlds whose
files carry the value, as the reference tools read them: MuJoCo's compiled
``geom_friction`` and ``opt.timestep``, libsdformat's surfaces and physics, and
for URDF check_urdf plus the Gazebo extension and MuJoCo's importer.
"""

from __future__ import annotations

import json

import mujoco
import numpy as np
import pytest
from support.reftools_sdf import dump_sdf
from support.reftools_urdf import check_urdf

import worldgen
from worldgen.errors import ParameterError
from worldgen.export.xml import parse_bytes

SWEEP = (0.6, 0.8, 1.0, 1.2)
SMALL = {"size": [6, 6], "n_obstacles": 6, "n_movers": 1}


@pytest.fixture(scope="module")
def sweep(tmp_path_factory):
    out = tmp_path_factory.mktemp("sweep")
    return {mu: worldgen.generate("cluttered", seed=2, friction=mu, **SMALL).write(out) for mu in SWEEP}


def test_a_friction_sweep_gives_four_distinct_worlds(sweep):
    metas = {mu: json.loads((folder / "world.json").read_text()) for mu, folder in sweep.items()}
    assert len({m["content_hash"] for m in metas.values()}) == 4
    assert len({folder.name for folder in sweep.values()}) == 4
    for mu, meta in metas.items():
        assert meta["params"]["friction"] == mu
        assert meta["feasibility"]["feasible"] is True


@pytest.mark.parametrize("mu", SWEEP)
def test_mjcf_compiled_friction_is_the_swept_value(sweep, mu):
    model = mujoco.MjModel.from_xml_path(str(sweep[mu] / "world.mjcf.xml"))
    assert model.ngeom >= 6 + 4 + 1 + 1  # obstacles, walls, floor, mover
    np.testing.assert_allclose(model.geom_friction[:, 0], mu)  # every geom, the mover's included
    assert model.geom(model.geom("mover_0").id).friction[0] == pytest.approx(mu)


@pytest.mark.parametrize("mu", SWEEP)
def test_sdf_surfaces_carry_the_swept_value(sweep, mu):
    dump = dump_sdf(sweep[mu] / "world.sdf")
    assert len(dump["friction"]) >= 6 + 4 + 1
    assert set(dump["friction"].values()) == {(mu, mu)}


@pytest.mark.parametrize("mu", SWEEP)
def test_urdf_carries_the_swept_value_for_gazebo(sweep, mu):
    path = sweep[mu] / "world.urdf"
    check_urdf(path)
    root = parse_bytes(path.read_bytes()).getroot()
    refs = root.findall("gazebo")
    assert len(refs) >= 6 + 4 + 1
    assert {(float(g.findtext("mu1")), float(g.findtext("mu2"))) for g in refs} == {(mu, mu)}


@pytest.mark.parametrize("step, rtf", [(0.002, 1.0), (0.005, 0.0), (0.0005, 2.5)])
def test_step_size_and_real_time_factor_reach_every_format(tmp_path, step, rtf):
    world = worldgen.generate("cluttered", seed=4, step_size=step, real_time_factor=rtf, size=[6, 6], n_obstacles=4)
    folder = world.write(tmp_path)
    dump = dump_sdf(folder / "world.sdf")
    assert dump["physics"] == pytest.approx((step, rtf))
    assert dump["update_rate"] == pytest.approx(rtf / step)
    mj = mujoco.MjModel.from_xml_path(str(folder / "world.mjcf.xml"))
    assert mj.opt.timestep == pytest.approx(step)
    assert mj.numeric("real_time_factor").data[0] == pytest.approx(rtf)
    check_urdf(folder / "world.urdf")
    urdf = mujoco.MjModel.from_xml_string((folder / "world.urdf").read_text())
    assert urdf.opt.timestep == pytest.approx(step)
    np.testing.assert_allclose(urdf.opt.gravity, [0, 0, -9.81])
    meta = json.loads((folder / "world.json").read_text())
    assert (meta["params"]["step_size"], meta["params"]["real_time_factor"]) == (step, rtf)


def test_physics_is_part_of_the_content_hash():
    a = worldgen.generate("cluttered", seed=4, size=[6, 6], n_obstacles=4)
    b = worldgen.generate("cluttered", seed=4, size=[6, 6], n_obstacles=4, step_size=0.004)
    assert a.scene.nodes == b.scene.nodes and a.content_hash != b.content_hash


@pytest.mark.parametrize("params, pattern", [
    ({"friction": -0.1}, r"parameter 'friction' must be in \[0, 10\], got -0.1"),
    ({"friction": "ice"}, r"parameter 'friction' must be a number in \[0, 10\], got 'ice'"),
    ({"step_size": 0}, r"parameter 'step_size' must be in \[0.0001, 0.1\], got 0"),
    ({"real_time_factor": -1}, r"parameter 'real_time_factor' must be in \[0, 1000\], got -1"),
])
def test_bad_physics_parameters_get_one_line(params, pattern):
    with pytest.raises(ParameterError, match=pattern) as err:
        worldgen.generate("cluttered", seed=0, **params)
    assert "\n" not in str(err.value)
