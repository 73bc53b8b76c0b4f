"""Third-party consumers load what worldgen writes: Drake every generator's SDF (movers left out with
``sdf_actors=false``) and URDF; pybullet every URDF. pybullet's ``loadSDF`` rejects door worlds (it
cannot attach a joint to ``world``; the SDF is valid), so docs/formats.md sends pybullet users to the URDF.

Both are in the ``test`` extra; without them the tests skip, except on CI (CI=true), where a missing
consumer is a failure.
"""

from __future__ import annotations

import importlib
import os

import pytest
from lxml import etree
from support.reftools_sdf import check_sdf

import worldgen
from worldgen.export.xml import safe_parser
from worldgen.generators import names


def need(module: str):
    if os.environ.get("CI"):
        return importlib.import_module(module)
    return pytest.importorskip(module)


def _world(generator: str, movers: int, **params):
    # A 1.5 m corridor (the default) leaves a robot no way past a mover: no such world is certified.
    wide = {"width": 3.0} if generator == "corridor" and movers else {}
    return worldgen.generate(generator, seed=3, n_movers=movers, **params, **wide)


def _drake_bodies_and_joints(path):
    need("pydrake")
    from pydrake.multibody.parsing import Parser
    from pydrake.multibody.plant import MultibodyPlant
    from pydrake.multibody.tree import BodyIndex, JointIndex

    plant = MultibodyPlant(0.0)
    Parser(plant).AddModels(str(path))
    plant.Finalize()
    bodies = {plant.get_body(BodyIndex(i)).name() for i in range(plant.num_bodies())}
    joints = {plant.get_joint(JointIndex(i)).name(): plant.get_joint(JointIndex(i)) for i in range(plant.num_joints())}
    return bodies, joints


@pytest.mark.parametrize("movers", [0, 2])
@pytest.mark.parametrize("generator", names())
def test_drake_loads_every_generators_sdf_and_urdf(tmp_path, generator, movers):
    world = _world(generator, movers, sdf_actors=movers == 0)  # actors only where there are none to leave out
    folder = world.write(tmp_path, preview=False)
    entities = {e["name"] for e in world.metadata["entities"]}
    for name in ("world.sdf", "world.urdf"):
        bodies, joints = _drake_bodies_and_joints(folder / name)
        assert entities <= bodies, (name, sorted(entities - bodies))
        for door in world.metadata["doors"]:  # a door is a revolute joint for Drake too
            assert type(joints[door["joint"]]).__name__ == "RevoluteJoint"


def test_sdf_actors_false_leaves_movers_out_of_the_sdf_only(tmp_path):
    with_actors = _world("cluttered", 2)
    without = _world("cluttered", 2, sdf_actors=False)
    assert with_actors.params["sdf_actors"] is True and without.metadata["params"]["sdf_actors"] is False
    assert without.scene.content_hash() == with_actors.scene.content_hash()  # the same scene...
    assert without.world_id != with_actors.world_id  # ...written differently: another world id
    sdf = etree.fromstring(without.to_sdf().encode(), safe_parser())
    assert sdf.findall(".//actor") == [] and len(etree.fromstring(with_actors.to_sdf().encode(), safe_parser())
                                                 .findall(".//actor")) == 2
    # Movers stay everywhere else: the MJCF and world.json's dynamic_obstacles are unchanged, but for
    # the note on how the SDF carries them: it no longer does.
    assert without.to_mjcf().replace(without.world_id, with_actors.world_id) == with_actors.to_mjcf()
    kept, dropped = with_actors.metadata["dynamic_obstacles"], without.metadata["dynamic_obstacles"]
    assert [m["formats"] for m in kept] == [{"sdf": "actor", "mjcf": "mocap_body", "urdf": None}] * 2
    assert [m["formats"] for m in dropped] == [{"sdf": None, "mjcf": "mocap_body", "urdf": None}] * 2
    assert [dict(m, formats=None) for m in dropped] == [dict(m, formats=None) for m in kept] != []
    folder = without.write(tmp_path, preview=False)
    ok, messages = check_sdf(folder / "world.sdf")
    assert ok, messages
    from worldgen.verify import check_folder
    assert check_folder(folder).ok  # regenerates byte for byte from the recorded params


@pytest.mark.parametrize("generator", names())
def test_pybullet_loads_every_generators_urdf(tmp_path, generator):
    p = need("pybullet")
    world = _world(generator, 0)
    folder = world.write(tmp_path, preview=False)
    client = p.connect(p.DIRECT)
    try:
        body = p.loadURDF(str(folder / "world.urdf"), physicsClientId=client)
        info = {p.getJointInfo(body, j, physicsClientId=client)[12].decode(): p.getJointInfo(body, j, physicsClientId=client)
                for j in range(p.getNumJoints(body, physicsClientId=client))}
        links = set(info) | {p.getBodyInfo(body, physicsClientId=client)[0].decode()}
        assert {e["name"] for e in world.metadata["entities"]} <= links
        for door in world.metadata["doors"]:
            joint = info[door["name"]]  # the leaf's link hangs on its hinge
            assert joint[2] == p.JOINT_REVOLUTE and joint[1].decode() == door["joint"]
            # URDF has no initial angle: its zero is the leaf as it starts, so the limits shift by it.
            lo, hi = door["limits"]
            assert (joint[8], joint[9]) == pytest.approx((lo - door["angle"], hi - door["angle"]), abs=1e-6)
    finally:
        p.disconnect(client)


def test_pybullet_loadsdf_takes_worlds_without_doors_and_rejects_door_worlds(tmp_path):
    """What the README tells pybullet users: loadSDF for door-free worlds, the URDF for door worlds."""
    p = need("pybullet")
    client = p.connect(p.DIRECT)
    try:
        plain = worldgen.generate("cluttered", seed=3).write(tmp_path / "a", sdf_version="1.6", preview=False)
        assert len(p.loadSDF(str(plain / "world.sdf"), physicsClientId=client)) > 0
        door = worldgen.generate("door", seed=3).write(tmp_path / "b", sdf_version="1.6", preview=False)
        with pytest.raises(p.error, match="Cannot load SDF file"):
            p.loadSDF(str(door / "world.sdf"), physicsClientId=client)
    finally:
        p.disconnect(client)
