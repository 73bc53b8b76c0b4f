"""The ROS 2 bundle of a world: everything a Gazebo + nav2 run needs beside the world's files, in ``ros2/``.

Opt-in (``worldgen generate --ros``, ``World.write(..., ros=True)``, ``ros: true`` in a pack recipe).
:func:`bundle` returns ``{relative path: bytes}``, the same bytes in any process:

=================================  ==========================================================================
``ros2/bridge.yaml``               ros_gz_bridge ``config_file``: /clock, the ground-truth pose, contacts,
                                   /cmd_vel, /odom, /tf, /scan (keys and directions as the bridge documents)
``ros2/nav2/<task>.yaml``          nav2 parameter overrides per task: the map, AMCL's initial pose at the
                                   task's spawn, the footprint radius, the goal checker's tolerance, the
                                   planner's map where doors start shut, ``use_sim_time`` for every node
``ros2/tasks.yaml``                every task: spawn, goal pose in the map frame, tolerance, time limit
``ros2/launch/<name>.launch.py``   one run: Gazebo headless, spawn, bridge, nav2, ``ros2 bag record``, the
                                   goal once nav2 is active, shutdown on the result or the time limit
``ros2/send_goal.py``              the goal sender the launch file runs (nav2_simple_commander)
``ros2/run_loop.py``               N worlds x M runs, one ``ros2 launch`` per run
``ros2/world.sdf``                 the world with the Gazebo systems a run needs (sensors, contacts), for one
                                   Gazebo release (``gz_release``; None leaves it out and runs ``world.sdf``)
=================================  ==========================================================================

Gazebo's world frame is the map frame: world.json, the SDF and map.yaml share one frame, so a goal
is world.json's goal as it stands. The Gazebo release's names and every topic come from
:mod:`worldgen.export.contract`. docs/ros2.md describes the loop and what was verified where. The module's
old home, ``worldgen.ros.bundle``, still imports, with a DeprecationWarning.
"""

from __future__ import annotations

import re
from importlib import resources
from typing import Any, Mapping, Optional

from worldgen.errors import ParameterError
from worldgen.export.contract import BRIDGED, DEFAULT_GZ_RELEASE, GZ_RELEASES, RECORDED, release
from worldgen.export.robot import DEFAULT_NAME as DEFAULT_ROBOT_NAME

__all__ = ["BUNDLE_DIR", "GOAL_CHECKER", "PLANNER_MAP_TOPIC", "ROBOT_SDF", "ROBOT_URDF", "DEFAULT_ROBOT_NAME",
           "ros_name", "release_of", "plugins",
           "with_plugins", "bridge_config", "nav2_map", "planner_map", "nav2_overrides", "tasks_spec", "bundle", "dumps"]

BUNDLE_DIR = "ros2"
#: The shipped robot's files in the bundle (worldgen.export.robot).
ROBOT_SDF, ROBOT_URDF = "robot.sdf", "robot.urdf"
#: The world systems the bundle's world.sdf names. Naming any plugin replaces Gazebo's default set
#: (physics, user commands, scene broadcaster), so those three come first; Sensors (ogre2) makes
#: gpu_lidar and cameras publish, Contact makes contact sensors publish, Imu makes IMUs publish.
_SYSTEMS = (("physics", "Physics", ""), ("user-commands", "UserCommands", ""),
            ("scene-broadcaster", "SceneBroadcaster", ""), ("sensors", "Sensors", "<render_engine>ogre2</render_engine>"),
            ("contact", "Contact", ""), ("imu", "Imu", ""))
#: The nav2 nodes that get ``use_sim_time`` explicitly (the launch file sets it on every node it finds too).
_NAV2_NODES = ("amcl", "bt_navigator", "controller_server", "planner_server", "smoother_server", "behavior_server",
               "velocity_smoother", "waypoint_follower", "collision_monitor", "map_server",
               "lifecycle_manager_localization", "lifecycle_manager_navigation")
_NAME_RE = re.compile(r"[^A-Za-z0-9_]+")
#: The goal checker nav2_bringup's params file names (nav2 1.3.13 ``goal_checker_plugins``); the launch
#: file also caps every other checker a params file names at the task's tolerance.
GOAL_CHECKER = "general_goal_checker"
#: Where the planner's map is published when it is not map_server's (absolute: the costmap resolves it
#: in no namespace of its own).
PLANNER_MAP_TOPIC = "/planner_map"


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
    row = release(gz_release)
    return [(*row.plugin(f, n), inner) for f, n, inner in _SYSTEMS]


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


def bridge_config(gz_release: str = DEFAULT_GZ_RELEASE) -> list[dict[str, Any]]:
    """The ros_gz_bridge YAML config: one mapping per bridged topic of the contract (worldgen.export.contract),
    with the bridge's documented keys."""
    row = release(gz_release)
    return [{"ros_topic_name": t.name, "gz_topic_name": t.gz_topic, "ros_type_name": t.ros_type,
             "gz_type_name": row.msg(t.gz_type or ""), "direction": t.direction} for t in BRIDGED]


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
    # nav2's SimpleGoalChecker counts a goal reached within xy_goal_tolerance (0.25 m in nav2 1.3.13's
    # nav2_params.yaml); above the task's tolerance nav2's `succeeded` could be a judged miss.
    out["controller_server"]["ros__parameters"][GOAL_CHECKER] = {"xy_goal_tolerance": round_float(task.goal_tolerance)}
    radius = round_float(world.robot.radius)
    for costmap in ("local_costmap", "global_costmap"):
        out[costmap] = {costmap: {"ros__parameters": {"use_sim_time": True, "robot_radius": radius}}}
    if planner_map(world):
        # The planner plans in the scene with every leaf open (the doors the robot may open); AMCL keeps
        # map_server's map of the scene as it starts. Both the costmap's and the static layer's own
        # map_topic: a static layer's own one wins where a params file sets it.
        block = out["global_costmap"]["global_costmap"]["ros__parameters"]
        block.update({"map_topic": PLANNER_MAP_TOPIC, "static_layer": {"map_topic": PLANNER_MAP_TOPIC}})
    return out


def planner_map(world) -> Optional[str]:
    """The map the global costmap plans in when it differs from :func:`nav2_map`: the world's map.yaml
    (every door leaf at its open limit) where a leaf starts closed or ajar, published by a map server of
    the planner's own on :data:`PLANNER_MAP_TOPIC`; None elsewhere (one map serves both)."""
    from worldgen.files import MAP_YAML_NAME
    from worldgen.groundtruth.truth import doors_start_shut

    return MAP_YAML_NAME if doors_start_shut(world) else None


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
    return resources.files("worldgen.templates").joinpath("ros2").joinpath(name + ".in").read_text(encoding="utf-8")


def bundle(world, sdf_version: str = "1.9", gz_release: Optional[str] = DEFAULT_GZ_RELEASE,
           robot_name: str = DEFAULT_ROBOT_NAME, folder_name: Optional[str] = None) -> dict[str, bytes]:
    """Every file of the ROS 2 bundle of ``world``: ``{path relative to the world folder: bytes}``.

    ``gz_release`` picks the system plugin names of the bundle's world.sdf (None: no second SDF; the
    run loads the world's own world.sdf with Gazebo's default systems, which publish no sensor in
    Garden and later). ``folder_name`` names the bags (default: the world's folder name). The robot
    worldgen.export.robot makes for the world is shipped as ``robot.sdf`` (spawned unless the run names
    another) and ``robot.urdf`` (robot_state_publisher's), named ``robot_name``.
    """
    from worldgen.export.robot import robot_sdf
    from worldgen.export.robot_urdf import robot_urdf
    from worldgen.files import MAP_IMAGE_NAME, MAP_YAML_NAME, SDF_NAME
    from worldgen.groundtruth.truth import doors_start_shut, start_occupancy_map

    row = release(gz_release or DEFAULT_GZ_RELEASE)
    robot = ros_name(robot_name)
    name = ros_name(world.world_id)
    files: dict[str, bytes] = {
        f"{BUNDLE_DIR}/bridge.yaml": dumps(bridge_config(row.name)),
        f"{BUNDLE_DIR}/tasks.yaml": dumps(tasks_spec(world)),
    }
    for task in world.tasks:
        files[f"{BUNDLE_DIR}/nav2/{task.id}.yaml"] = dumps(nav2_overrides(world, task))
    if doors_start_shut(world):
        grid = start_occupancy_map(world)
        files[f"{BUNDLE_DIR}/{MAP_IMAGE_NAME}"] = grid.pgm()
        files[f"{BUNDLE_DIR}/{MAP_YAML_NAME}"] = grid.yaml(MAP_IMAGE_NAME)
    files[f"{BUNDLE_DIR}/{ROBOT_SDF}"] = robot_sdf(world, name=robot, gz_release=row.name).encode()
    files[f"{BUNDLE_DIR}/{ROBOT_URDF}"] = robot_urdf(world, name=robot).encode()
    sdf_file = SDF_NAME
    if gz_release is not None:
        files[f"{BUNDLE_DIR}/{SDF_NAME}"] = with_plugins(world.export("sdf", sdf_version), gz_release, "../")
        sdf_file = f"{BUNDLE_DIR}/{SDF_NAME}"
    values = {"WORLD_ID": world.world_id, "WORLD_NAME": world.world_id, "ROS_NAME": name,
              "FOLDER": folder_name or world.folder_name, "SDF": sdf_file, "ROBOT": robot, "MAP": nav2_map(world),
              "PLANNER_MAP": planner_map(world) or "", "PLANNER_MAP_TOPIC": PLANNER_MAP_TOPIC,
              "GOAL_CHECKER": GOAL_CHECKER,
              "ROBOT_SDF": ROBOT_SDF, "ROBOT_URDF": ROBOT_URDF,
              "GZ_COMMAND": repr(row.server), "GZ_SEED": repr(row.seed), "GZ_PLUGIN_PATH": row.plugin_path_var,
              "FIRST_TASK": world.tasks[0].id, "TOPICS": repr(tuple(t.name for t in RECORDED))}
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
