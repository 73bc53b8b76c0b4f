"""The parts of worldgen.sim that need no simulator: protobuf text, stopping a process group, finding Gazebo."""

import subprocess
import sys

import pytest

from worldgen.errors import SimulatorError
from worldgen.sim import textproto
from worldgen.sim.gazebo import GazeboMissingError, locate, problems_in
from worldgen.sim.procs import group_members, run_tool, stop_group

POSE_V = """header {
  stamp {
    sec: 2
  }
}
pose {
  name: "floor"
  id: 4
  position {
    z: -0.05
  }
  orientation {
    w: 1
  }
}
pose {
  name: "box \\"a\\""
  id: 8
  position {
    x: 1.5e-3
    y: -2
  }
}
"""


def test_pose_v_text_reads_with_omitted_fields_at_their_defaults():
    message = textproto.parse(POSE_V)
    assert textproto.first(textproto.first(message, "header"), "stamp") == {"sec": [2]}
    assert textproto.poses_by_name(message) == {"floor": (0.0, 0.0, -0.05, 0.0, 0.0, 0.0, 1.0),
                                                 'box "a"': (0.0015, -2.0, 0.0, 0.0, 0.0, 0.0, 1.0)}


def test_several_printed_messages_split_and_bad_text_is_refused():
    assert [textproto.parse(m)["data"] for m in textproto.split_messages("data: true\n\ndata: false\n")] == \
        [["true"], ["false"]]
    for bad in ("pose {", "}", "x: 1 {", '"floating"'):
        with pytest.raises(SimulatorError):
            textproto.parse(bad)


def test_a_group_that_ignores_polite_signals_is_killed_and_nothing_survives():
    # a parent and a child, both ignoring SIGINT and SIGTERM, as a server with a render engine may
    script = ("import signal, subprocess, sys, time\n"
              "for s in (signal.SIGINT, signal.SIGTERM): signal.signal(s, signal.SIG_IGN)\n"
              "subprocess.Popen([sys.executable, '-c', 'import signal, time\\n"
              "for s in (signal.SIGINT, signal.SIGTERM): signal.signal(s, signal.SIG_IGN)\\n"
              "print(\\'child\\', flush=True); time.sleep(60)'])\n"
              "print('up', flush=True); time.sleep(60)\n")
    proc = subprocess.Popen([sys.executable, "-c", script], stdout=subprocess.PIPE, start_new_session=True)
    # both have set their signals aside before anything is sent (on a loaded machine the child takes a while)
    assert {proc.stdout.readline(), proc.stdout.readline()} == {b"up\n", b"child\n"}
    assert len(group_members(proc.pid)) == 2
    status = stop_group(proc, grace=1.0)
    assert status == -9 and group_members(proc.pid) == []


def test_a_tool_that_outlives_its_time_is_stopped():
    with pytest.raises(subprocess.TimeoutExpired):
        run_tool([sys.executable, "-c", "import time; time.sleep(30)"], {}, timeout=0.5)


def test_a_missing_install_names_how_to_install(tmp_path):
    with pytest.raises(GazeboMissingError, match="install Gazebo Fortress.*WORLDGEN_GAZEBO_SETUP"):
        locate(tmp_path / "setup.sh")


def test_only_known_harmless_lines_are_dropped_from_the_problems():
    log = ("Library error: libignition-tools-backward.so not found. Improved backtrace generation will be disabled\n"
           "\x1b[1;31m[Err] [Physics.cc:761] \x1b[0mFailed to find plugin\n[Msg] Loaded level [3]\n"
           "[Wrn] [SdfEntityCreator.cc:1] something\n")
    assert problems_in(log) == ["[Err] [Physics.cc:761] Failed to find plugin", "[Wrn] [SdfEntityCreator.cc:1] something"]


def test_the_dynamic_poses_of_a_world_with_actors_are_refused_before_they_crash_gazebo(tmp_path):
    import worldgen
    from worldgen.sim.gazebo import GazeboError, GazeboInstall, GazeboServer

    folder = worldgen.generate("cluttered", seed=3, n_movers=1).write(tmp_path, preview=False)
    server = GazeboServer(folder / "world.sdf", install=GazeboInstall(tmp_path / "setup.sh", {}, "6.18.0"))
    assert server.actors == 1
    with pytest.raises(GazeboError, match="dynamic_pose/info would crash Gazebo"):
        server.poses(dynamic=True)


def _printer(script: str) -> list[str]:
    """A stand-in subscriber: a Python process printing as ``ign topic -e`` does (messages, blank lines)."""
    return [sys.executable, "-u", "-c", script]


def test_a_subscription_keeps_every_complete_message_and_never_a_half_written_one():
    from worldgen.sim.topics import Subscription

    script = ("import sys, time\n"
              "for i in range(3):\n"
              "    print(f'stamp {{\\n  sec: {i}\\n}}\\n'); sys.stdout.flush()\n"
              "print('stamp {', end=''); sys.stdout.flush()\n"  # a message cut short
              "time.sleep(60)\n")
    steps = []
    with Subscription("/t", _printer(script), {}, steps.append, lambda text: [textproto.parse(m) for m in
                      textproto.split_messages(text)], SimulatorError) as sub:
        got = sub.wait(3, step=7, timeout=20)
        assert [textproto.first(textproto.first(m, "stamp"), "sec") for m in got] == [0, 1, 2]
        assert sub.wait(1, where=lambda m: textproto.first(textproto.first(m, "stamp"), "sec") == 2)
        with pytest.raises(SimulatorError, match="3 of 4 message"):
            sub.wait(4, timeout=0.3)
        proc = sub._proc
    assert proc.poll() is not None and not group_members(proc.pid)  # the subscriber stopped with its block
    assert len(sub.messages()) == 3 and steps == [7] * len(steps)


def _fake_install(folder, tool: str, words: str, plugin_var: str):
    """A setup script whose PATH holds one fake Gazebo tool that prints ``words`` for any arguments."""
    bin_dir = folder / "bin"
    bin_dir.mkdir(parents=True)
    exe = bin_dir / tool
    exe.write_text(f"#!/bin/sh\necho '{words}'\n")
    exe.chmod(0o755)
    setup = folder / "setup.sh"
    setup.write_text(f"export PATH={bin_dir}:/usr/bin:/bin\nexport {plugin_var}={folder}/plugins\n")
    return setup


@pytest.mark.parametrize(("version", "expected"), [("8.14.0", "harmonic"), ("6.18.0", "fortress")])
def test_locate_tells_the_release_from_the_servers_version(tmp_path, version, expected):
    from worldgen.export.contract import release

    row = release(expected)
    setup = _fake_install(tmp_path, row.cli, f"Library error: x\n{version}", row.plugin_path_var)
    install = locate(setup)
    assert (install.version, install.release.name) == (version, expected)
    assert locate(setup, release=expected).release is install.release
    other = "fortress" if expected == "harmonic" else "harmonic"
    with pytest.raises(GazeboMissingError, match=f"not {other}"):
        locate(setup, release=other)


def test_locate_refuses_a_release_it_does_not_run_and_a_version_it_does_not_know(tmp_path):
    from worldgen.errors import ParameterError
    from worldgen.export.contract import release

    with pytest.raises(ParameterError, match="'--gz-release' must be one of fortress, harmonic, got 'ionic'"):
        locate(release="ionic")
    row = release("harmonic")
    with pytest.raises(GazeboMissingError, match="Gazebo 3.1.0 is none of the releases"):
        locate(_fake_install(tmp_path, row.cli, "3.1.0", row.plugin_path_var))


def test_a_subscriber_and_a_service_read_the_tools_stdout_only(tmp_path):
    # What a Fortress tool prints on stderr when a Harmonic one lists topics on its discovery ports must not
    # land inside the text parsed (issue 39: "not protobuf text at offset 21").
    import worldgen
    from worldgen.export.contract import release
    from worldgen.sim.gazebo import GazeboInstall, GazeboServer
    from worldgen.sim.topics import Subscription

    noise = "import sys; sys.stderr.write('Unknown message type [8].\\n'); sys.stderr.flush()\n"
    script = noise + "print('stamp {\\n  sec: 4\\n}\\n', flush=True)\n" + noise + "import time; time.sleep(60)\n"
    with Subscription("/t", _printer(script), {}, lambda n: None, lambda text: [textproto.parse(m) for m in
                      textproto.split_messages(text)], SimulatorError) as sub:
        assert [textproto.first(textproto.first(m, "stamp"), "sec") for m in sub.wait(1, timeout=20)] == [4]
    row = release("fortress")
    bin_dir = tmp_path / "bin"
    bin_dir.mkdir()
    (bin_dir / row.cli).write_text("#!/bin/sh\necho 'Unknown message type [8].' >&2\necho 'data: true'\n"
                                   "echo 'Unknown message type [8].' >&2\n")
    (bin_dir / row.cli).chmod(0o755)
    folder = worldgen.generate("minimal", seed=0).write(tmp_path / "w", preview=False)
    env = {"PATH": f"{bin_dir}:/usr/bin:/bin"}
    server = GazeboServer(folder / "world.sdf", install=GazeboInstall(tmp_path / "setup.sh", env, "6.18.0", row))
    assert server.service("/x", row.msg("Empty"), row.msg("Boolean"), "") == {"data": ["true"]}
