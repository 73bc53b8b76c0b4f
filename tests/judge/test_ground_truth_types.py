"""`/ground_truth` has one type (the contract's nav_msgs/Odometry), and the judge still reads the others: a bag
whose ground truth is a tf2_msgs/TFMessage (ros_gz_bridge's Pose_V) with the same poses is judged the same."""

from __future__ import annotations

import math

import pytest
from support.runs import along, small_world, toward, write_bag

from worldgen import oracles
from worldgen.export.contract import GROUND_TRUTH, TF

pytest.importorskip("rosbags")


def _as_tf_message(src, dst):
    """A copy of the bag ``src`` at ``dst`` with every /ground_truth Odometry turned into a TFMessage holding the
    same pose (map -> the Odometry's child frame), stamp and receive time; every other message as it was."""
    from rosbags.highlevel import AnyReader

    from worldgen.ros.reader import peek_metadata
    from worldgen.ros.writer import BagWriter

    with BagWriter(dst, metadata=peek_metadata(src)) as bag:
        T = bag.types
        with AnyReader([src], default_typestore=bag.typestore) as reader:
            conns = {c.topic: bag.add_connection(c.topic, TF.ros_type if c.topic == GROUND_TRUTH.name else c.msgtype)
                     for c in sorted(reader.connections, key=lambda c: c.topic)}
            for conn, when, raw in reader.messages():
                msg = reader.deserialize(raw, conn.msgtype)
                if conn.topic == GROUND_TRUTH.name:
                    assert conn.msgtype == GROUND_TRUTH.ros_type == "nav_msgs/msg/Odometry"
                    p = msg.pose.pose
                    msg = T[TF.ros_type](transforms=[T["geometry_msgs/msg/TransformStamped"](
                        header=msg.header, child_frame_id=msg.child_frame_id,
                        transform=T["geometry_msgs/msg/Transform"](
                            translation=T["geometry_msgs/msg/Vector3"](x=p.position.x, y=p.position.y, z=p.position.z),
                            rotation=p.orientation))])
                bag.write(conns[conn.topic], when, msg)
    return dst


@pytest.fixture(scope="module")
def setup(tmp_path_factory):
    root = tmp_path_factory.mktemp("truth")
    world = small_world(root / "worlds")
    obstacle = next(e for e in oracles.load(world).meta["entities"] if e["role"] == "obstacle")
    bags = {}
    for name, traj in (("clean", along(world)), ("crash", toward(world, obstacle["pose"][:2]))):
        # No /tf and no /odom: the ground truth is the only pose source the judge can take.
        odometry = write_bag(root / f"{name}-odometry", world, traj, topics=("clock", "cmd_vel", "ground_truth"),
                             run=f"{name}odometry")
        bags[name] = (odometry, _as_tf_message(odometry, root / f"{name}-tf"))
    return world, bags


def test_the_writer_and_the_contract_agree_on_the_ground_truths_type(setup):
    from worldgen.ros import read_run

    world, bags = setup
    odometry, tf = bags["clean"]
    a, b = read_run(odometry, world), read_run(tf, world)
    assert a.topics[GROUND_TRUTH.name] == "nav_msgs/msg/Odometry" and b.topics[GROUND_TRUTH.name] == TF.ros_type
    assert a.source == b.source == "ground_truth"
    assert a.trajectory.shape == b.trajectory.shape and (a.trajectory == b.trajectory).all()


@pytest.mark.parametrize("name", ["clean", "crash"])
def test_a_tf_message_and_an_odometry_ground_truth_are_judged_the_same(setup, name):
    from worldgen.judge import judge

    world, bags = setup
    odometry, tf = (judge([bag], world=world).report["runs"][0] for bag in bags[name])
    for row in (odometry, tf):
        assert row["source"] == "ground_truth"
        row.pop("bag")
        row.pop("run")
    assert odometry["outcome"] == ("success" if name == "clean" else "failure")
    assert odometry.keys() == tf.keys()
    for key, value in odometry.items():
        if isinstance(value, float) and math.isnan(value):
            assert math.isnan(tf[key]), key
        else:
            assert tf[key] == value, key
