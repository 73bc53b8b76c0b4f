"""Stand-ins for ROS 2 the bundle's run-time tests share (tests/export/test_ros2_runs.py,
test_ros2_failures.py): ROS's launch API, what launch does with a description and with a process's exit,
and a `ros2 launch` process for run_loop.py.

The launch stand-ins perform substitutions and conditions as launch does (launch's substitution.py,
conditions, OnProcessExit's matcher and callback with the ProcessExited event, OnShutdown's with the
Shutdown event); they run the bundle's own code, they do not emulate ROS.
"""

from __future__ import annotations

import subprocess
import sys
import types
from pathlib import Path

import yaml

__all__ = ["perform", "fake_launch_api", "NAV2_PARAMS", "described", "Context", "launch_run", "process_exited", "shutdown", "configs",
           "FAKE_ROS2", "SLOW_ROS2", "ros2_env", "loop", "counts", "closed_bag"]


class _Action:
    def __init__(self, *args, **kwargs):
        self.args, self.kwargs = args, kwargs


class _Substitution:
    """launch.substitution.Substitution: describe() and perform(context)."""

    def describe(self):
        return type(self).__name__


class _LaunchConfiguration(_Substitution):
    def __init__(self, name):
        self.name = name

    def perform(self, context):
        return context.launch_configurations[self.name]


def perform(value, context) -> str:
    """One command-line argument or parameter as launch makes it: text, a substitution, or a list of them."""
    if isinstance(value, (list, tuple)):
        return "".join(perform(v, context) for v in value)
    return value.perform(context) if hasattr(value, "perform") else str(value)


class _IfCondition:
    def __init__(self, predicate):
        self.predicate = predicate

    def evaluate(self, context):
        return perform(self.predicate, context).lower() in ("true", "1")


class _UnlessCondition(_IfCondition):
    def evaluate(self, context):
        return not super().evaluate(context)


class _ParameterValue:
    def __init__(self, value, value_type=None):
        self.value, self.value_type = value, value_type


def fake_launch_api(monkeypatch, share: Path) -> None:
    """ROS's launch modules as stand-ins in sys.modules (undone by ``monkeypatch``)."""
    classes = {"launch": {"LaunchDescription": type("LaunchDescription", (_Action,), {})},
               "launch.actions": {n: type(n, (_Action,), {}) for n in (
                   "DeclareLaunchArgument", "ExecuteProcess", "IncludeLaunchDescription", "OpaqueFunction",
                   "RegisterEventHandler", "Shutdown", "TimerAction")},
               "launch.conditions": {"IfCondition": _IfCondition, "UnlessCondition": _UnlessCondition},
               "launch.event_handlers": {n: type(n, (_Action,), {}) for n in ("OnProcessExit", "OnShutdown")},
               "launch.launch_description_sources": {"PythonLaunchDescriptionSource": type("Source", (_Action,), {})},
               "launch.substitution": {"Substitution": _Substitution},
               "launch.substitutions": {"LaunchConfiguration": _LaunchConfiguration},
               "launch_ros": {}, "launch_ros.actions": {"Node": type("Node", (_Action,), {})},
               "launch_ros.parameter_descriptions": {"ParameterValue": _ParameterValue},
               "ament_index_python": {},
               "ament_index_python.packages": {"get_package_share_directory": lambda package: str(share / package)}}
    for name, attrs in classes.items():
        module = types.ModuleType(name)
        module.__dict__.update(attrs)
        monkeypatch.setitem(sys.modules, name, module)


class Context:
    """launch's LaunchContext as the bundle reads it: the arguments' values and whether it is shutting down."""

    def __init__(self, configs):
        self.launch_configurations = dict(configs)
        self.is_shutdown = False


def launch_run(description, configs: dict):
    """What launch does with the description: arguments get their defaults, then the entities in order:
    an OpaqueFunction runs (an exception stops the launch there), a process starts if its condition holds.
    Returns (context, [(action, its command as strings)])."""
    context = Context({})
    for entity in description.args[0]:
        if type(entity).__name__ == "DeclareLaunchArgument":
            context.launch_configurations.setdefault(entity.args[0], entity.kwargs["default_value"])
    context.launch_configurations.update(configs)
    started = []
    for entity in description.args[0]:
        kind = type(entity).__name__
        if kind == "OpaqueFunction":
            entity.kwargs["function"](context)
        elif kind in ("Node", "ExecuteProcess"):
            condition = entity.kwargs.get("condition")
            if condition is None or condition.evaluate(context):
                cmd = entity.kwargs.get("cmd") or [entity.kwargs["package"], entity.kwargs["executable"],
                                                   *entity.kwargs.get("arguments", [])]
                started.append((entity, [perform(a, context) for a in cmd]))
    return context, started



#: The parts of nav2 1.3.13's nav2_bringup/params/nav2_params.yaml the bundle's merge touches, as written
#: there: AMCL, the controller's goal checker (0.25 m), the global costmap's static layer (no map_topic).
NAV2_PARAMS = {
    "amcl": {"ros__parameters": {"use_sim_time": False, "max_particles": 2000}},
    "controller_server": {"ros__parameters": {
        "use_sim_time": False, "controller_frequency": 20.0, "goal_checker_plugins": ["general_goal_checker"],
        "general_goal_checker": {"stateful": True, "plugin": "nav2_controller::SimpleGoalChecker",
                                 "xy_goal_tolerance": 0.25, "yaw_goal_tolerance": 0.25}}},
    "global_costmap": {"global_costmap": {"ros__parameters": {
        "robot_radius": 0.22, "plugins": ["static_layer", "obstacle_layer", "inflation_layer"],
        "static_layer": {"plugin": "nav2_costmap_2d::StaticLayer", "map_subscribe_transient_local": True}}}},
}


def described(folder, world_id, tmp_path, monkeypatch):
    """(the launch module, its launch description) of the bundle in ``folder``, under the stand-ins, with a
    nav2_bringup share holding NAV2_PARAMS."""
    share = tmp_path / "share"
    (share / "nav2_bringup" / "params").mkdir(parents=True)
    (share / "nav2_bringup" / "params" / "nav2_params.yaml").write_text(yaml.safe_dump(NAV2_PARAMS))
    fake_launch_api(monkeypatch, share)
    monkeypatch.setenv("ROS_DISTRO", "jazzy")
    (tmp_path / "robot.urdf").write_text("<robot name='r'/>")
    from support.bundle import load_script as load
    from worldgen.export import ros2

    launch = load(folder / "ros2" / "launch" / f"{ros2.ros_name(world_id)}.launch.py", "runs_launch")
    return launch, launch.generate_launch_description()


def process_exited(described, context, action, returncode, process_name="process-1"):
    """What launch does when ``action``'s process exits: every OnProcessExit handler whose target is that
    action, or that names none (launch's OnActionEventBase matcher), called with the ProcessExited event;
    the entities they return."""
    event = types.SimpleNamespace(action=action, returncode=returncode, process_name=process_name)
    returned = []
    for entity in described.args[0]:
        handler = entity.args[0] if type(entity).__name__ == "RegisterEventHandler" else None
        if type(handler).__name__ == "OnProcessExit":
            target = handler.kwargs.get("target_action")
            if target is None or target is action:
                returned += handler.kwargs["on_exit"](event, context) or []
    return returned


def shutdown(described, context, due_to_sigint):
    """launch's shutdown: the OnShutdown handlers get the Shutdown event, then the context is shutting down."""
    event = types.SimpleNamespace(reason="ctrl-c (SIGINT)" if due_to_sigint else "test", due_to_sigint=due_to_sigint)
    for entity in described.args[0]:
        handler = entity.args[0] if type(entity).__name__ == "RegisterEventHandler" else None
        if type(handler).__name__ == "OnShutdown":
            handler.kwargs["on_shutdown"](event, context)
    context.is_shutdown = True


def configs(tmp_path, **more):
    """Launch arguments of one run (task_1, run 2, seed 5), ``more`` over them."""
    return {"robot": str(tmp_path / "robot.urdf"), "task": "task_1", "run": "2", "seed": "5",
            "out": str(tmp_path / "bags"), **more}


#: A stand-in for `ros2 launch`: reads its arguments as the launch file would, then does what the
#: scenario file says for this run's next attempt (JSON: {"<task>/<run>": ["good" | "crash" | "silent" |
#: "timeout" | "nobag", ...]}), and counts its launches. "crash": the bag begun, a crashed result, exit 0
#: (launch's status after a crash); "silent": exit 1 with no result; "timeout": a timed_out result;
#: "nobag": nav2's success over a bag the recorder never closed (no metadata.yaml, as when it died).
FAKE_ROS2 = r'''#!{python}
import json, os, sys
args = dict(a.split(':=', 1) for a in sys.argv[3:])
scenario = json.load(open(os.environ['FAKE_SCENARIO']))
counts_path = os.environ['FAKE_SCENARIO'] + '.counts'
counts = json.load(open(counts_path)) if os.path.exists(counts_path) else {{}}
key = args['task'] + '/' + args['run']
attempt = counts.get(key, 0)
counts[key] = attempt + 1
json.dump(counts, open(counts_path, 'w'))
plan = scenario.get(key, ['good'])
what = plan[min(attempt, len(plan) - 1)]
folder = os.path.basename(os.path.dirname(os.path.dirname(os.path.dirname(sys.argv[2]))))
bag = os.path.join(args['out'], folder + '__' + args['task'] + '__run' + args['run'])
os.makedirs(args['out'], exist_ok=True)
if what == 'silent':
    sys.exit(1)
os.makedirs(bag)
if what != 'nobag':  # what rosbag2 leaves on closing a bag: metadata.yaml listing its storage file
    open(os.path.join(bag, 'b_0.mcap'), 'wb').write(b'MCAP')
    with open(os.path.join(bag, 'metadata.yaml'), 'w') as fh:
        fh.write('rosbag2_bagfile_information:\n  relative_file_paths: [b_0.mcap]\n  message_count: 12\n')
outcome = {{'good': 'succeeded', 'crash': 'crashed', 'timeout': 'timed_out', 'nobag': 'succeeded'}}[what]
with open(bag + '.result.yaml', 'w') as fh:
    fh.write('outcome: ' + outcome + '\nreason: ' + what + '\n')
'''


def closed_bag(bag: Path, messages: int = 12) -> Path:
    """A rosbag2 folder as the recorder leaves it on closing: one storage file and metadata.yaml."""
    bag.mkdir(parents=True)
    (bag / "b_0.mcap").write_bytes(b"MCAP")
    (bag / "metadata.yaml").write_text("rosbag2_bagfile_information:\n  relative_file_paths: [b_0.mcap]\n"
                                       f"  message_count: {messages}\n")
    return bag


def ros2_env(tmp_path: Path, script: str = FAKE_ROS2) -> tuple[Path, dict]:
    """A `ros2` stand-in (``script``) first on the PATH: (its scenario file, the environment to run in)."""
    import os

    bin_dir = tmp_path / "bin"
    bin_dir.mkdir(exist_ok=True)
    (bin_dir / "ros2").write_text(script.format(python=sys.executable))
    (bin_dir / "ros2").chmod(0o755)
    scenario = tmp_path / "scenario.json"
    return scenario, {**os.environ, "PATH": f"{bin_dir}{os.pathsep}{os.environ['PATH']}", "FAKE_SCENARIO": str(scenario)}


def loop(folder, tmp_path, env, *more):
    """run_loop.py over ``folder``: 4 runs, a robot file of the test's, bags in tmp_path/bags."""
    (tmp_path / "robot.urdf").write_text("<robot name='r'/>")
    return subprocess.run([sys.executable, str(folder / "ros2" / "run_loop.py"), "--runs", "4", "--robot",
                           str(tmp_path / "robot.urdf"), "--out", str(tmp_path / "bags"), *more, str(folder)],
                          capture_output=True, text=True, timeout=120, env=env)


def counts(scenario):
    """How many times the stand-in was launched, per task/run."""
    return yaml.safe_load(Path(str(scenario) + ".counts").read_text())


#: A `ros2 launch` stand-in that, on SIGINT, takes a while to stop what it started (launch's escalation
#: takes up to 10 s) and notes that it finished its shutdown.
SLOW_ROS2 = r'''#!{python}
import os, signal, sys, time
def stop(signum, frame):
    time.sleep(1.0)  # stopping Gazebo, nav2, the recorder
    open(os.environ['FAKE_SCENARIO'] + '.stopped', 'w').write('clean')
    sys.exit(0)
signal.signal(signal.SIGINT, stop)
open(os.environ['FAKE_SCENARIO'] + '.started', 'w').write('')
time.sleep(60)
'''
