"""The ROS 2 bundle of a world: everything a Gazebo + nav2 run needs beside the world's files, in ``ros2/``.

Opt-in (``worldgen generate --ros``, ``World.write(..., ros=True)``, ``ros: true`` in a pack recipe).
:func:`bundle` returns ``{relative path: bytes}``, the same bytes in any process:

=================================  ==========================================================================
``ros2/bridge.yaml``               ros_gz_bridge ``config_file``: /clock, the ground-truth pose, contacts,
                                   /cmd_vel, /odom, /tf, /scan (keys and directions as the bridge documents)
``ros2/nav2/<task>.yaml``          nav2 parameter overrides per task: the map, AMCL's initial pose at the
                                   task's spawn, the footprint radius, ``use_sim_time`` for every node
``ros2/tasks.yaml``                every task: spawn, goal pose in the map frame, tolerance, time limit
``ros2/launch/<name>.launch.py``   one run: Gazebo headless, spawn, bridge, nav2, ``ros2 bag record``, the
                                   goal once nav2 is active, shutdown on the result or the time limit
``ros2/send_goal.py``              the goal sender the launch file runs (nav2_simple_commander)
``ros2/run_loop.py``               N worlds x M runs, one ``ros2 launch`` per run
``ros2/world.sdf``                 the world with the Gazebo systems a run needs (sensors, contacts), for one
                                   Gazebo release (``gz_release``; None leaves it out and runs ``world.sdf``)
=================================  ==========================================================================

Gazebo's world frame is the map frame: world.json, the SDF and map.yaml share one frame, so a goal
is world.json's goal as it stands. docs/ros2.md describes the loop and what was verified where.
"""

from __future__ import annotations

import re
from importlib import resources
from typing import Any, Mapping, Optional

from worldgen.errors import ParameterError
from worldgen.export.robot import DEFAULT_NAME as DEFAULT_ROBOT_NAME
from worldgen.export.robot import GZ_RELEASES, gz_release_of

__all__ = ["BUNDLE_DIR", "ROBOT_SDF", "ROBOT_URDF", "GZ_RELEASES", "GZ_SERVERS", "DEFAULT_GZ_RELEASE",
           "DEFAULT_ROBOT_NAME", "TOPICS", "RECORDED_TOPICS", "ros_name", "release_of", "plugins", "with_plugins",
           "bridge_config", "nav2_map", "nav2_overrides", "tasks_spec", "bundle", "dumps"]

BUNDLE_DIR = "ros2"
#: The shipped robot's files in the bundle (worldgen.export.robot).
ROBOT_SDF, ROBOT_URDF = "robot.sdf", "robot.urdf"
#: Gazebo's server command per release, whether it takes ``--seed`` (gz-sim 8's cmdsim.rb has it; gz-sim 7's
#: and ign-gazebo 6's do not) and the variable it reads system plugin paths from. The launch file runs it
#: without a shell: ros_gz_sim's gz_sim.launch.py runs ``ruby $(which gz) sim`` through one, the shell does
#: not pass launch's SIGINT on, and Gazebo outlives the run (ros2/launch#545).
GZ_SERVERS = {
    "fortress": (("ign", "gazebo"), False, "IGN_GAZEBO_SYSTEM_PLUGIN_PATH"),
    "garden": (("gz", "sim"), False, "GZ_SIM_SYSTEM_PLUGIN_PATH"),
    "harmonic": (("gz", "sim"), True, "GZ_SIM_SYSTEM_PLUGIN_PATH"),
    "ionic": (("gz", "sim"), True, "GZ_SIM_SYSTEM_PLUGIN_PATH"),
}
#: Harmonic pairs with ROS 2 Jazzy, the current LTS pair.
DEFAULT_GZ_RELEASE = "harmonic"
#: The world systems the bundle's world.sdf names. Naming any plugin replaces Gazebo's default set
#: (physics, user commands, scene broadcaster), so those three come first; Sensors (ogre2) makes
#: gpu_lidar and cameras publish, Contact makes contact sensors publish, Imu makes IMUs publish.
_SYSTEMS = (("physics", "Physics", ""), ("user-commands", "UserCommands", ""),
            ("scene-broadcaster", "SceneBroadcaster", ""), ("sensors", "Sensors", "<render_engine>ogre2</render_engine>"),
            ("contact", "Contact", ""), ("imu", "Imu", ""))

#: ROS topic -> (ROS type, Gazebo type suffix, Gazebo topic, direction); ``{robot}`` is the robot's
#: model name. The ground truth comes from gz-sim's OdometryPublisher system on the robot model (its
#: ``tf_topic`` defaults to /model/<name>/pose: Pose_V, the model's world pose), bridged as
#: tf2_msgs/TFMessage on /ground_truth, the topic ``worldgen judge`` reads first; the robot's own
#: topics keep the names nav2 expects.
TOPICS: dict[str, tuple[str, str, str, str]] = {
    "/clock": ("rosgraph_msgs/msg/Clock", "Clock", "/clock", "GZ_TO_ROS"),
    "/ground_truth": ("tf2_msgs/msg/TFMessage", "Pose_V", "/model/{robot}/pose", "GZ_TO_ROS"),
    "/contacts": ("ros_gz_interfaces/msg/Contacts", "Contacts", "/contacts", "GZ_TO_ROS"),
    "/cmd_vel": ("geometry_msgs/msg/Twist", "Twist", "/cmd_vel", "ROS_TO_GZ"),
    "/odom": ("nav_msgs/msg/Odometry", "Odometry", "/odom", "GZ_TO_ROS"),
    "/tf": ("tf2_msgs/msg/TFMessage", "Pose_V", "/tf", "GZ_TO_ROS"),
    "/scan": ("sensor_msgs/msg/LaserScan", "LaserScan", "/scan", "GZ_TO_ROS"),
    "/imu": ("sensor_msgs/msg/Imu", "IMU", "/imu", "GZ_TO_ROS"),
    "/joint_states": ("sensor_msgs/msg/JointState", "Model", "/joint_states", "GZ_TO_ROS"),
}
#: What ``ros2 bag record`` keeps: what ``worldgen judge`` reads (the goal's time from the navigate_to_pose
#: action's status, a hidden topic), plus the contacts.
RECORDED_TOPICS = ("/odom", "/tf", "/tf_static", "/cmd_vel", "/clock", "/scan", "/ground_truth", "/contacts",
                   "/navigate_to_pose/_action/status")
#: The nav2 nodes that get ``use_sim_time`` explicitly (the launch file sets it on every node it finds too).
_NAV2_NODES = ("amcl", "bt_navigator", "controller_server", "planner_server", "smoother_server", "behavior_server",
               "velocity_smoother", "waypoint_follower", "collision_monitor", "map_server",
               "lifecycle_manager_localization", "lifecycle_manager_navigation")
_NAME_RE = re.compile(r"[^A-Za-z0-9_]+")


def ros_name(text: str) -> str:
    """``text`` as a valid ROS 2 name token: [A-Za-z0-9_] only, no repeated or trailing underscore,
    not starting with a digit (ROS 2's naming rules, which world ids with '-' break)."""
    name = re.sub("_+", "_", _NAME_RE.sub("_", text)).strip("_")
    if not name or name[0].isdigit():
        name = "w_" + name
    return name.rstrip("_")


def release_of(ros) -> str:
    """The Gazebo release a ``ros`` option names: True for the default, else a release's name."""
    if ros is True:
        return DEFAULT_GZ_RELEASE
    if isinstance(ros, str) and ros.lower() in GZ_RELEASES:
        return ros.lower()
    raise ParameterError(f"parameter 'ros' must be true or a Gazebo release among {', '.join(GZ_RELEASES)}, got {ros!r}")


def plugins(gz_release: str = DEFAULT_GZ_RELEASE) -> list[tuple[str, str, str]]:
    """``(filename, name, inner XML)`` of every world system the bundle's SDF names, for ``gz_release``."""
    filename, name, _ = gz_release_of(gz_release)
    return [(filename.format(f), name.format(n), inner) for f, n, inner in _SYSTEMS]


def with_plugins(sdf_text: str, gz_release: str = DEFAULT_GZ_RELEASE, mesh_prefix: str = "") -> bytes:
    """The SDF world ``sdf_text`` (either version worldgen writes) with :func:`plugins` first in its
    ``<world>``, and every mesh ``<uri>`` prefixed with ``mesh_prefix`` (the bundle's SDF sits one
    folder below the meshes). Text insertion after the ``<world ...>`` line keeps every other byte."""
    lines = sdf_text.splitlines(keepends=True)
    at = next((i for i, line in enumerate(lines) if line.lstrip().startswith("<world ")), None)
    if at is None:
        raise ParameterError("parameter 'sdf_text' must hold an SDF <world>, got none")
    indent = lines[at][: len(lines[at]) - len(lines[at].lstrip())] + "  "
    block = []
    for filename, name, inner in plugins(gz_release):
        if inner:
            block += [f'{indent}<plugin filename="{filename}" name="{name}">\n', f"{indent}  {inner}\n",
                      f"{indent}</plugin>\n"]
        else:
            block.append(f'{indent}<plugin filename="{filename}" name="{name}"/>\n')
    body = lines[: at + 1] + block + lines[at + 1:]
    text = "".join(body)
    if mesh_prefix:
        text = re.sub(r"<uri>(?![a-z]+://|/)", "<uri>" + mesh_prefix, text)
    return text.encode()


def _topics(robot_name: str) -> dict[str, tuple[str, str, str, str]]:
    robot = ros_name(robot_name)
    return {ros.format(robot=robot): (rt, gt, gz.format(robot=robot), d) for ros, (rt, gt, gz, d) in TOPICS.items()}


def bridge_config(robot_name: str = DEFAULT_ROBOT_NAME, gz_release: str = DEFAULT_GZ_RELEASE) -> list[dict[str, Any]]:
    """The ros_gz_bridge YAML config: one mapping per topic with the bridge's documented keys."""
    prefix = gz_release_of(gz_release)[2]
    return [{"ros_topic_name": ros, "gz_topic_name": gz, "ros_type_name": ros_type,
             "gz_type_name": f"{prefix}.{gz_type}", "direction": direction}
            for ros, (ros_type, gz_type, gz, direction) in _topics(robot_name).items()]


def _spawn(task) -> dict[str, float]:
    from worldgen.floats import round_float
    return {"x": round_float(task.spawn.x), "y": round_float(task.spawn.y), "z": round_float(task.spawn.z),
            "yaw": round_float(task.spawn.yaw)}


def nav2_map(world) -> str:
    """The map nav2 gets, relative to the world folder: the world's map.yaml, unless a door leaf starts
    closed or ajar; then the bundle's own map of the scene as it starts (map.pgm draws every leaf open,
    the scene the reference paths were planned in, and AMCL would meet leaves its map lacks). Door states
    are the world's (world.json ``doors[].state``), so every task starts from the same map."""
    from worldgen.files import MAP_YAML_NAME
    from worldgen.groundtruth.truth import doors_start_shut

    return f"{BUNDLE_DIR}/{MAP_YAML_NAME}" if doors_start_shut(world) else MAP_YAML_NAME


def nav2_overrides(world, task) -> dict[str, Any]:
    """nav2 parameters for ``task``: merged over a full nav2 params file by the launch file.

    ``map_server.yaml_filename`` (:func:`nav2_map`) is relative to the world folder (the launch file
    makes it absolute).
    """
    from worldgen.floats import round_float

    out: dict[str, Any] = {node: {"ros__parameters": {"use_sim_time": True}} for node in _NAV2_NODES}
    out["amcl"]["ros__parameters"].update({"set_initial_pose": True, "initial_pose": _spawn(task),
                                           "global_frame_id": "map"})
    out["map_server"]["ros__parameters"]["yaml_filename"] = nav2_map(world)
    radius = round_float(world.robot.radius)
    for costmap in ("local_costmap", "global_costmap"):
        out[costmap] = {costmap: {"ros__parameters": {"use_sim_time": True, "robot_radius": radius}}}
    return out


def tasks_spec(world) -> dict[str, Any]:
    """Every task as a goal pose in the map frame with its tolerance and time limit: world.json's
    figures, from the one builder of its task block (worldgen.export.tasks)."""
    from worldgen.export.tasks import task_entry
    from worldgen.floats import round_float

    paths = list(world.feasibility.paths) + [None] * len(world.tasks)
    tasks = []
    for task, path in zip(world.tasks, paths):
        entry = task_entry(world, task, path)
        limit = entry["time_limit"]
        tasks.append({"id": task.id, "spawn": _spawn(task),
                      "goal": {"frame_id": "map", "x": round_float(task.goal.x), "y": round_float(task.goal.y),
                               "yaw": round_float(task.goal.yaw)},
                      "tolerance": round_float(entry["goal_tolerance"]),
                      "time_limit": None if limit is None else round_float(limit)})
    return {"world_id": world.world_id, "world_name": world.world_id, "frame_id": "map", "tasks": tasks}


def dumps(data: Any) -> bytes:
    """Canonical YAML (sorted keys, block style), as scenario.yaml is written."""
    import yaml

    return yaml.safe_dump(data, sort_keys=True, default_flow_style=False, width=100, allow_unicode=False).encode()


def _template(name: str) -> str:
    """``templates/ros2/<name>.in``: .in, so that no tool takes the scripts for modules of worldgen."""
    return resources.files("worldgen.templates").joinpath("ros2", name + ".in").read_text(encoding="utf-8")


def bundle(world, sdf_version: str = "1.9", gz_release: Optional[str] = DEFAULT_GZ_RELEASE,
           robot_name: str = DEFAULT_ROBOT_NAME, folder_name: Optional[str] = None) -> dict[str, bytes]:
    """Every file of the ROS 2 bundle of ``world``: ``{path relative to the world folder: bytes}``.

    ``gz_release`` picks the system plugin names of the bundle's world.sdf (None: no second SDF; the
    run loads the world's own world.sdf with Gazebo's default systems, which publish no sensor in
    Garden and later). ``folder_name`` names the bags (default: the world's folder name). The robot
    worldgen.export.robot makes for the world is shipped as ``robot.sdf`` (spawned unless the run names
    another) and ``robot.urdf`` (robot_state_publisher's), named ``robot_name``.
    """
    from worldgen.export.robot import robot_sdf, robot_urdf
    from worldgen.files import MAP_IMAGE_NAME, MAP_YAML_NAME, SDF_NAME
    from worldgen.groundtruth.truth import doors_start_shut, start_occupancy_map

    if gz_release is not None:
        gz_release_of(gz_release)
    robot = ros_name(robot_name)
    name = ros_name(world.world_id)
    files: dict[str, bytes] = {
        f"{BUNDLE_DIR}/bridge.yaml": dumps(bridge_config(robot, gz_release or DEFAULT_GZ_RELEASE)),
        f"{BUNDLE_DIR}/tasks.yaml": dumps(tasks_spec(world)),
    }
    for task in world.tasks:
        files[f"{BUNDLE_DIR}/nav2/{task.id}.yaml"] = dumps(nav2_overrides(world, task))
    if doors_start_shut(world):
        grid = start_occupancy_map(world)
        files[f"{BUNDLE_DIR}/{MAP_IMAGE_NAME}"] = grid.pgm()
        files[f"{BUNDLE_DIR}/{MAP_YAML_NAME}"] = grid.yaml(MAP_IMAGE_NAME)
    files[f"{BUNDLE_DIR}/{ROBOT_SDF}"] = robot_sdf(world, name=robot, gz_release=gz_release or DEFAULT_GZ_RELEASE).encode()
    files[f"{BUNDLE_DIR}/{ROBOT_URDF}"] = robot_urdf(world, name=robot).encode()
    sdf_file = SDF_NAME
    if gz_release is not None:
        files[f"{BUNDLE_DIR}/{SDF_NAME}"] = with_plugins(world.export("sdf", sdf_version), gz_release, "../")
        sdf_file = f"{BUNDLE_DIR}/{SDF_NAME}"
    command, seed, plugin_path = GZ_SERVERS[gz_release or DEFAULT_GZ_RELEASE]
    values = {"WORLD_ID": world.world_id, "WORLD_NAME": world.world_id, "ROS_NAME": name,
              "FOLDER": folder_name or world.folder_name, "SDF": sdf_file, "ROBOT": robot, "MAP": nav2_map(world),
              "ROBOT_SDF": ROBOT_SDF, "ROBOT_URDF": ROBOT_URDF,
              "GZ_COMMAND": repr(command), "GZ_SEED": repr(seed), "GZ_PLUGIN_PATH": plugin_path,
              "FIRST_TASK": world.tasks[0].id, "TOPICS": repr(tuple(t.format(robot=robot) for t in RECORDED_TOPICS))}
    launch = _fill(_template("launch.py"), values)
    files[f"{BUNDLE_DIR}/launch/{name}.launch.py"] = launch.encode()
    files[f"{BUNDLE_DIR}/send_goal.py"] = _template("send_goal.py").encode()
    files[f"{BUNDLE_DIR}/run_loop.py"] = _template("run_loop.py").encode()
    return files


def _fill(text: str, values: Mapping[str, str]) -> str:
    for key, value in values.items():
        text = text.replace(f"@{key}@", value)
    left = re.findall(r"@[A-Z_]+@", text)
    if left:  # a template and this writer disagree: a bug, not a user's mistake
        raise AssertionError(f"ROS 2 template placeholders left unfilled: {left}")
    return text
