"""The few fields the run reader needs, read straight from a message's CDR bytes (the ROS 2 wire format).

rosbags decodes a whole message into objects (an Odometry's two 36-double covariances included);
the reader needs a stamp, two frame names and a planar pose. These functions read only those, with
:mod:`struct`, for the standard layouts of nav_msgs/Odometry, tf2_msgs/TFMessage,
geometry_msgs/Twist, TwistStamped and PoseStamped (identical in Humble and Jazzy). The reader
checks each connection's first message against rosbags' own decoding and falls back to it for
a connection where they differ, so a bag with other definitions is still read right.

CDR (XCDR1, as ROS 2's middlewares write it): a 4-byte encapsulation header (byte 1 is 1 for
little-endian, 0 for big-endian), then the fields in order, each aligned to its size counted
from the end of that header; a string is a uint32 length (with its NUL) and its bytes.
"""

from __future__ import annotations

import math
import struct
from typing import Optional

__all__ = ["Pose2", "odometry", "tf_message", "twist", "twist_stamped", "pose_stamped", "clock", "DECODERS"]

#: (stamp s, parent frame, child frame, x, y, yaw)
Pose2 = tuple[float, str, str, float, float, float]


def _order(raw: bytes) -> str:
    if len(raw) < 4 or raw[0] != 0 or raw[1] not in (0, 1):
        raise ValueError("not plain CDR")
    return "<" if raw[1] == 1 else ">"


def _yaw(qx: float, qy: float, qz: float, qw: float) -> float:
    return math.atan2(2.0 * (qw * qz + qx * qy), 1.0 - 2.0 * (qy * qy + qz * qz))


def _header(raw: bytes, o: str, p: int) -> tuple[float, str, int]:
    """stamp (s), frame_id, and the offset after them; ``p`` counts from the start of ``raw``."""
    sec, nsec, n = struct.unpack_from(o + "iII", raw, p)
    frame = raw[p + 12: p + 11 + n].decode()
    return sec + nsec * 1e-9, frame, p + 12 + n


def _string(raw: bytes, o: str, p: int) -> tuple[str, int]:
    p = 4 + ((p - 4 + 3) & ~3)
    (n,) = struct.unpack_from(o + "I", raw, p)
    return raw[p + 4: p + 3 + n].decode(), p + 4 + n


def _pose(raw: bytes, o: str, p: int) -> tuple[float, float, float, int]:
    """x, y, yaw of a Point + Quaternion (or Vector3 + Quaternion) at ``p`` (aligned to 8 here), and the offset after."""
    p = 4 + ((p - 4 + 7) & ~7)
    x, y, _, qx, qy, qz, qw = struct.unpack_from(o + "7d", raw, p)
    return x, y, _yaw(qx, qy, qz, qw), p + 56


def odometry(raw: bytes) -> Pose2:
    o = _order(raw)
    t, frame, p = _header(raw, o, 4)
    child, p = _string(raw, o, p)
    x, y, yaw, _ = _pose(raw, o, p)
    return t, frame, child, x, y, yaw


def pose_stamped(raw: bytes) -> Pose2:
    o = _order(raw)
    t, frame, p = _header(raw, o, 4)
    x, y, yaw, _ = _pose(raw, o, p)
    return t, frame, "", x, y, yaw


def tf_message(raw: bytes) -> list[Pose2]:
    o = _order(raw)
    (count,) = struct.unpack_from(o + "I", raw, 4)
    p, out = 8, []
    for _ in range(count):
        p = 4 + ((p - 4 + 3) & ~3)
        t, parent, p = _header(raw, o, p)
        child, p = _string(raw, o, p)
        x, y, yaw, p = _pose(raw, o, p)
        out.append((t, parent, child, x, y, yaw))
    return out


def twist(raw: bytes) -> tuple[Optional[float], float, float, float]:
    """(None: no stamp, linear x, linear y, angular z)."""
    o = _order(raw)
    vx, vy, _, _, _, wz = struct.unpack_from(o + "6d", raw, 4)
    return None, vx, vy, wz


def twist_stamped(raw: bytes) -> tuple[Optional[float], float, float, float]:
    o = _order(raw)
    t, _, p = _header(raw, o, 4)
    p = 4 + ((p - 4 + 7) & ~7)
    vx, vy, _, _, _, wz = struct.unpack_from(o + "6d", raw, p)
    return t, vx, vy, wz


def clock(raw: bytes) -> float:
    o = _order(raw)
    sec, nsec = struct.unpack_from(o + "iI", raw, 4)
    return sec + nsec * 1e-9


#: message type -> its reader
DECODERS = {
    "nav_msgs/msg/Odometry": odometry,
    "geometry_msgs/msg/PoseStamped": pose_stamped,
    "tf2_msgs/msg/TFMessage": tf_message,
    "geometry_msgs/msg/Twist": twist,
    "geometry_msgs/msg/TwistStamped": twist_stamped,
    "rosgraph_msgs/msg/Clock": clock,
}
