"""Read a recorded ROS 2 run from a bag into the oracles' trajectory, streaming (optional extra ``ros``).

Usage (an example that runs is in :mod:`worldgen.ros`)::

    run = read_run("runs/r0", "worlds/cluttered-s0-1f3a9c0b")
    run.trajectory            # (n, 4) t, x, y, yaw in the world frame, t in simulation seconds
    run.source, run.start     # which pose source was used, and where the run was taken to start

A bag is a rosbag2 folder (metadata.yaml plus its storage files), a single ``.mcap`` or
``.db3`` file, or a ROS 1 ``.bag``; read with ``rosbags`` (pure Python, no ROS install).
The bag's own message definitions are used where it carries them, else the release's
(``distro``, default Jazzy; the messages read here have the same layout in Humble and Jazzy).

The robot's pose comes from the first source the bag has, in this order:

1. ``ground_truth`` - a pose topic bridged from the simulator (``pose_topic``, default
   ``/ground_truth``): nav_msgs/Odometry (``gz.msgs.Odometry``), geometry_msgs PoseStamped,
   PoseWithCovarianceStamped or TransformStamped (``gz.msgs.Pose``), or tf2_msgs/TFMessage
   (``gz.msgs.Pose_V``; the transform whose child frame is ``model``, else the first);
2. ``tf`` - the chain ``map`` -> ``odom`` -> base (``base_footprint``, else ``base_link``) on
   ``/tf`` and ``/tf_static``; a dynamic map -> odom is interpolated at each odom -> base stamp
   (held before its first and after its last stamp);
3. ``odom`` - ``/odom`` composed with the task's spawn pose: odometry drifts without
   bound, and the run says so (``drift_bounded`` False).

Times are header stamps (simulation time). Unstamped messages (Twist, action topics) get
the simulation time of their receive time, through the latest stamped message before them.
Where the run starts (``start``): ``command`` (the first non-zero ``/cmd_vel``, default),
``goal`` (the first goal sent: ``/goal_pose`` or nav2's ``navigate_to_pose`` action topics),
``motion`` (the first 0.1 m of motion, as the BARN Challenge starts its clock) or ``bag``
(the first pose). The trajectory begins with the pose at the start, interpolated.

Nothing but pose samples is kept: a few floats per message, decimated to at most one
sample per ``min_dt`` seconds; message objects are dropped as they are read.
"""

from __future__ import annotations

import math
from array import array
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Optional, Sequence

import numpy as np

from worldgen.errors import ParameterError, WorldgenError
from worldgen.export.contract import CLOCK, CMD_VEL, GOAL_POSE, GROUND_TRUTH, NAV_FEEDBACK, NAV_STATUS, ODOM, TF, TF_STATIC
from worldgen.ros.bagio import (
    RunMismatchError,
    bag_metadata,
    decoder,
    fail,
    listed_topics,
    mismatch,
    storage,
    typestore,
    unreadable,
)
from worldgen.ros.deps import require_rosbags

__all__ = ["BagRun", "RunMismatchError", "read_run", "bag_metadata", "peek_metadata", "START_RULES", "GOAL_TOPICS",
           "MOTION_START"]

START_RULES = ("command", "goal", "motion", "bag")
#: Where a goal shows: RViz's and nav2's goal topic, and the navigate_to_pose action's topics as recorded.
GOAL_TOPICS = (GOAL_POSE.name, NAV_FEEDBACK.name, NAV_STATUS.name)
#: The BARN Challenge starts its clock once the robot has moved this far (m) from where it stood.
MOTION_START = 0.1
_POSE_TYPES = ("nav_msgs/msg/Odometry", "geometry_msgs/msg/PoseStamped", "geometry_msgs/msg/PoseWithCovarianceStamped",
               "geometry_msgs/msg/TransformStamped", "tf2_msgs/msg/TFMessage")


@dataclass
class BagRun:
    """One run read from a bag: the trajectory and how it was obtained."""

    bag: str
    trajectory: np.ndarray            # (n, 4) t, x, y, yaw; world frame; simulation seconds
    source: str                       # ground_truth | tf | odom
    source_detail: str                # the topic or frame chain
    drift_bounded: bool               # False for odometry alone
    start: str                        # the start rule applied
    start_time: float                 # simulation time (s) the run starts at
    end_time: float
    topics: dict[str, str] = field(default_factory=dict)
    metadata: dict[str, str] = field(default_factory=dict)  # worldgen.* custom data, where the bag has it


class _Series:
    """t, x, y, yaw samples in a flat float array, at most one per ``min_dt`` seconds."""

    __slots__ = ("data", "min_dt", "last")

    def __init__(self, min_dt: float):
        self.data = array("d")
        self.min_dt = min_dt
        self.last = -math.inf

    def add(self, t: float, x: float, y: float, yaw: float) -> None:
        if t - self.last >= self.min_dt or t < self.last:
            self.data.extend((t, x, y, yaw))
            self.last = t

    def array(self) -> np.ndarray:
        a = np.frombuffer(self.data, dtype=float).reshape(-1, 4).copy()
        a = a[np.argsort(a[:, 0], kind="stable")]
        a[:, 3] = np.unwrap(a[:, 3])
        return a


def peek_metadata(bag) -> dict[str, str]:
    """The bag's ``worldgen.*`` custom data (world_id, task, run) without reading its messages; a bare storage
    file or a ROS 1 bag has none (it lives in a rosbag2 folder's metadata.yaml)."""
    require_rosbags()
    from rosbags.highlevel import AnyReader

    path = Path(bag)
    if not path.exists():
        raise fail(path, "does not exist")
    if not path.is_dir():
        return {}
    try:
        source, meta = storage(path)
        if meta:
            custom = meta["custom"]
        else:
            with AnyReader([source], default_typestore=typestore(None)) as reader:
                custom = bag_metadata(reader)["custom"]
    except Exception as exc:  # a truncated or foreign file
        raise unreadable(path, exc) from None
    return {str(k): str(v) for k, v in custom.items() if str(k).startswith("worldgen.")}


def _interp(series: np.ndarray, t: np.ndarray) -> np.ndarray:
    """(len(t), 3) x, y, yaw of a (n, 4) series at times t, held before its first and after its last sample."""
    if len(series) == 1:
        return np.repeat(series[:, 1:], len(t), axis=0)
    return np.stack([np.interp(t, series[:, 0], series[:, k]) for k in (1, 2, 3)], axis=1)


def _compose(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Row-wise pose a then b (x, y, yaw): b given in a's frame, returned in a's parent frame."""
    c, s = np.cos(a[:, 2]), np.sin(a[:, 2])
    return np.stack([a[:, 0] + c * b[:, 0] - s * b[:, 1], a[:, 1] + s * b[:, 0] + c * b[:, 1], a[:, 2] + b[:, 2]], axis=1)


def read_run(bag, world=None, *, task: Optional[str] = None, start: str = "command",
             pose_topic: str = GROUND_TRUTH.name, model: Optional[str] = None,
             odom_topic: str = ODOM.name, cmd_topic: str = CMD_VEL.name, goal_topics: Sequence[str] = GOAL_TOPICS,
             map_frame: str = "map", odom_frame: str = "odom", base_frames: Sequence[str] = ("base_footprint", "base_link"),
             spawn_tolerance: float = 0.25, distro: Optional[str] = None, min_dt: float = 0.02) -> BagRun:
    """Read ``bag`` (folder, .mcap, .db3, .bag) into a :class:`BagRun`; ``world`` gives the spawn (any form the
    oracles accept; None skips the spawn check and rules out the odometry source)."""
    require_rosbags()
    from rosbags.highlevel import AnyReader

    if start not in START_RULES:
        raise ParameterError(f"parameter 'start' must be one of {', '.join(START_RULES)}, got {start!r}")
    path = Path(bag)
    if not path.exists():
        raise fail(path, "does not exist")
    spawn = None
    if world is not None:
        from worldgen.groundtruth.ground import load
        spawn = np.asarray(load(world).task(task)["spawn"], dtype=float)[[0, 1, 5]]
    try:
        store, meta = storage(path)
        with AnyReader([store], default_typestore=typestore(distro)) as reader:
            meta = meta or bag_metadata(reader)
            topics = {c.topic: c.msgtype for c in reader.connections}
            st = None  # a bag without any pose topic is refused by its topic list: no message is read
            if _pose_topics(topics, pose_topic, odom_topic):
                st = _stream(reader, topics, pose_topic, model, odom_topic, cmd_topic, goal_topics, map_frame,
                             odom_frame, tuple(base_frames), start, min_dt, distro)
    except WorldgenError as exc:
        raise fail(path, str(exc)) from None
    except Exception as exc:  # rosbags' and the storage libraries' errors: a truncated or foreign file
        listed = listed_topics(path)
        if listed is not None and not _pose_topics(listed, pose_topic, odom_topic):  # foreign, and no pose anyway
            topics, st = listed, None
        else:
            raise unreadable(path, exc) from None
    found = ", ".join(f"{t} ({ty})" for t, ty in sorted(topics.items())) or "none"
    source, detail, traj = _pose(st, spawn, pose_topic, odom_topic, map_frame, odom_frame, base_frames) if st else \
        (None, "", None)
    if traj is None or source is None:  # _pose names a source with every trajectory
        need = f"{pose_topic}, /tf with {map_frame}->{odom_frame}->{'|'.join(base_frames)}, or {odom_topic}"
        has_odometry = st is not None and ((st["odom"] is not None and len(st["odom"].data))
                                           or any(len(b.data) for b in st["base"].values()))
        if has_odometry and spawn is None:
            need += " (odometry needs a world for its spawn pose)"
        raise fail(path, f"no pose source: need {need}; topics found: {found}")
    t0, rule = _start_time(st, traj, start, cmd_topic, found, path)
    traj = _cut(traj, t0)
    if spawn is not None:
        d = float(math.hypot(traj[0, 1] - spawn[0], traj[0, 2] - spawn[1]))
        if d > spawn_tolerance:
            raise mismatch(path, f"the run starts {d:.2f} m from the task's spawn ({spawn[0]:.2f}, {spawn[1]:.2f}) at "
                              f"({traj[0, 1]:.2f}, {traj[0, 2]:.2f}), more than spawn_tolerance {spawn_tolerance:g} m: "
                              f"is this the right world and task?")
    return BagRun(bag=str(path), trajectory=traj, source=source, source_detail=detail, drift_bounded=source != "odom",
                  start=rule, start_time=float(traj[0, 0]), end_time=float(traj[-1, 0]), topics=topics,
                  metadata={k: str(v) for k, v in meta["custom"].items() if str(k).startswith("worldgen.")})


def _pose_topics(topics: dict[str, str], pose_topic: str, odom_topic: str) -> bool:
    """Whether the bag has a topic any pose source could come from (its connections, before any message)."""
    return (topics.get(pose_topic) in _POSE_TYPES or TF.name in topics or TF_STATIC.name in topics
            or odom_topic in topics)


# long: one pass over the bag's messages, a few lines for each topic's case, sharing the clock between them
def _stream(reader, topics, pose_topic, model, odom_topic, cmd_topic, goal_topics, map_frame, odom_frame, base_frames,
            start, min_dt, distro) -> dict:
    """One pass over the topics that matter; returns the pose series and the start events."""
    gt = pose_topic in topics and topics[pose_topic] in _POSE_TYPES
    wanted = {cmd_topic}
    if start == "goal":
        wanted |= set(goal_topics)
    if gt:
        wanted.add(pose_topic)
    else:
        wanted |= {TF.name, TF_STATIC.name, odom_topic}
    conns = [c for c in reader.connections if c.topic in wanted or c.topic == CLOCK.name]
    st: dict[str, Any] = {"gt": _Series(min_dt) if gt else None, "odom": None, "base": {f: _Series(min_dt) for f in base_frames},
                          "map_odom": _Series(0.0), "first_cmd": None, "first_goal": None, "cmd_seen": False}
    if not gt and odom_topic in topics:
        st["odom"] = _Series(min_dt)
    ref = None  # (receive ns, simulation s) of the latest stamped message: clocks unstamped ones
    # The receive time (ns) of a first non-zero Twist that came before any stamped message: the first one after
    # it times it (a drive that commands at time 0 sends it before the simulator's first tick is recorded).
    early = None
    decode = decoder(reader, conns, distro)
    for conn, recv, raw in reader.messages(connections=conns):
        topic = conn.topic
        if topic in goal_topics and conn.msgtype != GOAL_POSE.ros_type:
            if st["first_goal"] is None and ref is not None:
                st["first_goal"] = ref[1] + (recv - ref[0]) * 1e-9
            continue
        v = decode(conn, raw)
        if topic == CLOCK.name:
            ref = (recv, v)
        elif topic == cmd_topic:
            st["cmd_seen"] = True
            t, vx, vy, wz = v
            if st["first_cmd"] is None and early is None and (abs(vx) > 1e-9 or abs(vy) > 1e-9 or abs(wz) > 1e-9):
                if t is not None:
                    st["first_cmd"] = t
                elif ref is not None:  # a Twist has no stamp: the simulation time it was received at
                    st["first_cmd"] = ref[1] + (recv - ref[0]) * 1e-9
                else:  # unstamped, before any clock: timed by the next stamped message
                    early = recv
        elif topic in goal_topics:
            if st["first_goal"] is None:
                st["first_goal"] = v[0]
        elif topic == pose_topic and gt:
            poses = v if isinstance(v, list) else [v]
            chosen = [p for p in poses if model is None or p[2] == model][:1]
            for t, _, _, x, y, yaw in chosen:
                st["gt"].add(t, x, y, yaw)
                ref = (recv, t)
        elif topic == odom_topic and st["odom"] is not None:
            st["odom"].add(v[0], v[3], v[4], v[5])
            ref = (recv, v[0])
        elif topic in (TF.name, TF_STATIC.name):
            for t, parent, child, x, y, yaw in v:
                parent, child = parent.lstrip("/"), child.lstrip("/")
                if parent == odom_frame and child in st["base"]:
                    st["base"][child].add(t, x, y, yaw)
                elif parent == map_frame and child == odom_frame:
                    st["map_odom"].add(t, x, y, yaw)
                else:
                    continue
                ref = (recv, t)
        if early is not None and ref is not None:
            st["first_cmd"], early = ref[1] - (ref[0] - early) * 1e-9, None
    if early is not None:  # no clock in the whole bag: its receive time is all there is
        st["first_cmd"] = early * 1e-9
    return st


def _pose(st, spawn, pose_topic, odom_topic, map_frame, odom_frame, base_frames):
    """(source, detail, (n, 4) trajectory) of the first pose source the bag has; trajectory None when none."""
    if st["gt"] is not None and len(st["gt"].data):
        return "ground_truth", pose_topic, st["gt"].array()
    base = next((f for f in base_frames if len(st["base"][f].data)), None)
    if base is not None and len(st["map_odom"].data):
        rel = st["base"][base].array()
        correction = _interp(st["map_odom"].array(), rel[:, 0])
        out = rel.copy()
        out[:, 1:] = _compose(correction, rel[:, 1:])
        return "tf", f"{map_frame}->{odom_frame}->{base}", out
    # Odometry alone: the /odom topic, else the odom -> base transform it is usually published beside.
    rel, detail = None, ""
    if st["odom"] is not None and len(st["odom"].data):
        rel, detail = st["odom"].array(), odom_topic
    elif base is not None:
        rel, detail = st["base"][base].array(), f"/tf {odom_frame}->{base}"
    if rel is not None and spawn is not None:
        out = rel.copy()
        out[:, 1:] = _compose(np.repeat(spawn[None, :], len(rel), axis=0), rel[:, 1:])
        return "odom", f"{detail} + spawn (unbounded drift)", out
    return None, "", None


def _start_time(st, traj, start, cmd_topic, found, path) -> tuple[float, str]:
    if start == "bag":
        return float(traj[0, 0]), "bag"
    if start == "command":
        if not st["cmd_seen"] and st["first_cmd"] is None:
            raise fail(path, f"start='command' needs {cmd_topic}, which is not in the bag; topics found: {found}")
        if st["first_cmd"] is None:  # commands, all zero: the robot was never told to move; judge it from the start
            return float(traj[0, 0]), "command (none non-zero: from the first pose)"
        return float(st["first_cmd"]), "command"
    if start == "goal":
        if st["first_goal"] is None:
            raise fail(path, f"start='goal' needs a goal topic ({', '.join(GOAL_TOPICS)}); topics found: {found}")
        return float(st["first_goal"]), "goal"
    moved = np.hypot(traj[:, 1] - traj[0, 1], traj[:, 2] - traj[0, 2]) >= MOTION_START
    k = int(np.argmax(moved)) if moved.any() else 0
    return float(traj[k, 0]), "motion" if moved.any() else "motion (never moved: from the first pose)"


def _cut(traj: np.ndarray, t0: float) -> np.ndarray:
    """The samples from t0 on, led by the pose interpolated at t0 (held before the first sample)."""
    t0 = min(max(t0, float(traj[0, 0])), float(traj[-1, 0]))
    head = np.concatenate([[t0], _interp(traj, np.array([t0]))[0]])
    rest = traj[traj[:, 0] > t0]
    return np.vstack([head[None, :], rest])
