"""The bundle's Gazebo server under launch's shutdown, with the real server (Fortress, ign-gazebo 6; the Harmonic
bundle's in gz-sim 8 too).

The launch file starts Gazebo as an ExecuteProcess with a command list, no shell. On shutdown launch
signals that one process: SIGINT, SIGTERM after ``sigterm_timeout`` (5 s by default), SIGKILL after
``sigkill_timeout`` more (5 s) (launch/actions/execute_local.py, Humble to Jazzy). Here the exact command
the Fortress bundle's launch file builds runs with the shipped robot spawned (its gpu_lidar renders),
is stopped that way, and nothing it started may outlive it: its process group (the test starts it in
its own session to be able to look) and every descendant seen while it ran must be gone. With the
lidar rendering, Gazebo sometimes ignores SIGINT and SIGTERM (4 of 12 stops measured here, the others
ended on SIGINT): then launch's SIGKILL ends it, which reaches it because no shell stands between. The
same server started as ros_gz_sim's gz_sim.launch.py starts it, through a shell, leaves Gazebo running.
"""

from __future__ import annotations

import importlib.util
import os
import signal
import subprocess
import time
from pathlib import Path

import pytest
from support.gazebo import every_case

import worldgen
from worldgen.export.contract import SIM_GZ_RELEASES
from worldgen.export.robot import robot_sdf

pytestmark = pytest.mark.gazebo

#: launch's defaults (ExecuteProcess: LaunchConfiguration('sigterm_timeout', default=5), sigkill the same).
SIGTERM_TIMEOUT = SIGKILL_TIMEOUT = 5.0




@pytest.fixture(scope="module")
def run_setup(install, tmp_path_factory):
    """A Fortress bundle written; its launch file's Gazebo command and environment."""
    return _run_setup(install, tmp_path_factory)


def _run_setup(install, tmp_path_factory):
    """A bundle written for the install's release; its launch file's Gazebo command and environment."""
    rel = install.release
    world = worldgen.generate("cluttered", seed=3, size=[6, 6], n_obstacles=4)
    folder = world.write(tmp_path_factory.mktemp("gz"), ros=rel.name)
    path = next((folder / "ros2" / "launch").glob("*.launch.py"))
    spec = importlib.util.spec_from_file_location("gz_launch", path)
    launch = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(launch)
    # A transport partition of its own: another Gazebo on this machine (a parallel test) is not this one;
    # a home of its own: Gazebo writes its config and logs under ~/.ignition (docs/gazebo.md); the logs
    # of this test go there too.
    cache = os.environ.get("XDG_CACHE_HOME") or str(Path.home() / ".cache")
    env = dict(install.env, XDG_CACHE_HOME=cache, HOME=str(tmp_path_factory.mktemp("home")),
               **{rel.partition_var: f"worldgen-bundle-{os.getpid()}-{rel.name}"})
    env.update(launch.gazebo_env())
    command = launch.gazebo_command(str(folder / launch.SDF), "0")
    robot = folder / f"robot_{rel.name}.sdf"
    robot.write_text(robot_sdf(world, gz_release=rel.name))
    return world, command, env, robot, rel


def _descendants(pid: int) -> set[int]:
    parents = {}
    for stat in Path("/proc").glob("[0-9]*/stat"):
        try:
            text = stat.read_text()
        except OSError:
            continue
        parents[int(stat.parent.name)] = int(text[text.rfind(")") + 2:].split()[1])
    found, frontier = set(), {pid}
    while frontier:
        frontier = {p for p, parent in parents.items() if parent in frontier} - found
        found |= frontier
    return found


def _alive(pid: int) -> bool:
    try:
        text = Path(f"/proc/{pid}/stat").read_text()
    except OSError:
        return False
    return text[text.rfind(")") + 2:].split()[0] != "Z"


def _up(world, env, robot, rel) -> None:
    """Wait until the world answers, then spawn the robot at the first task's spawn (``rel``'s tool and types)."""
    deadline = time.monotonic() + 60
    name = world.world_id
    while time.monotonic() < deadline:
        listed = subprocess.run([rel.cli, "service", "-l"], env=env, capture_output=True, text=True, timeout=30).stdout
        if f"/world/{name}/create" in listed:
            break
        time.sleep(0.5)
    else:
        pytest.fail(f"Gazebo did not offer /world/{name}/create within 60 s")
    spawn = world.tasks[0].spawn
    req = f'sdf_filename: "{robot}", name: "robot", pose: {{position: {{x: {spawn.x}, y: {spawn.y}}}}}'
    done = subprocess.run([rel.cli, "service", "-s", f"/world/{name}/create", "--reqtype", rel.msg("EntityFactory"),
                           "--reptype", rel.msg("Boolean"), "--timeout", "10000", "--req", req],
                          env=env, capture_output=True, text=True, timeout=60)
    assert "data: true" in done.stdout, done.stdout + done.stderr


def _stop_as_launch_does(proc: subprocess.Popen) -> str:
    """launch's shutdown of one ExecuteProcess: SIGINT to it, SIGTERM after SIGTERM_TIMEOUT, SIGKILL after
    SIGKILL_TIMEOUT more; the signal it ended on."""
    for sig, wait in ((signal.SIGINT, SIGTERM_TIMEOUT), (signal.SIGTERM, SIGKILL_TIMEOUT), (signal.SIGKILL, 10.0)):
        proc.send_signal(sig)
        try:
            proc.wait(timeout=wait)
            return sig.name
        except subprocess.TimeoutExpired:
            continue
    raise AssertionError("the process outlived SIGKILL")


def _start(args, env, shell=False) -> tuple[subprocess.Popen, Path]:
    log = Path(env["HOME"]) / f"gz-{time.monotonic_ns()}.log"
    proc = subprocess.Popen(args, env=env, shell=shell, stdin=subprocess.DEVNULL, stdout=log.open("w"),
                            stderr=subprocess.STDOUT, start_new_session=True)
    return proc, log


@pytest.mark.parametrize("release", SIM_GZ_RELEASES)
def test_the_bundles_gazebo_server_stops_with_launch_and_leaves_nothing(release, installs, tmp_path_factory):
    from worldgen.sim.procs import group_members

    world, command, env, robot, rel = _run_setup(installs(release), tmp_path_factory)
    assert tuple(command[:2]) == rel.server and "-s" in command and "-r" in command
    proc, log = _start(command, env)
    try:
        _up(world, env, robot, rel)
        seen = _descendants(proc.pid) | {proc.pid}
        ended_on = _stop_as_launch_does(proc)
        time.sleep(0.5)
        assert ended_on in ("SIGINT", "SIGTERM", "SIGKILL")  # SIGINT mostly; the escalation when it hangs
        assert group_members(proc.pid) == [] and not [p for p in seen if _alive(p)], log.read_text()[-2000:]
    finally:
        if group_members(proc.pid):
            os.killpg(proc.pid, signal.SIGKILL)
        log.unlink(missing_ok=True)


# The premise of the test above, checked with WORLDGEN_GAZEBO_ALL=1 (8 s the suite could not keep); else left
# out of the run, not skipped.
if every_case():
    def test_through_a_shell_as_ros_gz_sim_starts_it_gazebo_outlives_the_run(run_setup):
        """The failure the bundle avoids (ros2/launch#545): the shell ends, Gazebo is left behind. If this
        test ever fails, a shell started the old way would also be fine, and the check above proves little."""
        from worldgen.sim.procs import group_members

        world, command, env, robot, rel = run_setup
        # gz_sim.launch.py's ExecuteProcess: cmd=['ruby $(which ign) gazebo', gz_args, ...], shell=True
        line = f"ruby $(which {rel.server[0]}) {rel.server[1]} " + " ".join(command[2:])
        proc, log = _start(line, env, shell=True)
        try:
            _up(world, env, robot, rel)
            _stop_as_launch_does(proc)
            time.sleep(0.5)
            assert group_members(proc.pid), "Gazebo stopped with its shell"
        finally:
            if group_members(proc.pid):
                os.killpg(proc.pid, signal.SIGKILL)
            log.unlink(missing_ok=True)
