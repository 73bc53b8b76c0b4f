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
  simulator's own pose of the model as the ROS 2 bundle bridges it (every topic's name and type
  is :mod:`worldgen.export.contract`'s).

The bag's receive times (what ``ros2 bag record`` logs) are wall-clock times, a fixed
epoch plus the simulation time: a reader must take times from the header stamps.
The world and task go into the bag's ``custom_data`` metadata (rosbag2 metadata
version 6 and later; ``worldgen.world_id``, ``worldgen.task``, ``worldgen.run``).

:func:`write_run` is a thin function over :class:`BagWriter`, a bag written message by message
as rosbags' own writer writes one (open, add a connection per topic, write, close), for a bag of
other messages: a test's, or a run of another robot.
"""

from __future__ import annotations

import functools
import math
from pathlib import Path
from typing import Any, Callable, Mapping, Optional, Sequence

import numpy as np

from worldgen.errors import ParameterError
from worldgen.export import contract
from worldgen.export.contract import CLOCK, CMD_VEL, CMD_VEL_STAMPED_TYPE, GOAL_POSE, GROUND_TRUTH, ODOM, SCAN, TF, TF_STATIC
from worldgen.ros.deps import require_rosbags

__all__ = ["BagWriter", "write_run", "STORAGES", "DISTROS", "WALL_EPOCH_NS", "DEFAULT_TOPICS"]

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
#: ``topics``' words and the contract's topics they write.
_TOPICS = {"clock": CLOCK, "odom": ODOM, "tf": TF, "cmd_vel": CMD_VEL, "scan": SCAN, "ground_truth": GROUND_TRUTH}


@functools.lru_cache(maxsize=None)
def _store(distro: str):
    """The release's typestore, built once per process (its serialisers are generated code)."""
    from rosbags.typesys import Stores, get_typestore

    return get_typestore(Stores.ROS2_HUMBLE if distro == "humble" else Stores.ROS2_JAZZY)


class BagWriter:
    """A rosbag2 folder written message by message; a context manager (rosbags' ``Writer`` is the model)::

        with BagWriter("runs/r0", metadata={"worldgen.task": "task_0"}) as bag:
            clock = bag.add_connection("/clock")          # the contract's type for a topic it knows
            bag.write(clock, WALL_EPOCH_NS, bag.types["rosgraph_msgs/msg/Clock"](clock=...))

    ``path`` must not exist; ``storage`` is one of :data:`STORAGES`, ``distro`` (whose message definitions
    the bag carries) one of :data:`DISTROS`; ``metadata`` goes into the bag's ``custom_data``. Messages are
    serialised here (CDR, the release's typestore) and must be written in receive-time order.
    """

    def __init__(self, path, *, storage: str = "mcap", distro: str = "jazzy",
                 metadata: Optional[Mapping[str, str]] = None):
        require_rosbags()
        if storage not in STORAGES:
            raise ParameterError(f"parameter 'storage' must be one of {', '.join(STORAGES)}, got {storage!r}")
        if distro not in DISTROS:
            raise ParameterError(f"parameter 'distro' must be one of {', '.join(DISTROS)}, got {distro!r}")
        self.path = Path(path)
        if self.path.exists():
            raise ParameterError(f"parameter 'path': '{self.path}' exists already; a bag is written into a new folder")
        self.storage, self.distro = storage, distro
        self.typestore = _store(distro)
        self._metadata = {str(k): str(v) for k, v in (metadata or {}).items()}
        self._writer: Any = None

    @property
    def types(self) -> dict[str, Any]:
        """Message classes by type name (``types["nav_msgs/msg/Odometry"]``), of the bag's ROS 2 release."""
        return self.typestore.types

    def open(self) -> BagWriter:
        from rosbags.rosbag2 import StoragePlugin, Writer

        plugin = StoragePlugin.MCAP if self.storage == "mcap" else StoragePlugin.SQLITE3
        writer = Writer(self.path, version=8, storage_plugin=plugin)
        for key, value in self._metadata.items():
            writer.set_custom_data(key, value)
        writer.open()
        self._writer = writer
        return self

    def add_connection(self, topic: str, msgtype: Optional[str] = None):
        """A connection for ``topic``: ``msgtype``, else the type :mod:`worldgen.export.contract` gives it."""
        if self._writer is None:
            raise ParameterError(f"bag '{self.path}' is not open: add connections inside 'with BagWriter(...)'")
        if msgtype is None:
            known = {t.name: t.ros_type for t in contract.TOPICS}
            if topic not in known:
                raise ParameterError(f"parameter 'msgtype' is needed for {topic}, a topic worldgen.export.contract does not name")
            msgtype = known[topic]
        return self._writer.add_connection(topic, msgtype, typestore=self.typestore)

    def write(self, connection, time_ns: int, message) -> None:
        """``message`` on ``connection``, received at ``time_ns`` (wall clock, ns)."""
        if self._writer is None:
            raise ParameterError(f"bag '{self.path}' is not open: write inside 'with BagWriter(...)'")
        self._writer.write(connection, time_ns, self.typestore.serialize_cdr(message, connection.msgtype))

    def close(self) -> None:
        """Finish the bag (its metadata.yaml); a second close does nothing."""
        if self._writer is not None:
            writer, self._writer = self._writer, None
            writer.close()

    def __enter__(self) -> BagWriter:
        return self.open()

    def __exit__(self, *exc) -> None:
        self.close()


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


def _check(trajectory, topics) -> np.ndarray:
    traj = np.asarray(trajectory, dtype=float)
    if traj.ndim != 2 or traj.shape[1] != 4 or len(traj) < 1 or not np.all(np.isfinite(traj)):
        raise ParameterError(f"parameter 'trajectory' must be a finite (n, 4) array t, x, y, yaw, got shape {traj.shape}")
    if np.any(np.diff(traj[:, 0]) < 0) or traj[0, 0] < 0:
        raise ParameterError("parameter 'trajectory' must have non-decreasing, non-negative times")
    unknown = sorted(set(topics) - set(_TOPICS))
    if unknown:
        raise ParameterError(f"parameter 'topics': unknown {', '.join(unknown)}; allowed: {', '.join(_TOPICS)}")
    return traj


def _receive_ns(t: float) -> int:
    return WALL_EPOCH_NS + int(round(t * 1e9))


class _Messages:
    """The run's messages, built with one release's message classes: stamps, headers, transforms, odometry."""

    def __init__(self, types: Mapping[str, Any], base_frame: str):
        self.T, self.base_frame = types, base_frame
        self.zero6 = np.zeros(36)  # covariances: the same unknown for every message

    def stamp(self, t: float):
        ns = int(round(t * 1e9))
        return self.T["builtin_interfaces/msg/Time"](sec=ns // 10**9, nanosec=ns % 10**9)

    def header(self, t: float, frame: str):
        return self.T["std_msgs/msg/Header"](stamp=self.stamp(t), frame_id=frame)

    def twist(self, v: float, w: float):
        V = self.T["geometry_msgs/msg/Vector3"]
        return self.T["geometry_msgs/msg/Twist"](linear=V(x=v, y=0.0, z=0.0), angular=V(x=0.0, y=0.0, z=w))

    def pose(self, p):
        T = self.T
        return T["geometry_msgs/msg/Pose"](position=T["geometry_msgs/msg/Point"](x=p[0], y=p[1], z=0.0),
                                           orientation=T["geometry_msgs/msg/Quaternion"](*_quat(p[2])))

    def tf(self, t: float, parent: str, child: str, p):
        T = self.T
        return T["geometry_msgs/msg/TransformStamped"](
            header=self.header(t, parent), child_frame_id=child,
            transform=T["geometry_msgs/msg/Transform"](translation=T["geometry_msgs/msg/Vector3"](x=p[0], y=p[1], z=0.0),
                                                        rotation=T["geometry_msgs/msg/Quaternion"](*_quat(p[2]))))

    def tf_message(self, transforms: list):
        return self.T[TF.ros_type](transforms=transforms)

    def odometry(self, t: float, frame: str, p, v: float, w: float):
        T, zero6 = self.T, self.zero6
        return T[ODOM.ros_type](
            header=self.header(t, frame), child_frame_id=self.base_frame,
            pose=T["geometry_msgs/msg/PoseWithCovariance"](pose=self.pose(p), covariance=zero6),
            twist=T["geometry_msgs/msg/TwistWithCovariance"](twist=self.twist(v, w), covariance=zero6))

    def scan(self, t: float, ranges: np.ndarray, angles: tuple[float, float, float, float]):
        amin, amax, rmin, rmax = angles
        inc = (amax - amin) / max(len(ranges) - 1, 1)
        return self.T[SCAN.ros_type](
            header=self.header(t, "base_scan"), angle_min=amin, angle_max=amax, angle_increment=inc, time_increment=0.0,
            scan_time=0.0, range_min=rmin, range_max=rmax, ranges=ranges, intensities=np.zeros(0, dtype=np.float32))


def _samples(m: _Messages, traj: np.ndarray, cmds: np.ndarray, spawn3, topics, drift: float, map_odom: bool,
             scan, scan_angles) -> list[tuple[float, str, Any]]:
    """(simulation time, topic, message) of every per-sample message, in the order a recorder gets them."""
    v_of = np.interp(traj[:, 0], cmds[:, 0], cmds[:, 1]) if len(cmds) else np.zeros(len(traj))
    w_of = np.interp(traj[:, 0], cmds[:, 0], cmds[:, 2]) if len(cmds) else np.zeros(len(traj))
    out: list[tuple[float, str, Any]] = []
    travelled, prev = 0.0, None
    for k, (t, x, y, yaw) in enumerate(traj):
        truth = (x, y, yaw)
        if prev is not None:
            travelled += math.hypot(x - prev[0], y - prev[1])
        prev = truth
        # The odometry is the true motion since the spawn, turned by the heading error accumulated so far.
        rel, bias = _relative(spawn3, truth), drift * travelled
        odom = (math.cos(bias) * rel[0] - math.sin(bias) * rel[1], math.sin(bias) * rel[0] + math.cos(bias) * rel[1],
                rel[2] + bias)
        if "clock" in topics:
            out.append((t, CLOCK.name, m.T[CLOCK.ros_type](clock=m.stamp(t))))
        if "odom" in topics:
            out.append((t, ODOM.name, m.odometry(t, "odom", odom, float(v_of[k]), float(w_of[k]))))
        if "ground_truth" in topics:
            out.append((t, GROUND_TRUTH.name, m.odometry(t, "map", truth, float(v_of[k]), float(w_of[k]))))
        if "tf" in topics:
            transforms = [m.tf(t, "odom", m.base_frame, odom)]
            if drift and map_odom:
                # The localisation's map -> odom: truth = map_odom o odom, so map_odom = truth o odom^-1.
                transforms.insert(0, m.tf(t, "map", "odom", _compose(truth, _relative(odom, (0.0, 0.0, 0.0)))))
            out.append((t, TF.name, m.tf_message(transforms)))
        if scan is not None and "scan" in topics:
            out.append((t, SCAN.name, m.scan(t, np.asarray(scan(x, y, yaw), dtype=np.float32), scan_angles)))
    return out


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
    traj = _check(trajectory, topics)
    custom = {f"worldgen.{k}": str(v) for k, v in (("world_id", world_id), ("task", task), ("run", run)) if v is not None}
    bag = BagWriter(path, storage=storage, distro=distro, metadata=custom)
    spawn3 = tuple(float(v) for v in (spawn if spawn is not None else traj[0, 1:4]))
    cmds = _commands(traj) if commands is None else np.asarray(commands, dtype=float).reshape(-1, 3)
    m = _Messages(bag.types, base_frame)
    out = _samples(m, traj, cmds, spawn3, topics, drift, map_odom, scan, scan_angles)
    if "cmd_vel" in topics:
        out += [(float(t), CMD_VEL.name, m.T[CMD_VEL_STAMPED_TYPE](header=m.header(float(t), base_frame),
                                                                    twist=m.twist(float(v), float(w)))
                 if stamped_cmd else m.twist(float(v), float(w))) for t, v, w in cmds]
    if goal is not None:
        gt_, gx, gy, gyaw = (float(v) for v in goal)
        out.append((gt_, GOAL_POSE.name, m.T[GOAL_POSE.ros_type](header=m.header(gt_, "map"), pose=m.pose((gx, gy, gyaw)))))
    # Messages go out in receive-time order, as a recorder writes them (a stable sort: ties keep their order).
    timed = sorted(((_receive_ns(t) + RECEIVE_LATENCY_NS, name, msg) for t, name, msg in out), key=lambda item: item[0])
    static = "tf" in topics and not drift and map_odom
    types = {CMD_VEL.name: CMD_VEL_STAMPED_TYPE if stamped_cmd else CMD_VEL.ros_type}
    with bag:
        conns = {name: bag.add_connection(name, types.get(name))
                 for name in sorted({item[1] for item in timed} | ({TF_STATIC.name} if static else set()))}
        if static:
            t0 = float(traj[0, 0])
            bag.write(conns[TF_STATIC.name], _receive_ns(t0), m.tf_message([m.tf(t0, "map", "odom", spawn3)]))
        for when, name, msg in timed:
            bag.write(conns[name], when, msg)
    return bag.path
