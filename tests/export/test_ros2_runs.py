"""The ROS 2 bundle at run time, without ROS: the launch file's description run through stand-ins of
ROS's launch API, and run_loop.py over stand-in `ros2 launch` processes.

The stand-ins (tests/support/launch_standins.py) perform substitutions and conditions as launch does
(launch's substitution.py, conditions, OnProcessExit's matcher and callback with the exit event); they
run the bundle's own code, they do not emulate ROS. What each failure of a run becomes is in
test_ros2_failures.py. The real Gazebo server's shutdown is in test_ros2_gazebo.py; docs/ros2.md says what was
verified where.
"""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

import pytest
import yaml
from support.launch_standins import SLOW_ROS2, closed_bag, configs, counts, launch_run, loop, perform, process_exited

# -- the launch file -------------------------------------------------------------

def test_every_process_is_an_action_of_the_description(description):
    """`ros2 launch --print` lists the description's own entities (launch's LaunchIntrospector): every
    process must be one, not something an OpaqueFunction returns at launch time."""
    _, described = description
    kinds = [type(e).__name__ for e in described.args[0]]
    assert kinds.count("Node") == 4 and kinds.count("ExecuteProcess") == 3 and kinds.count("OpaqueFunction") == 1
    assert kinds.index("OpaqueFunction") < min(kinds.index("Node"), kinds.index("ExecuteProcess"))  # checks first
    assert kinds.count("IncludeLaunchDescription") == 1 and kinds.count("RegisterEventHandler") == 2


def test_a_run_starts_what_it_should(world, folder, description, tmp_path):
    _, described = description
    context, started = launch_run(described, configs(tmp_path, robot_state_publisher="true"))
    commands = {e.kwargs.get("name") or e.kwargs.get("executable"): cmd for e, cmd in started}
    assert set(commands) == {"gazebo", "create", "robot_state_publisher", "parameter_bridge", "record", "send_goal"}
    gazebo = next(e for e, _ in started if e.kwargs.get("name") == "gazebo")
    assert "shell" not in gazebo.kwargs  # launch's default: no shell, the signal reaches Gazebo itself
    assert commands["gazebo"] == ["gz", "sim", "-s", "-r", "--headless-rendering", "--seed", "5",
                                  str(folder / "ros2" / "world.sdf")]
    create = commands["create"]
    flags = dict(zip(create[2::2], create[3::2]))
    x, y, z, _, _, yaw = world.metadata["tasks"][1]["spawn"]
    assert (float(flags["-x"]), float(flags["-y"]), float(flags["-z"]), float(flags["-Y"])) == (x, y, z, yaw)
    assert flags["-file"] == str(tmp_path / "robot.urdf") and flags["-world"] == world.world_id
    bag = str(tmp_path / "bags" / f"{world.folder_name}__task_1__run2")
    assert commands["record"][commands["record"].index("-o") + 1] == bag
    assert f"worldgen.world_id={world.world_id}" in commands["record"] and "worldgen.task=task_1" in commands["record"]
    goal = commands["send_goal"]
    assert goal[goal.index("--result") + 1] == bag + ".result.yaml" and goal[goal.index("--task") + 1] == "task_1"
    state = next(e for e, _ in started if e.kwargs.get("executable") == "robot_state_publisher")
    value = state.kwargs["parameters"][0]["robot_description"]
    assert perform(value.value, context) == "<robot name='r'/>" and value.value_type is str
    nav2 = next(e for e in described.args[0] if type(e).__name__ == "IncludeLaunchDescription")
    nav2_args = {k: perform(v, context) for k, v in nav2.kwargs["launch_arguments"]}
    params = yaml.safe_load(Path(nav2_args["params_file"]).read_text())
    assert nav2_args["params_file"] == bag + ".nav2_params.yaml" and params["amcl"]["ros__parameters"]["max_particles"] == 2000
    assert params["amcl"]["ros__parameters"]["initial_pose"] == {"x": x, "y": y, "z": z, "yaw": yaw}
    timer = next(e for e in described.args[0] if type(e).__name__ == "TimerAction")
    assert float(perform(timer.kwargs["period"], context)) == pytest.approx(
        10 * world.metadata["tasks"][1]["time_limit"] + 120)


def test_a_robot_from_a_topic_is_spawned_from_it(description, tmp_path):
    _, described = description
    _, started = launch_run(described, configs(tmp_path, robot="", robot_topic="/robot_description"))
    [create] = [cmd for e, cmd in started if e.kwargs.get("executable") == "create"]
    assert create[create.index("-topic") + 1] == "/robot_description" and "-file" not in create


@pytest.mark.parametrize("bad, message", [
    ({"task": "task_9"}, "task must be one of task_0, task_1, got 'task_9'"),
    ({"run": "-1"}, "run must be a whole number >= 0, got '-1'"),
    ({"seed": "1.5"}, "seed must be a whole number >= 0, got '1.5'"),
    ({"robot": "/no/robot.urdf"}, "robot must be a URDF or SDF file, got '/no/robot.urdf' (no such file)"),
    ({"robot_topic": "/robot_description"}, "give robot:=FILE (URDF or SDF) or robot_topic:=TOPIC"),
    ({"robot_description": "/no/r.urdf"}, "robot_description must be a URDF or SDF file, got '/no/r.urdf'"),
    ({"robot": "", "robot_topic": "/d", "robot_state_publisher": "true"}, "robot_state_publisher:=true needs a URDF"),
    ({"storage": "zip"}, "storage must be one of mcap, sqlite3, got 'zip'"),
    ({"wall_limit": "0"}, "wall_limit must be a number of seconds > 0, got '0'"),
    ({"wall_limit": "nan"}, "wall_limit must be a number of seconds > 0, got 'nan'"),
    ({"params_file": "/no/nav2.yaml"}, "params_file must be a nav2 parameters file, got '/no/nav2.yaml'"),
    ({"robot_state_publisher": "yes"}, "robot_state_publisher must be true, false or auto, got 'yes'"),
])
def test_a_bad_argument_stops_the_launch_before_anything_is_written(description, tmp_path, bad, message):
    _, described = description
    with pytest.raises(ValueError) as caught:
        launch_run(described, configs(tmp_path, **bad))
    assert str(caught.value).startswith(message)
    assert not (tmp_path / "bags").exists()


def test_a_recorded_run_is_never_overwritten(description, tmp_path, world):
    _, described = description
    bags = tmp_path / "bags"
    bags.mkdir()
    (bags / f"{world.folder_name}__task_1__run2.result.yaml").write_text("outcome: succeeded\n")
    with pytest.raises(ValueError, match="recorded already"):
        launch_run(described, configs(tmp_path))
    assert sorted(p.name for p in bags.iterdir()) == [f"{world.folder_name}__task_1__run2.result.yaml"]


def _action(described, name):
    """The description's process ``name`` (an ExecuteProcess's name or a Node's executable)."""
    return next(e for e in described.args[0] if name in (e.kwargs.get("name"), e.kwargs.get("executable")))


def test_a_run_that_ends_without_an_answer_is_recorded(world, description, tmp_path):
    """launch returned 0 when the goal sender crashed, the robot failed to spawn or the wall clock ran
    out; the result file now says what happened, and the first answer stays."""
    _, described = description
    context, _ = launch_run(described, configs(tmp_path))
    result = tmp_path / "bags" / f"{world.folder_name}__task_1__run2.result.yaml"
    actions = process_exited(described, context, _action(described, "send_goal"), -11)
    assert [type(a).__name__ for a in actions] == ["Shutdown"]
    record = yaml.safe_load(result.read_text())
    assert (record["outcome"], record["reason"], record["task"], record["run"]) == (
        "crashed", "send_goal.py exited with -11", "task_1", 2)
    timer = next(e for e in described.args[0] if type(e).__name__ == "TimerAction")
    timer.kwargs["actions"][0].kwargs["function"](context)
    assert yaml.safe_load(result.read_text())["outcome"] == "crashed"  # the first answer stays
    result.unlink()
    timer.kwargs["actions"][0].kwargs["function"](context)
    assert yaml.safe_load(result.read_text())["reason"] == (
        f"wall-clock limit of {10 * world.metadata['tasks'][1]['time_limit'] + 120:g} s reached")
    result.unlink()
    spawns = [e for e in described.args[0] if e.kwargs.get("executable") == "create"]
    assert len(spawns) == 2 and process_exited(described, context, spawns[0], 0) == [] and not result.exists()
    assert [type(a).__name__ for a in process_exited(described, context, spawns[1], 1)] == ["Shutdown"]
    assert yaml.safe_load(result.read_text())["reason"] == "ros_gz_sim create exited with 1"
    result.unlink()
    gazebo = _action(described, "gazebo")
    context.is_shutdown = True  # Gazebo stopping because the run is shutting down is no crash
    assert process_exited(described, context, gazebo, 0) == [] and not result.exists()
    context.is_shutdown = False
    process_exited(described, context, gazebo, 134)
    assert yaml.safe_load(result.read_text())["reason"] == "Gazebo exited with 134"
    assert sorted(p.name for p in result.parent.iterdir() if ".tmp" in p.name) == []


# -- the loop ------------------------------------------------------------------

def test_the_loop_retries_crashed_and_timed_out_runs_then_sets_them_aside(world, folder, tmp_path, fake_ros2):
    scenario, env = fake_ros2
    scenario.write_text('{"task_0/1": ["crash", "good"], "task_0/2": ["timeout"], "task_0/3": ["silent", "good"]}')
    done = loop(folder, tmp_path, env, "--retries", "2")
    assert done.returncode == 1, done.stdout + done.stderr  # one run set aside
    assert counts(scenario) == {"task_0/0": 1, "task_0/1": 2, "task_0/2": 3, "task_0/3": 2}
    assert "4 runs: 3 done, 1 set aside" in done.stdout
    assert "crashed (crash), attempt 1 of 3" in done.stdout and "timed_out (timeout), attempt 3 of 3" in done.stdout
    bags = tmp_path / "bags"
    name = f"{world.folder_name}__task_0__run"
    for k in (0, 1, 3):
        assert yaml.safe_load((bags / f"{name}{k}.result.yaml").read_text())["outcome"] == "succeeded"
        assert (bags / f"{name}{k}").is_dir()
    aside = yaml.safe_load((bags / f"{name}2.result.yaml").read_text())
    assert aside["set_aside"] is True and aside["outcome"] == "timed_out" and len(aside["attempts"]) == 3
    assert aside["attempts"][0] == {"folder": f".attempts/{name}2.attempt0", "outcome": "timed_out", "reason": "timeout"}
    assert not (bags / f"{name}2").exists()  # no bag of a set-aside run where `worldgen judge bags/*/` looks
    silent = yaml.safe_load((bags / ".attempts" / f"{name}3.attempt0" / f"{name}3.result.yaml").read_text())
    assert silent == {"outcome": "crashed", "reason": "ros2 launch exited with 1 and no result file",
                      "written_by": "run_loop.py", "world_dir": str(folder), "world_id": world.world_id,
                      "task": "task_0", "run": 3, "seed": 3}
    assert (bags / ".attempts" / f"{name}1.attempt0" / f"{name}1").is_dir()  # the crashed attempt's bag, kept

    again = loop(folder, tmp_path, env, "--retries", "2")  # resume: nothing runs again
    assert again.returncode == 1 and counts(scenario) == {"task_0/0": 1, "task_0/1": 2, "task_0/2": 3, "task_0/3": 2}
    assert again.stdout.count("skip ") == 4 and "set aside already" in again.stdout


def test_an_interrupted_run_is_run_again_on_resume(world, folder, tmp_path, fake_ros2):
    scenario, env = fake_ros2
    scenario.write_text("{}")
    bags = tmp_path / "bags"
    name = f"{world.folder_name}__task_0__run"
    (bags / f"{name}0").mkdir(parents=True)  # the loop was stopped mid-run: a bag, no result
    closed_bag(bags / f"{name}1")
    (bags / f"{name}1.result.yaml").write_text("outcome: failed\n")  # nav2's answer over a bag: done
    done = loop(folder, tmp_path, env)
    assert done.returncode == 0, done.stdout + done.stderr
    assert counts(scenario) == {"task_0/0": 1, "task_0/2": 1, "task_0/3": 1}
    # The loop itself was stopped: no attempt of the run's, so it is kept as an interrupted one.
    assert (bags / ".attempts" / f"{name}0.interrupted0" / f"{name}0").is_dir()
    assert not list((bags / ".attempts").glob("*.attempt*"))
    assert yaml.safe_load((bags / f"{name}0.result.yaml").read_text())["outcome"] == "succeeded"


@pytest.mark.parametrize("args, message", [
    (["--runs", "0", "--robot", "R"], "--runs must be >= 1"),
    (["--robot", "/no/robot.urdf"], "--robot must be a URDF or SDF file, got '/no/robot.urdf' (no such file)"),
    (["--robot", "R", "--robot-topic", "/d"], "give --robot FILE or --robot-topic TOPIC, not both"),
    (["--robot", "R", "--launch-arg", "storage=mcap"], "--launch-arg must be KEY:=VALUE, got 'storage=mcap'"),
])
def test_the_loop_checks_its_arguments_before_writing(folder, tmp_path, args, message):
    (tmp_path / "r.urdf").write_text("<robot name='r'/>")
    args = [str(tmp_path / "r.urdf") if a == "R" else a for a in args]
    done = subprocess.run([sys.executable, str(folder / "ros2" / "run_loop.py"), *args, "--out", str(tmp_path / "bags"),
                           str(folder)], capture_output=True, text=True, timeout=60)
    assert done.returncode == 2 and done.stderr.startswith(f"error: {message}")
    assert done.stderr.count("\n") == 1 and not (tmp_path / "bags").exists()
    no_bundle = subprocess.run([sys.executable, str(folder / "ros2" / "run_loop.py"), "--robot", str(tmp_path / "r.urdf"),
                                "--out", str(tmp_path / "bags"), str(tmp_path)], capture_output=True, text=True, timeout=60)
    assert no_bundle.returncode == 2 and "must hold one ros2/launch/*.launch.py" in no_bundle.stderr
    assert not (tmp_path / "bags").exists()
    no_ros = subprocess.run([sys.executable, str(folder / "ros2" / "run_loop.py"), "--out", str(tmp_path / "bags"),
                             str(folder)], capture_output=True, text=True, timeout=60,
                            env={**os.environ, "PATH": str(tmp_path / "empty")})
    assert no_ros.returncode == 2 and no_ros.stderr == (
        "error: ros2 is not on the PATH: source your ROS 2 setup first (e.g. /opt/ros/jazzy/setup.bash)\n")
    assert not (tmp_path / "bags").exists()


def test_the_bundles_own_robot_is_spawned_unless_the_run_names_another(folder, description, tmp_path):
    _, described = description
    context, started = launch_run(described, configs(tmp_path, robot=""))
    create = next(cmd for e, cmd in started if e.kwargs.get("executable") == "create")
    assert create[create.index("-file") + 1] == str(folder / "ros2" / "robot.sdf")
    state = next(e for e, _ in started if e.kwargs.get("executable") == "robot_state_publisher")
    urdf = perform(state.kwargs["parameters"][0]["robot_description"].value, context)
    assert urdf == (folder / "ros2" / "robot.urdf").read_text()
    (tmp_path / "mine.sdf").write_text("<sdf version='1.9'/>")
    _, started = launch_run(described, configs(tmp_path, robot=str(tmp_path / "mine.sdf")))
    kinds = [e.kwargs.get("executable") for e, _ in started]
    assert "robot_state_publisher" not in kinds  # auto: a robot of the user's own, no URDF named


def test_an_interrupted_loop_lets_launch_stop_what_it_started(folder, tmp_path, fake_ros2):
    import signal
    import time

    scenario, env = fake_ros2
    (tmp_path / "bin" / "ros2").write_text(SLOW_ROS2.format(python=sys.executable))
    (tmp_path / "robot.urdf").write_text("<robot name='r'/>")
    looping = subprocess.Popen([sys.executable, str(folder / "ros2" / "run_loop.py"), "--out", str(tmp_path / "bags"),
                             str(folder)], env=env, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    deadline = time.monotonic() + 30
    while not Path(str(scenario) + ".started").exists() and time.monotonic() < deadline:
        time.sleep(0.05)
    looping.send_signal(signal.SIGINT)  # only the loop, as `kill -INT`; a terminal's Ctrl-C reaches both
    _, err = looping.communicate(timeout=30)
    assert looping.returncode == 130 and "run the same command again to resume" in err
    assert Path(str(scenario) + ".stopped").read_text() == "clean"  # launch finished its own shutdown


# -- goal:=false: the simulation and nav2 for a driver that sends the goal itself (world.osc) --

def test_without_the_goal_a_run_starts_the_simulation_and_nav2_only(world, description, tmp_path):
    """scenario_execution's world.osc starts the launch with goal:=false, then records and navigates itself:
    the launch starts neither the recorder nor the goal sender, writes the nav2 parameters, refuses no
    earlier result, and leaves the result file to the driver whatever ends the run."""
    _, described = description
    bags = tmp_path / "bags"
    bags.mkdir()
    earlier = bags / f"{world.folder_name}__task_1__run2.result.yaml"
    earlier.write_text("outcome: succeeded\n")
    context, started = launch_run(described, configs(tmp_path, goal="false", robot_state_publisher="true"))
    names = {e.kwargs.get("name") or e.kwargs.get("executable") for e, _ in started}
    assert names == {"gazebo", "create", "robot_state_publisher", "parameter_bridge"}
    assert (bags / f"{world.folder_name}__task_1__run2.nav2_params.yaml").exists()
    gazebo = next(e for e, _ in started if e.kwargs.get("name") == "gazebo")
    earlier.unlink()
    ended = process_exited(described, context, gazebo, 134, "gazebo-1")  # a crash ends the run: the driver records it
    assert any(type(e).__name__ == "Shutdown" for e in ended), ended
    assert not earlier.exists()
    with pytest.raises(ValueError, match="goal must be true or false, got 'no'"):
        launch_run(described, configs(tmp_path, goal="no"))
