"""The CDR fast path reads the same fields rosbags decodes, in both byte orders, and the reader falls back to
rosbags on a connection where the two disagree."""

import math

import numpy as np
import pytest

import worldgen.ros.cdr as cdr

rosbags = pytest.importorskip("rosbags")


@pytest.fixture(scope="module", params=["humble", "jazzy"])
def store(request):
    from rosbags.typesys import Stores, get_typestore
    return get_typestore(Stores.ROS2_HUMBLE if request.param == "humble" else Stores.ROS2_JAZZY)


def _msgs(store):
    T = store.types
    stamp = T["builtin_interfaces/msg/Time"](sec=12, nanosec=345_000_000)

    def header(frame):
        return T["std_msgs/msg/Header"](stamp=stamp, frame_id=frame)

    yaw = 2.5
    q = T["geometry_msgs/msg/Quaternion"](x=0.0, y=0.0, z=math.sin(yaw / 2), w=math.cos(yaw / 2))
    point = T["geometry_msgs/msg/Point"](x=1.25, y=-3.5, z=0.1)
    vec = T["geometry_msgs/msg/Vector3"](x=1.25, y=-3.5, z=0.1)
    pose = T["geometry_msgs/msg/Pose"](position=point, orientation=q)
    twist = T["geometry_msgs/msg/Twist"](linear=T["geometry_msgs/msg/Vector3"](x=0.5, y=0.01, z=0.0),
                                         angular=T["geometry_msgs/msg/Vector3"](x=0.0, y=0.0, z=-0.3))
    cov = np.arange(36, dtype=float)
    tf = T["geometry_msgs/msg/TransformStamped"](header=header("odom"), child_frame_id="base_footprint",
                                                 transform=T["geometry_msgs/msg/Transform"](translation=vec, rotation=q))
    tf2 = T["geometry_msgs/msg/TransformStamped"](header=header("a_longer_frame_name"), child_frame_id="b",
                                                  transform=T["geometry_msgs/msg/Transform"](translation=vec, rotation=q))
    return yaw, {
        "nav_msgs/msg/Odometry": T["nav_msgs/msg/Odometry"](
            header=header("odom"), child_frame_id="base_link",
            pose=T["geometry_msgs/msg/PoseWithCovariance"](pose=pose, covariance=cov),
            twist=T["geometry_msgs/msg/TwistWithCovariance"](twist=twist, covariance=cov)),
        "geometry_msgs/msg/PoseStamped": T["geometry_msgs/msg/PoseStamped"](header=header("map"), pose=pose),
        "tf2_msgs/msg/TFMessage": T["tf2_msgs/msg/TFMessage"](transforms=[tf, tf2, tf]),
        "geometry_msgs/msg/Twist": twist,
        "geometry_msgs/msg/TwistStamped": T["geometry_msgs/msg/TwistStamped"](header=header("base"), twist=twist),
        "rosgraph_msgs/msg/Clock": T["rosgraph_msgs/msg/Clock"](clock=stamp),
    }


@pytest.mark.parametrize("little_endian", [True, False])
def test_the_fast_path_reads_what_rosbags_decodes(store, little_endian):
    yaw, msgs = _msgs(store)
    t = 12.345
    for msgtype, msg in msgs.items():
        raw = bytes(store.serialize_cdr(msg, msgtype, little_endian=little_endian))
        got = cdr.DECODERS[msgtype](raw)
        if msgtype == "nav_msgs/msg/Odometry":
            assert got[1:3] == ("odom", "base_link") and got[3:5] == (1.25, -3.5) and got[5] == pytest.approx(yaw)
        elif msgtype == "geometry_msgs/msg/PoseStamped":
            assert got[1:5] == ("map", "", 1.25, -3.5) and got[5] == pytest.approx(yaw)
        elif msgtype == "tf2_msgs/msg/TFMessage":
            assert [g[1:5] for g in got] == [("odom", "base_footprint", 1.25, -3.5), ("a_longer_frame_name", "b", 1.25, -3.5),
                                             ("odom", "base_footprint", 1.25, -3.5)]
        elif msgtype == "geometry_msgs/msg/Twist":
            assert got == (None, 0.5, 0.01, -0.3)
        elif msgtype == "geometry_msgs/msg/TwistStamped":
            assert got[1:] == (0.5, 0.01, -0.3)
        if msgtype != "geometry_msgs/msg/Twist":
            stamp = got if isinstance(got, float) else (got[0][0] if isinstance(got, list) else got[0])
            assert stamp == pytest.approx(t, abs=1e-12)


def test_a_connection_whose_fast_path_disagrees_is_read_by_rosbags(tmp_path, monkeypatch):
    from support.runs import along, small_world, write_bag

    from worldgen.ros import read_run

    world = small_world(tmp_path / "w")
    truth = along(world)
    bag = write_bag(tmp_path / "run", world, truth)
    wrong = dict(cdr.DECODERS)
    wrong["tf2_msgs/msg/TFMessage"] = lambda raw: [(0.0, "odom", "base_footprint", 9.0, 9.0, 0.0)]
    monkeypatch.setattr(cdr, "DECODERS", wrong)
    run = read_run(bag, world)
    np.testing.assert_allclose(run.trajectory[:, :3], truth[:, :3], atol=1e-9)
