"""Write a run as a real ROS 2 bag, with the topics a Gazebo + nav2 run records (optional extra ``ros``).

Usage (an example that runs is in :mod:`worldgen.ros`)::

    write_run("runs/r0", trajectory, spawn=(x, y, yaw), world_id="cluttered-s0-...", task="t0")

``trajectory`` is the robot's true pose over simulation time, an (n, 4) array of
``t, x, y, yaw`` in the world frame (world.json's frame, which is also nav2's
``map`` frame: map.yaml's origin is in world coordinates). The bag holds what a
ROS 2 run gives, each message stamped with simulation time in its header:

- ``/clock`` (rosgraph_msgs/Clock) at every sample;
- ``/odom`` (nav_msgs/Odometry, ``odom`` -> ``base_footprint``): the pose relative
  to the spawn, so it starts at zero as a wheel odometry does; ``drift`` (rad per
  metre driven) bends it away from the truth as a real odometry drifts;
- ``/tf``: ``odom`` -> ``base_footprint`` at every sample, and ``map`` -> ``odom``
  (the localisation's correction: the spawn composed with the drift so far) at
  every sample when the odometry drifts, else once on ``/tf_static``;
- ``/cmd_vel`` (geometry_msgs/Twist, or TwistStamped with ``stamped_cmd=True`` as
  Jazzy's nav2 may send): ``v, w`` rows from ``commands`` or read off the trajectory;
- optionally ``/scan`` (sensor_msgs/LaserScan) from a ``scan`` callable
  ``(x, y, yaw) -> ranges`` and ``/ground_truth`` (nav_msgs/Odometry in ``map``), the
  simulator's own pose of the model as ros_gz_bridge bridges ``gz.msgs.Odometry``.

The bag's receive times (what ``ros2 bag record`` logs) are wall-clock times, a fixed
epoch plus the simulation time: a reader must take times from the header stamps.
The world and task go into the bag's ``custom_data`` metadata (rosbag2 metadata
version 6 and later; ``worldgen.world_id``, ``worldgen.task``, ``worldgen.run``).
"""

from __future__ import annotations

import functools
import math
from pathlib import Path
from typing import Callable, Optional, Sequence

import numpy as np

from worldgen.errors import ParameterError
from worldgen.ros.deps import require_rosbags

__all__ = ["write_run", "STORAGES", "DISTROS", "WALL_EPOCH_NS", "DEFAULT_TOPICS"]

#: Storage plugins a bag can be written with.
STORAGES = ("sqlite3", "mcap")
#: ROS 2 releases whose message definitions a bag can carry.
DISTROS = ("humble", "jazzy")
#: Receive times are this wall-clock instant (2023-11-14T22:13:20Z) plus the simulation time: fixed, so the
#: same run gives the same bytes.
WALL_EPOCH_NS = 1_700_000_000 * 10**9
#: What a run records unless told otherwise.
DEFAULT_TOPICS = ("clock", "odom", "tf", "cmd_vel")
#: What a message takes from its stamp to the recorder.
RECEIVE_LATENCY_NS = 2_000_000
_ALL_TOPICS = ("clock", "odom", "tf", "cmd_vel", "scan", "ground_truth")


@functools.lru_cache(maxsize=None)
def _store(distro: str):
    """The release's typestore, built once per process (its serialisers are generated code)."""
    from rosbags.typesys import Stores, get_typestore

    return get_typestore(Stores.ROS2_HUMBLE if distro == "humble" else Stores.ROS2_JAZZY)


def _quat(yaw: float) -> tuple[float, float, float, float]:
    return 0.0, 0.0, math.sin(yaw / 2.0), math.cos(yaw / 2.0)


def _compose(a, b):
    """Pose a then pose b (each x, y, yaw): b expressed in a's frame, returned in a's parent frame."""
    ca, sa = math.cos(a[2]), math.sin(a[2])
    return a[0] + ca * b[0] - sa * b[1], a[1] + sa * b[0] + ca * b[1], a[2] + b[2]


def _relative(a, b):
    """b expressed in a's frame (the inverse of :func:`_compose`)."""
    ca, sa = math.cos(a[2]), math.sin(a[2])
    dx, dy = b[0] - a[0], b[1] - a[1]
    return ca * dx + sa * dy, -sa * dx + ca * dy, b[2] - a[2]


def _commands(traj: np.ndarray) -> np.ndarray:
    """(n, 3) ``t, v, w``: the twist that drives each sample to the next (zero after the last)."""
    out = np.zeros((len(traj), 3))
    out[:, 0] = traj[:, 0]
    if len(traj) > 1:
        dt = np.diff(traj[:, 0])
        dt[dt <= 0] = np.inf
        d = np.diff(traj[:, 1:3], axis=0)
        yaw = traj[:-1, 3]
        out[:-1, 1] = (d[:, 0] * np.cos(yaw) + d[:, 1] * np.sin(yaw)) / dt
        out[:-1, 2] = (np.angle(np.exp(1j * np.diff(traj[:, 3])))) / dt
    return out


def _check(trajectory, topics, storage, distro) -> np.ndarray:
    traj = np.asarray(trajectory, dtype=float)
    if traj.ndim != 2 or traj.shape[1] != 4 or len(traj) < 1 or not np.all(np.isfinite(traj)):
        raise ParameterError(f"parameter 'trajectory' must be a finite (n, 4) array t, x, y, yaw, got shape {traj.shape}")
    if np.any(np.diff(traj[:, 0]) < 0) or traj[0, 0] < 0:
        raise ParameterError("parameter 'trajectory' must have non-decreasing, non-negative times")
    if storage not in STORAGES:
        raise ParameterError(f"parameter 'storage' must be one of {', '.join(STORAGES)}, got {storage!r}")
    if distro not in DISTROS:
        raise ParameterError(f"parameter 'distro' must be one of {', '.join(DISTROS)}, got {distro!r}")
    unknown = sorted(set(topics) - set(_ALL_TOPICS))
    if unknown:
        raise ParameterError(f"parameter 'topics': unknown {', '.join(unknown)}; allowed: {', '.join(_ALL_TOPICS)}")
    return traj


# long: every topic's messages written in one pass over the trajectory, inside one writer context
def write_run(path, trajectory, *, spawn: Optional[Sequence[float]] = None, commands=None,
              topics: Sequence[str] = DEFAULT_TOPICS, storage: str = "mcap", distro: str = "jazzy",
              drift: float = 0.0, scan: Optional[Callable[[float, float, float], np.ndarray]] = None,
              scan_angles: tuple[float, float, float, float] = (-math.pi, math.pi, 0.05, 12.0),
              stamped_cmd: bool = False, base_frame: str = "base_footprint",
              world_id: Optional[str] = None, task: Optional[str] = None, run: Optional[str] = None,
              goal: Optional[Sequence[float]] = None, map_odom: bool = True) -> Path:
    """Write ``trajectory`` as a rosbag2 folder at ``path`` (must not exist); returns the folder.

    ``commands`` is an (m, 3) ``t, v, w`` array (default: read off the trajectory); ``goal``
    ``(t, x, y, yaw)`` adds the goal sent at time t on ``/goal_pose`` (PoseStamped in ``map``, as RViz sends it);
    ``map_odom=False`` leaves ``map`` -> ``odom`` out (no localisation running: odometry only);
    ``scan_angles`` is LaserScan's ``angle_min, angle_max, range_min, range_max``.
    """
    require_rosbags()
    from rosbags.rosbag2 import StoragePlugin, Writer

    traj = _check(trajectory, topics, storage, distro)
    spawn3 = tuple(float(v) for v in (spawn if spawn is not None else traj[0, 1:4]))
    cmds = _commands(traj) if commands is None else np.asarray(commands, dtype=float).reshape(-1, 3)
    ts = _store(distro)
    T = ts.types
    Header, Time = T["std_msgs/msg/Header"], T["builtin_interfaces/msg/Time"]
    Vector3, Quaternion = T["geometry_msgs/msg/Vector3"], T["geometry_msgs/msg/Quaternion"]
    Point, Pose = T["geometry_msgs/msg/Point"], T["geometry_msgs/msg/Pose"]
    Twist = T["geometry_msgs/msg/Twist"]
    zero6 = np.zeros(36)

    def stamp(t: float):
        ns = int(round(t * 1e9))
        return Time(sec=ns // 10**9, nanosec=ns % 10**9)

    def header(t: float, frame: str):
        return Header(stamp=stamp(t), frame_id=frame)

    def tf(t: float, parent: str, child: str, p):
        return T["geometry_msgs/msg/TransformStamped"](
            header=header(t, parent), child_frame_id=child,
            transform=T["geometry_msgs/msg/Transform"](translation=Vector3(x=p[0], y=p[1], z=0.0),
                                                        rotation=Quaternion(*_quat(p[2]))))

    def odometry(t: float, frame: str, p, v: float, w: float):
        return T["nav_msgs/msg/Odometry"](
            header=header(t, frame), child_frame_id=base_frame,
            pose=T["geometry_msgs/msg/PoseWithCovariance"](
                pose=Pose(position=Point(x=p[0], y=p[1], z=0.0), orientation=Quaternion(*_quat(p[2]))), covariance=zero6),
            twist=T["geometry_msgs/msg/TwistWithCovariance"](
                twist=Twist(linear=Vector3(x=v, y=0.0, z=0.0), angular=Vector3(x=0.0, y=0.0, z=w)), covariance=zero6))

    path = Path(path)
    if path.exists():
        raise ParameterError(f"parameter 'path': '{path}' exists already; a bag is written into a new folder")
    plugin = StoragePlugin.MCAP if storage == "mcap" else StoragePlugin.SQLITE3
    # Messages go out in receive-time order, as a recorder writes them: gather (time, order, topic, msg) first.
    out: list[tuple[int, int, str, object]] = []

    def put(t: float, topic: str, msg) -> None:
        out.append((WALL_EPOCH_NS + int(round(t * 1e9)) + RECEIVE_LATENCY_NS, len(out), topic, msg))

    v_of = np.interp(traj[:, 0], cmds[:, 0], cmds[:, 1]) if len(cmds) else np.zeros(len(traj))
    w_of = np.interp(traj[:, 0], cmds[:, 0], cmds[:, 2]) if len(cmds) else np.zeros(len(traj))
    odom = (0.0, 0.0, 0.0)
    travelled = 0.0
    prev = None
    for k, (t, x, y, yaw) in enumerate(traj):
        truth = (x, y, yaw)
        if prev is not None:
            travelled += math.hypot(x - prev[0], y - prev[1])
        prev = truth
        # The odometry is the true motion since the spawn, turned by the heading error accumulated so far.
        rel = _relative(spawn3, truth)
        bias = drift * travelled
        odom = (math.cos(bias) * rel[0] - math.sin(bias) * rel[1], math.sin(bias) * rel[0] + math.cos(bias) * rel[1],
                rel[2] + bias)
        if "clock" in topics:
            put(t, "/clock", T["rosgraph_msgs/msg/Clock"](clock=stamp(t)))
        if "odom" in topics:
            put(t, "/odom", odometry(t, "odom", odom, float(v_of[k]), float(w_of[k])))
        if "ground_truth" in topics:
            put(t, "/ground_truth", odometry(t, "map", truth, float(v_of[k]), float(w_of[k])))
        if "tf" in topics:
            transforms = [tf(t, "odom", base_frame, odom)]
            if drift and map_odom:
                # The localisation's map -> odom: truth = map_odom o odom, so map_odom = truth o odom^-1.
                inv = _relative(odom, (0.0, 0.0, 0.0))
                transforms.insert(0, tf(t, "map", "odom", _compose(truth, inv)))
            put(t, "/tf", T["tf2_msgs/msg/TFMessage"](transforms=transforms))
        if scan is not None and "scan" in topics:
            amin, amax, rmin, rmax = scan_angles
            ranges = np.asarray(scan(x, y, yaw), dtype=np.float32)
            inc = (amax - amin) / max(len(ranges) - 1, 1)
            put(t, "/scan", T["sensor_msgs/msg/LaserScan"](
                header=header(t, "base_scan"), angle_min=amin, angle_max=amax, angle_increment=inc, time_increment=0.0,
                scan_time=0.0, range_min=rmin, range_max=rmax, ranges=ranges, intensities=np.zeros(0, dtype=np.float32)))
    if "cmd_vel" in topics:
        for t, v, w in cmds:
            twist = Twist(linear=Vector3(x=float(v), y=0.0, z=0.0), angular=Vector3(x=0.0, y=0.0, z=float(w)))
            put(float(t), "/cmd_vel", T["geometry_msgs/msg/TwistStamped"](header=header(float(t), base_frame), twist=twist)
                if stamped_cmd else twist)
    if goal is not None:
        gt_, gx, gy, gyaw = (float(v) for v in goal)
        put(gt_, "/goal_pose", T["geometry_msgs/msg/PoseStamped"](
            header=header(gt_, "map"), pose=Pose(position=Point(x=gx, y=gy, z=0.0), orientation=Quaternion(*_quat(gyaw)))))
    static = "tf" in topics and not drift and map_odom
    types = {"/clock": "rosgraph_msgs/msg/Clock", "/odom": "nav_msgs/msg/Odometry", "/tf": "tf2_msgs/msg/TFMessage",
             "/tf_static": "tf2_msgs/msg/TFMessage", "/scan": "sensor_msgs/msg/LaserScan",
             "/ground_truth": "nav_msgs/msg/Odometry", "/goal_pose": "geometry_msgs/msg/PoseStamped",
             "/cmd_vel": "geometry_msgs/msg/TwistStamped" if stamped_cmd else "geometry_msgs/msg/Twist"}
    out.sort(key=lambda m: (m[0], m[1]))
    writer = Writer(path, version=8, storage_plugin=plugin)
    for key, value in (("world_id", world_id), ("task", task), ("run", run)):
        if value is not None:
            writer.set_custom_data(f"worldgen.{key}", str(value))
    with writer:
        conns = {}
        for topic in sorted({m[2] for m in out} | ({"/tf_static"} if static else set())):
            conns[topic] = writer.add_connection(topic, types[topic], typestore=ts)
        if static:
            t0 = float(traj[0, 0])
            msg = T["tf2_msgs/msg/TFMessage"](transforms=[tf(t0, "map", "odom", spawn3)])
            writer.write(conns["/tf_static"], WALL_EPOCH_NS + int(round(t0 * 1e9)), ts.serialize_cdr(msg, types["/tf_static"]))
        for when, _, topic, msg in out:
            writer.write(conns[topic], when, ts.serialize_cdr(msg, types[topic]))
    return path
