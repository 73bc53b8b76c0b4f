"""Every way a ROS 2 run of the bundle fails is noticed (issue 39, E1-E8), at launch level: the bundle's
launch description under stand-ins of ROS's launch API, with stand-in processes for nav2's (actions the
description does not hold, as nav2_bringup's are), and run_loop.py over stand-in `ros2 launch` processes.

Each test fails on the bundle before issue 39 (the last merge of main before it). docs/ros2.md says what
was run here and what was only read in ROS's sources.
"""

from __future__ import annotations

import os
import signal
import subprocess
import sys
import time
from collections import deque
from pathlib import Path

import numpy as np
import pytest
import yaml
from support.launch_standins import configs, counts, described, launch_run, loop, process_exited, ros2_env, shutdown

import worldgen


def _result(tmp_path, world, run=2, task="task_1"):
    return tmp_path / "bags" / f"{world.folder_name}__{task}__run{run}.result.yaml"


def _nav2_process(name):
    """A process nav2_bringup's launch file starts (a Node of its own description, not the bundle's)."""
    from launch_ros.actions import Node

    return Node(package="nav2_controller", executable=name, name=name)


def _action(described, name):
    return next(e for e in described.args[0] if name in (e.kwargs.get("name"), e.kwargs.get("executable")))


# -- E1: nav2's goal checker no looser than the task -------------------------------------------------

def test_e1_nav2_counts_a_goal_reached_only_within_the_tasks_tolerance(world, folder, description, tmp_path):
    """nav2 1.3.13's params file lets SimpleGoalChecker succeed 0.25 m from the goal; the task allows 0.2 m."""
    launch, described = description
    launch_run(described, configs(tmp_path))
    params = yaml.safe_load(Path(str(_result(tmp_path, world)).replace(".result.", ".nav2_params.")).read_text())
    controller = params["controller_server"]["ros__parameters"]
    tolerance = world.metadata["tasks"][1]["goal_tolerance"]
    assert tolerance < 0.25 and controller["goal_checker_plugins"] == ["general_goal_checker"]
    assert controller["general_goal_checker"]["xy_goal_tolerance"] == tolerance
    assert controller["general_goal_checker"]["plugin"] == "nav2_controller::SimpleGoalChecker"  # the rest kept
    overrides = yaml.safe_load((folder / "ros2" / "nav2" / "task_1.yaml").read_text())
    assert overrides["controller_server"]["ros__parameters"]["general_goal_checker"] == {"xy_goal_tolerance": tolerance}
    # A params file of the user's naming other checkers: each capped, a tighter one left as it is.
    own = {"controller_server": {"ros__parameters": {"goal_checker_plugins": ["loose", "tight"],
                                                     "loose": {"xy_goal_tolerance": 0.5},
                                                     "tight": {"xy_goal_tolerance": 0.05}}}}
    capped = launch.merged_params(own, overrides, str(folder), tolerance)["controller_server"]["ros__parameters"]
    assert (capped["loose"]["xy_goal_tolerance"], capped["tight"]["xy_goal_tolerance"]) == (tolerance, 0.05)
    bare = launch.merged_params({"controller_server": {"ros__parameters": {}}}, {}, str(folder), tolerance)
    assert bare["controller_server"]["ros__parameters"]["goal_checker"]["xy_goal_tolerance"] == tolerance


# -- E2: the recorder's death, a bag that cannot be read ---------------------------------------------

@pytest.mark.parametrize("code", [1, 0, -6])
def test_e2_the_recorders_death_is_a_crash(world, description, tmp_path, code):
    _, described = description
    context, _ = launch_run(described, configs(tmp_path))
    actions = process_exited(described, context, _action(described, "record"), code, "ros2-7")
    assert [type(a).__name__ for a in actions] == ["Shutdown"]
    record = yaml.safe_load(_result(tmp_path, world).read_text())
    assert (record["outcome"], record["process"], record["reason"]) == (
        "crashed", "ros2 bag record", f"ros2 bag record exited with {code}")


def test_e2_nav2s_answer_over_a_bag_that_cannot_be_read_is_a_crash(world, description, tmp_path):
    """The goal sender answered, then the recorder closed nothing (it died, the disk was full)."""
    _, described = description
    context, _ = launch_run(described, configs(tmp_path))
    result = _result(tmp_path, world)
    result.write_text(yaml.safe_dump({"outcome": "succeeded", "task": "task_1", "run": 2, "seed": 5}))
    Path(str(result).replace(".result.yaml", "")).mkdir()  # the bag begun, never closed: no metadata.yaml
    process_exited(described, context, _action(described, "send_goal"), 0)
    shutdown(described, context, due_to_sigint=False)
    assert process_exited(described, context, _action(described, "record"), 0) == []
    record = yaml.safe_load(result.read_text())
    assert (record["outcome"], record["nav2_outcome"], record["process"]) == ("crashed", "succeeded", "ros2 bag record")
    assert record["reason"].startswith("no readable bag: ") and "metadata.yaml is missing" in record["reason"]


def test_e2_the_loop_never_counts_a_run_without_a_readable_bag_as_done(world, folder, tmp_path, fake_ros2):
    scenario, env = fake_ros2
    scenario.write_text('{"task_0/0": ["nobag", "good"], "task_0/1": ["nobag"]}')
    done = loop(folder, tmp_path, env, "--runs", "2", "--retries", "1")
    assert done.returncode == 1, done.stdout + done.stderr
    assert counts(scenario) == {"task_0/0": 2, "task_0/1": 2} and "2 runs: 1 done, 1 set aside" in done.stdout
    bags, name = tmp_path / "bags", f"{world.folder_name}__task_0__run"
    first = yaml.safe_load((bags / ".attempts" / f"{name}0.attempt0" / f"{name}0.result.yaml").read_text())
    assert (first["outcome"], first["nav2_outcome"]) == ("crashed", "succeeded")
    assert yaml.safe_load((bags / f"{name}1.result.yaml").read_text())["set_aside"] is True
    # A result that says done over a bag that cannot be read is not skipped on resume either.
    closed = yaml.safe_load((bags / f"{name}0.result.yaml").read_text())
    assert closed["outcome"] == "succeeded"
    (bags / f"{name}0" / "metadata.yaml").unlink()
    again = loop(folder, tmp_path, env, "--runs", "1", "--retries", "2")
    assert counts(scenario)["task_0/0"] == 3 and again.returncode == 0, again.stdout + again.stderr


# -- E3: any process's crash, nav2's included, ends the run -------------------------------------------

@pytest.mark.parametrize("answered_later", ["failed", None])
def test_e3_a_nav2_process_that_crashes_ends_the_run_as_crashed_naming_it(world, folder, description, tmp_path,
                                                                          answered_later):
    """Before nav2 is active (no answer ever) or mid-goal (the lifecycle manager then aborts the goal and
    the goal sender writes nav2's `failed`): the run is a crash at once, not a wall-limit wait."""
    from support.bundle import load_script

    _, described = description
    context, _ = launch_run(described, configs(tmp_path))
    controller = _nav2_process("controller_server")
    actions = process_exited(described, context, controller, -11, "controller_server-9")
    assert [type(a).__name__ for a in actions] == ["Shutdown"]
    result = _result(tmp_path, world)
    if answered_later:
        goal = load_script(folder / "ros2" / "send_goal.py", "failures_send_goal")
        assert not goal.write_result(str(result), {"outcome": answered_later})
    record = yaml.safe_load(result.read_text())
    assert (record["outcome"], record["process"], record["reason"]) == (
        "crashed", "controller_server-9", "controller_server-9 exited with -11")
    assert (record["world_id"], record["task"], record["run"], record["seed"]) == (world.world_id, "task_1", 2, 5)


def test_e3_exits_in_shutdown_and_clean_exits_of_nav2_are_no_crash(world, description, tmp_path):
    _, described = description
    context, _ = launch_run(described, configs(tmp_path))
    assert process_exited(described, context, _nav2_process("amcl"), 0, "amcl-3") == []
    shutdown(described, context, due_to_sigint=False)
    assert process_exited(described, context, _nav2_process("amcl"), -15, "amcl-3") == []
    assert process_exited(described, context, _action(described, "parameter_bridge"), 1) == []
    assert not _result(tmp_path, world).exists()


def test_e3_a_bridge_that_ends_mid_run_is_a_crash(world, description, tmp_path):
    _, described = description
    context, _ = launch_run(described, configs(tmp_path))
    assert process_exited(described, context, _action(described, "parameter_bridge"), 0)
    assert yaml.safe_load(_result(tmp_path, world).read_text())["reason"] == "parameter_bridge exited with 0"


# -- E4, E5: SIGTERM and interrupts ------------------------------------------------------------------

#: A `ros2 launch` stand-in that behaves as launch does on signals (launch_service.py, execute_local.py,
#: Jazzy): on SIGINT it sends its processes (a child standing in for Gazebo) nothing, expecting the
#: Ctrl-C to have reached them too, waits, and escalates to SIGTERM for what did not stop; SIGTERM
#: cancels launch's run task at once, which leaves the child running ("can result in orphaned processes").
SIGNALLED_ROS2 = r'''#!{python}
import os, signal, subprocess, sys, time
child = subprocess.Popen([sys.executable, '-c', 'import time; time.sleep(120)'])
mark = os.environ['FAKE_SCENARIO']
def stop(signum, frame):
    try:  # a Ctrl-C reached every process of the group: launch waits for them before it escalates
        child.wait(timeout=3)
        how = 'clean'
    except subprocess.TimeoutExpired:
        child.terminate()
        how = 'escalated to SIGTERM'
    open(mark + '.stopped', 'w').write(how)
    sys.exit(0)
def orphan(signum, frame):
    open(mark + '.orphaned', 'w').write(str(child.pid))
    os._exit(1)
signal.signal(signal.SIGINT, stop)
signal.signal(signal.SIGTERM, orphan)
open(mark + '.child', 'w').write(str(child.pid) + ' ' + str(os.getpid()))
open(mark + '.started', 'w').write('')
time.sleep(120)
'''


def _start_loop(folder, tmp_path, env, scenario, sigint_ignored=False):
    """run_loop.py, its own process group's leader; ``sigint_ignored``: as a script's `&` starts it."""
    def ignore():
        signal.signal(signal.SIGINT, signal.SIG_IGN)

    proc = subprocess.Popen([sys.executable, str(folder / "ros2" / "run_loop.py"), "--retries", "0", "--out",
                             str(tmp_path / "bags"), str(folder)], env=env, stdout=subprocess.PIPE,
                            stderr=subprocess.PIPE, text=True, start_new_session=True,
                            preexec_fn=ignore if sigint_ignored else None)
    deadline = time.monotonic() + 30
    while not Path(str(scenario) + ".started").exists() and time.monotonic() < deadline:
        time.sleep(0.05)
    return proc


def _alive(pid: int) -> bool:
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    return True


@pytest.mark.parametrize("to", ["loop", "group"])
def test_e4_sigterm_to_the_loop_stops_the_run_it_started(world, folder, tmp_path, to):
    """`docker stop` signals the loop; `timeout` and a CI cancel signal its process group."""
    scenario, env = ros2_env(tmp_path, SIGNALLED_ROS2)
    proc = _start_loop(folder, tmp_path, env, scenario)
    child, launch = map(int, Path(str(scenario) + ".child").read_text().split())
    try:
        (os.killpg if to == "group" else os.kill)(proc.pid, signal.SIGTERM)
        _, err = proc.communicate(timeout=30)
        assert proc.returncode == 143 and "interrupted (SIGTERM)" in err, err
        assert Path(str(scenario) + ".stopped").read_text() == "clean"
        assert not Path(str(scenario) + ".orphaned").exists() and not _alive(child)
    finally:
        for pid in (child, launch):  # the test's own stand-ins, left running by a failure
            if _alive(pid):
                os.kill(pid, signal.SIGKILL)
        if proc.poll() is None:
            proc.kill()
    record = yaml.safe_load(_result(tmp_path, world, run=0, task="task_0").read_text())
    assert (record["outcome"], record["task"], record["run"], record["seed"]) == ("interrupted", "task_0", 0, 0)


def test_e5_an_interrupted_run_is_no_attempt(world, folder, tmp_path):
    """Three interrupted loops with --retries 0, then one that runs: the run is done, not set aside."""
    scenario, env = ros2_env(tmp_path, SIGNALLED_ROS2)
    for _ in range(3):
        for mark in (".started", ".stopped"):
            Path(str(scenario) + mark).unlink(missing_ok=True)
        proc = _start_loop(folder, tmp_path, env, scenario)
        proc.send_signal(signal.SIGINT)  # Ctrl-C reaches the loop (launch runs in a session of its own)
        _, err = proc.communicate(timeout=30)
        assert proc.returncode == 130 and Path(str(scenario) + ".stopped").exists(), err
    bags, name = tmp_path / "bags", f"{world.folder_name}__task_0__run0"
    scenario, env = ros2_env(tmp_path)
    scenario.write_text("{}")
    done = subprocess.run([sys.executable, str(folder / "ros2" / "run_loop.py"), "--retries", "0", "--out",
                           str(bags), str(folder)], env=env, capture_output=True, text=True, timeout=60)
    assert done.returncode == 0 and "1 runs: 1 done, 0 set aside" in done.stdout, done.stdout + done.stderr
    kept = sorted(p.name for p in (bags / ".attempts").iterdir())
    assert kept == [f"{name}.interrupted{i}" for i in range(3)]
    first = yaml.safe_load((bags / ".attempts" / kept[0] / f"{name}.result.yaml").read_text())
    assert first["outcome"] == "interrupted" and first["reason"] == "the loop got SIGINT during the run"


def test_e5_a_loop_started_with_sigint_ignored_still_stops_its_run_on_sigint(world, folder, tmp_path):
    """A loop started in a script's background inherits SIGINT ignored; it sets its own handler, so the
    SIGINT it forwards is not ignored by launch and the processes launch starts either."""
    scenario, env = ros2_env(tmp_path, SIGNALLED_ROS2)
    proc = _start_loop(folder, tmp_path, env, scenario, sigint_ignored=True)
    child, launch = map(int, Path(str(scenario) + ".child").read_text().split())
    try:
        proc.send_signal(signal.SIGINT)
        _, err = proc.communicate(timeout=30)
        assert proc.returncode == 130 and Path(str(scenario) + ".stopped").read_text() == "clean", err
    finally:
        for pid in (child, launch):
            if _alive(pid):
                os.kill(pid, signal.SIGKILL)
        if proc.poll() is None:
            proc.kill()


def test_e5_ctrl_c_of_a_launch_is_recorded_interrupted(world, description, tmp_path):
    _, described = description
    context, _ = launch_run(described, configs(tmp_path))
    shutdown(described, context, due_to_sigint=True)
    process_exited(described, context, _action(described, "send_goal"), 5)
    record = yaml.safe_load(_result(tmp_path, world).read_text())
    assert (record["outcome"], record["reason"]) == ("interrupted", "ros2 launch was interrupted (SIGINT)")


# -- E6: door tasks nav2 can plan ------------------------------------------------------------------

def _pgm(path: Path) -> np.ndarray:
    magic, cols, rows, _, data = path.read_bytes().split(maxsplit=4)
    assert magic == b"P5"
    return np.frombuffer(data, dtype=np.uint8).reshape(int(rows), int(cols))


def _reachable(grid: np.ndarray, origin, resolution, radius, start, goal) -> bool:
    """Whether a disc of ``radius`` gets from ``start`` to ``goal`` over the map's free cells (254), 4-connected
    over cells whose centres are at least ``radius`` from every other cell (as a costmap inflates)."""
    from scipy import ndimage

    rows = grid.shape[0]
    clear = ndimage.distance_transform_edt(grid == 254) * resolution >= radius

    def cell(x, y):
        return rows - 1 - int((y - origin[1]) // resolution), int((x - origin[0]) // resolution)

    start_cell, goal_cell = cell(*start), cell(*goal)
    seen, todo = {start_cell}, deque([start_cell])
    while todo:
        r, c = todo.popleft()
        if (r, c) == goal_cell:
            return True
        for nxt in ((r + 1, c), (r - 1, c), (r, c + 1), (r, c - 1)):
            if nxt not in seen and 0 <= nxt[0] < rows and 0 <= nxt[1] < grid.shape[1] and clear[nxt]:
                seen.add(nxt)
                todo.append(nxt)
    return False


@pytest.mark.parametrize("state", ["closed", "ajar"])
def test_e6_the_planner_plans_through_doors_amcl_localises_in_them_as_they_start(state, tmp_path, monkeypatch):
    world = worldgen.generate("door", seed=4, state=state, angle=0.5)
    folder = world.write(tmp_path / "w", ros=True)
    _, description = described(folder, world.world_id, tmp_path, monkeypatch)
    context, started = launch_run(description, configs(tmp_path, task="task_0"))
    params = yaml.safe_load(Path(str(_result(tmp_path, world, task="task_0")).replace(
        ".result.", ".nav2_params.")).read_text())
    costmap = params["global_costmap"]["global_costmap"]["ros__parameters"]
    assert costmap["map_topic"] == costmap["static_layer"]["map_topic"] == "/planner_map"
    assert costmap["static_layer"]["plugin"] == "nav2_costmap_2d::StaticLayer"  # nav2's own layer kept
    assert params["map_server"]["ros__parameters"]["yaml_filename"] == str(folder / "ros2" / "map.yaml")
    assert "map_topic" not in params["amcl"]["ros__parameters"]  # AMCL: map_server's /map
    servers = {e.kwargs["name"]: e for e, _ in started if e.kwargs.get("package") in (
        "nav2_map_server", "nav2_lifecycle_manager")}
    planner = servers["planner_map_server"].kwargs["parameters"][0]
    assert planner["topic_name"] == "/planner_map" and planner["yaml_filename"] == str(folder / "map.yaml")
    manager = servers["lifecycle_manager_planner_map"].kwargs["parameters"][0]
    assert manager["autostart"] is True and manager["node_names"] == ["planner_map_server"]
    # The robot's disc gets from spawn to goal in the planner's map, not in AMCL's (the leaf as it starts).
    meta = world.metadata
    occupancy, [task] = meta["occupancy"], meta["tasks"]
    assert task["requires_door_open"] is True
    ends = (task["spawn"][:2], task["goal"][:2])
    for path, through in ((folder / "map.pgm", True), (folder / "ros2" / "map.pgm", False)):
        assert _reachable(_pgm(path), occupancy["origin"], occupancy["resolution"], meta["robot"]["radius"],
                          *ends) is through, path
    # A crash of the planner's map server is a crash of the run, as any process's.
    assert process_exited(description, context, servers["planner_map_server"], 0)
    assert yaml.safe_load(_result(tmp_path, world, task="task_0").read_text())["process"] == "planner_map_server"


# -- E7: launch arguments checked by the loop ---------------------------------------------------------

@pytest.mark.parametrize("extra, message", [
    ("storage:=zip", "--launch-arg storage must be one of mcap, sqlite3, got 'zip'"),
    ("wall_limit:=-3", "--launch-arg wall_limit must be a number of seconds > 0, got '-3'"),
    ("robot_state_publisher:=yes", "--launch-arg robot_state_publisher must be true, false or auto, got 'yes'"),
    ("params_file:=/no/nav2.yaml", "--launch-arg params_file must be a nav2 parameters file, got '/no/nav2.yaml'"),
    ("stroage:=mcap", "--launch-arg stroage: no such launch argument; one of robot_name, robot_description, "),
    ("seed:=3", "--launch-arg seed: set by the loop for every run; use --seed"),
])
def test_e7_the_loop_checks_launch_arguments_before_anything_runs(folder, tmp_path, fake_ros2, extra, message):
    scenario, env = fake_ros2
    scenario.write_text("{}")
    done = loop(folder, tmp_path, env, "--launch-arg", extra)
    assert done.returncode == 2 and done.stderr.startswith(f"error: {message}"), done.stderr
    assert done.stderr.count("\n") == 1 and not (tmp_path / "bags").exists()
    assert not Path(str(scenario) + ".counts").exists()  # no launch
    good = loop(folder, tmp_path, env, "--launch-arg", "storage:=sqlite3", "--launch-arg", "wall_limit:=90")
    assert good.returncode == 0, good.stderr


# -- E8: every record names its run ------------------------------------------------------------------

def test_e8_every_record_names_world_task_run_and_seed(world, folder, tmp_path, fake_ros2):
    scenario, env = fake_ros2
    scenario.write_text('{"task_0/1": ["silent"], "task_0/2": ["timeout"]}')
    done = loop(folder, tmp_path, env, "--runs", "3", "--retries", "1", "--seed", "10")
    assert done.returncode == 1, done.stdout + done.stderr
    bags, name = tmp_path / "bags", f"{world.folder_name}__task_0__run"
    records = [bags / f"{name}1.result.yaml", bags / f"{name}2.result.yaml",
               bags / ".attempts" / f"{name}1.attempt0" / f"{name}1.result.yaml"]
    for path in records:
        record = yaml.safe_load(path.read_text())
        k = int(path.name.split("__run")[1].split(".")[0])
        assert {key: record[key] for key in ("world_dir", "world_id", "task", "run", "seed")} == {
            "world_dir": str(folder), "world_id": world.world_id, "task": "task_0", "run": k, "seed": 10 + k}, path
    assert yaml.safe_load(records[1].read_text())["set_aside"] is True
