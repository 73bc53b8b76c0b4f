"""The world as OpenSCENARIO 2 for scenario_execution (``world.osc``): one scenario per task, each a nav2
run in Gazebo that ``worldgen judge`` judges like a run of the ROS 2 bundle.

Asked for like ``usd``, as the optional format ``osc`` (``--formats sdf,mjcf,urdf,osc --ros``): the file is
rendered from the world, hashed in world.json, and re-rendered by ``worldgen check``. Each scenario:

1. starts the world's ``--ros`` bundle (``ros2/launch/<world>.launch.py``, relative to the .osc) for its
   task with ``goal:=false``: Gazebo, the robot at the spawn, the bridge, nav2; the bundle's own goal
   sender and recorder stay off, as the scenario does both;
2. waits for the simulation (``wait_for_sim``: Gazebo's clock of the world);
3. initialises nav2 at the task's spawn (``init_nav2``, frame ``base_footprint`` of worldgen's robot);
4. records the judge's topics (the contract's :data:`~worldgen.export.contract.RECORDED`), hidden ones
   included (nav2's action status), in simulation time;
5. sends the goal (``nav_to_pose``) under a ``timeout`` of the task's time limit, then ends.

A scenario's own ``timeout`` is the bundle's wall-clock backstop (10 x the time limit + 120 s, given to
the launch as ``wall_limit``), so both stop together. People and movers are declared as ``osc_actor``
fields: osc.gazebo can spawn and delete a model but has no action that walks one, so their certified walks
stay where Gazebo plays them, the world's SDF ``<actor>`` scripts (docs/osc.md says what that keeps and
drops). Every number is written with its unit (m, rad, s), and the text passes :func:`~worldgen.export.osc_lint.lint`
before it is returned, so a fault there stops the export before any file is written.
"""

from __future__ import annotations

from typing import Any, Optional

from worldgen.errors import ParameterError
from worldgen.export.contract import RECORDED
from worldgen.export.osc_lint import lint
from worldgen.export.ros2 import BUNDLE_DIR, ros_name
from worldgen.floats import fmt

__all__ = ["LIBRARIES", "BASE_FRAME", "ROBOT_FIELD", "SIM_WAIT", "scenario_name", "launch_file", "wall_limit",
           "writer_args", "to_osc"]

#: The scenario_execution libraries a scenario imports (helpers: timeout; ros: launch, bag; gazebo; nav2).
LIBRARIES = ("helpers", "ros", "gazebo", "nav2")
#: The frame nav2 localises: worldgen's robot has its pose at ``base_footprint`` (export/robot.py).
BASE_FRAME = "base_footprint"
#: The scenario's name of the robot (a ``differential_drive_robot`` with no namespace, as the bundle's nav2).
ROBOT_FIELD = "robot"
#: Seconds (of wall clock) the scenario waits for Gazebo's clock before it fails.
SIM_WAIT = 120.0


def scenario_name(world_id: str, task_id: str) -> str:
    """The scenario of ``task_id``: an OSC identifier, unique within the world's file."""
    return ros_name(f"{world_id} {task_id}")


def launch_file(world_id: str) -> str:
    """The bundle's launch file, relative to the world folder (where world.osc sits)."""
    return f"{BUNDLE_DIR}/launch/{ros_name(world_id)}.launch.py"


def wall_limit(time_limit: Optional[float]) -> float:
    """Wall-clock seconds a run may take: the bundle launch file's default, 10 x the time limit + 120 s
    (600 s without a limit), given to the launch as ``wall_limit`` and used as the scenario's timeout."""
    return 600.0 if time_limit is None else 10.0 * float(time_limit) + 120.0


def writer_args(world) -> dict[str, Any]:
    """What :func:`to_osc` reads off a World besides its scene: its id and tasks as the bundle has them."""
    from worldgen.export.ros2 import tasks_spec

    return {"tasks": tasks_spec(world)["tasks"], "world_id": world.world_id}


def _pose(p: dict[str, float], z: bool) -> str:
    position = f"x: {fmt(p['x'])}m, y: {fmt(p['y'])}m" + (f", z: {fmt(p['z'])}m" if z else "")
    return f"pose_3d(position: position_3d({position}), orientation: orientation_3d(yaw: {fmt(p['yaw'])}rad))"


def _string(text: str) -> str:
    if "'" in text or "\\" in text or "\n" in text:  # OSC 2 strings have no escapes worldgen's ids would need
        raise ParameterError(f"{text!r} cannot be written as an OpenSCENARIO 2 string (a quote, a backslash or a "
                             "line break)")
    return f"'{text}'"


def _fields(movers) -> list[str]:
    """``name: osc_actor`` of each person and mover, names made OSC identifiers and kept apart from the robot's."""
    out, taken = [], {ROBOT_FIELD}
    for mover in movers:
        name = ros_name(mover.name)
        while name in taken:
            name = f"{name}_"
        taken.add(name)
        out += [f"    # {'person' if mover.person else 'mover'} {mover.name}: walked by world.sdf's <actor>",
                f"    {name}: osc_actor"]
    return out


def _scenario(world_id: str, task: dict, movers) -> list[str]:
    limit = task.get("time_limit")
    wall = wall_limit(limit)
    arguments = ", ".join(f"key_value(key: {_string(k)}, value: {_string(v)})"
                          for k, v in (("task", task["id"]), ("goal", "false"), ("wall_limit", fmt(wall))))
    topics = ", ".join(_string(t.name) for t in RECORDED)
    robot = ROBOT_FIELD
    lines = [f"scenario {scenario_name(world_id, task['id'])}:",
             f"    timeout({fmt(wall)}s)",
             f"    {robot}: differential_drive_robot",
             *_fields(movers),
             "    do serial:",
             f"        ros_launch(package_name: '', launch_file: {_string(launch_file(world_id))}, "
             f"arguments: [{arguments}], wait_for_shutdown: false)",
             f"        wait_for_sim(timeout: {fmt(SIM_WAIT)}s, world_name: {_string(world_id)})",
             f"        {robot}.init_nav2(initial_pose: {_pose(task['spawn'], True)}, "
             f"base_frame_id: {_string(BASE_FRAME)})",
             f"        bag_record(topics: [{topics}], hidden_topics: true, use_sim_time: true)"]
    goal = f"{robot}.nav_to_pose(goal_pose: {_pose(task['goal'], False)})"
    if limit is None:  # no limit recorded (an infeasible task): the wall-clock backstop alone ends the run
        lines.append(f"        {goal}")
    else:
        lines += ["        serial:", f"            timeout({fmt(limit)}s)", f"            {goal}"]
    return lines + ["        emit end"]


def to_osc(scene, name: str, tasks=None, world_id: Optional[str] = None) -> bytes:
    """``world.osc`` of the world ``name``: the imports, then one scenario per task of ``tasks`` (the bundle's
    task entries, :func:`writer_args`). ParameterError for a world without a task (nothing to navigate), or
    where :func:`~worldgen.export.osc_lint.lint` finds a fault."""
    world_id = world_id or name
    if not tasks:
        raise ParameterError(f"world {world_id} has no task: the osc format writes one scenario per task, "
                             "so it needs at least one")
    head = [f"# worldgen world {world_id}: one scenario per task, run in turn by scenario_execution.",
            "# Needs the world's ROS 2 bundle (worldgen generate --ros); see worldgen's docs/osc.md.",
            *(f"import osc.{lib}" for lib in LIBRARIES)]
    body: list[str] = []
    for task in tasks:
        body += ["", *_scenario(world_id, task, scene.movers)]
    text = "\n".join(head + body) + "\n"
    lint(text)
    return text.encode()
