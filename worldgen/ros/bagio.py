"""Opening a bag and decoding the few message types the run reader needs (for :mod:`worldgen.ros.reader`).

Three costs dominate reading a short bag with rosbags, and each is paid once here rather than per bag:
the typestore (rosbags generates each type's deserialiser on first use: kept per set of definitions,
so a batch reuses it), metadata.yaml (parsed with PyYAML; an uncompressed one-file rosbag2 folder is
then read through its storage file), and decoding whole messages (the fields needed are read from the
CDR bytes by :mod:`worldgen.ros.cdr`, checked against rosbags' decoding on each connection's first
message; a connection where the two differ is decoded by rosbags throughout).
"""

from __future__ import annotations

import functools
import math
import struct
from collections import OrderedDict
from pathlib import Path
from typing import Any, Callable, Optional

import worldgen.ros.cdr as cdr
from worldgen.errors import BagError

__all__ = ["RunMismatchError", "fail", "mismatch", "unreadable", "typestore", "storage", "listed_topics", "bag_metadata",
           "decoder"]


class RunMismatchError(BagError):
    """The bag reads, but its run is not the task's: it starts far from the spawn, or names another world.

    Not a bag that cannot be read: the judge counts it as a failed run, with this reason.
    """


def fail(bag: Path, why: str) -> BagError:
    return BagError(f"bag '{bag}': {why}")


def mismatch(bag: Path, why: str) -> RunMismatchError:
    return RunMismatchError(f"bag '{bag}': {why}")


def unreadable(bag: Path, exc: Exception) -> BagError:
    why = (str(exc).splitlines() or [""])[0][:160]
    return fail(bag, f"cannot be read as a ROS bag ({type(exc).__name__}: {why})")


@functools.lru_cache(maxsize=None)
def typestore(distro: Optional[str]):
    """The release's typestore (Humble or Jazzy, default Jazzy), for bags that carry no definitions."""
    from rosbags.typesys import Stores, get_typestore

    stores = {"humble": Stores.ROS2_HUMBLE, "jazzy": Stores.ROS2_JAZZY}
    return get_typestore(stores.get(distro or "jazzy", Stores.ROS2_JAZZY))


def storage(path: Path) -> tuple[Path, dict[str, Any]]:
    """The path to open and the bag's metadata (``custom``, ``ros_distro``; empty where there is no metadata.yaml)."""
    meta_file = path / "metadata.yaml"
    if not (path.is_dir() and meta_file.is_file()):
        return path, {}
    import yaml

    try:
        info = yaml.load(meta_file.read_text(), Loader=getattr(yaml, "CSafeLoader", yaml.SafeLoader))
        info = info["rosbag2_bagfile_information"]
        files = info.get("relative_file_paths") or []
        single = path / Path(files[0]).name if len(files) == 1 else None
        plain = not info.get("compression_mode") and not info.get("compression_format")
    except (yaml.YAMLError, KeyError, TypeError, IndexError, AttributeError):
        return path, {}  # rosbags reads it and says what is wrong
    meta = {"custom": info.get("custom_data") or {}, "ros_distro": info.get("ros_distro")}
    if single is not None and plain and single.suffix in (".mcap", ".db3") and single.is_file():
        return single, meta
    return path, meta


def listed_topics(path: Path) -> Optional[dict[str, str]]:
    """topic -> type as the bag lists them without a reader: a rosbag2 folder's metadata.yaml, else a .db3's
    ``topics`` table; None where neither can be read. For a bag rosbags cannot open (a definition it cannot
    build, say), this still tells whether any pose topic was there to read."""
    import sqlite3

    import yaml

    meta_file = path / "metadata.yaml"
    try:
        if path.is_dir() and meta_file.is_file():
            info = yaml.safe_load(meta_file.read_text())["rosbag2_bagfile_information"]
            return {str(t["topic_metadata"]["name"]): str(t["topic_metadata"]["type"])
                    for t in info.get("topics_with_message_count") or []}
        if path.is_file() and path.suffix == ".db3":
            with sqlite3.connect(f"file:{path}?mode=ro", uri=True) as db:
                return {str(name): str(kind) for name, kind in db.execute("SELECT name, type FROM topics")}
    except (OSError, yaml.YAMLError, sqlite3.Error, KeyError, TypeError, AttributeError):
        return None
    return None


def bag_metadata(reader) -> dict[str, Any]:
    """The ``custom_data`` and ``ros_distro`` rosbags read from an opened bag, where it has them."""
    out: dict[str, Any] = {"custom": {}, "ros_distro": None}
    for r in getattr(reader, "readers", []):
        meta = getattr(getattr(r, "storage", None), "metadata", None)
        if meta is not None:
            out["custom"].update(getattr(meta, "custom", None) or {})
            out["ros_distro"] = out["ros_distro"] or getattr(meta, "ros_distro", None)
    return out


#: Typestores built from bags' own definitions, by those definitions (and the release's, for bags without).
_STORES: OrderedDict[tuple, Any] = OrderedDict()


def _yaw(q) -> float:
    return math.atan2(2.0 * (q.w * q.z + q.x * q.y), 1.0 - 2.0 * (q.y * q.y + q.z * q.z))


def _t(stamp) -> float:
    return stamp.sec + stamp.nanosec * 1e-9


def _transform(tr) -> cdr.Pose2:
    p, q = tr.transform.translation, tr.transform.rotation
    return _t(tr.header.stamp), tr.header.frame_id, tr.child_frame_id, p.x, p.y, _yaw(q)


def _slow(msgtype: str, msg) -> Any:
    """What :mod:`worldgen.ros.cdr` returns for the type, from rosbags' decoded message."""
    if msgtype == "rosgraph_msgs/msg/Clock":
        return _t(msg.clock)
    if msgtype == "tf2_msgs/msg/TFMessage":
        return [_transform(tr) for tr in msg.transforms]
    if msgtype == "geometry_msgs/msg/TransformStamped":
        return _transform(msg)
    if msgtype == "geometry_msgs/msg/Twist":
        return None, msg.linear.x, msg.linear.y, msg.angular.z
    if msgtype == "geometry_msgs/msg/TwistStamped":
        return _t(msg.header.stamp), msg.twist.linear.x, msg.twist.linear.y, msg.twist.angular.z
    pose = msg.pose.pose if hasattr(msg.pose, "pose") else msg.pose
    child = getattr(msg, "child_frame_id", "")
    return _t(msg.header.stamp), msg.header.frame_id, child, pose.position.x, pose.position.y, _yaw(pose.orientation)


def decoder(reader, conns, distro: Optional[str]) -> Callable[[Any, bytes], Any]:
    """``decode(connection, raw)`` for the connections to read: the CDR fast path where it agrees with rosbags."""
    key = (distro, reader.is2) + tuple(sorted((c.msgtype, c.msgdef.format.name, c.msgdef.data) for c in conns))
    if key not in _STORES:
        _STORES[key] = reader.typestore
        if len(_STORES) > 16:
            _STORES.popitem(last=False)
    _STORES.move_to_end(key)
    store = _STORES[key]
    deserialize = store.deserialize_cdr if reader.is2 else store.deserialize_ros1
    chosen: dict[int, Callable[[bytes], Any]] = {}

    def slow_for(msgtype: str) -> Callable[[bytes], Any]:
        return lambda raw: _slow(msgtype, deserialize(raw, msgtype))

    def decode(conn, raw: bytes) -> Any:
        use = chosen.get(conn.id)
        if use is None:
            slow = slow_for(conn.msgtype)
            value = slow(raw)
            fast = cdr.DECODERS.get(conn.msgtype) if reader.is2 else None
            try:
                agrees = fast is not None and fast(raw) == value
            except (ValueError, IndexError, UnicodeDecodeError, struct.error):
                agrees = False
            chosen[conn.id] = fast if agrees and fast is not None else slow
            return value
        return use(raw)

    return decode
