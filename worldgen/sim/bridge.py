"""Driving a robot in Gazebo in lockstep: the C++ bridge (``drive_bridge.cc``), built on first use, and the
backend the drive loop steps (:class:`GazeboBackend`).

Fortress's ign-transport has no Python bindings, and each ``ign service`` call starts a process (about
0.1 s), so a 20 Hz controller talks to Gazebo through one long-lived program instead: it publishes the
twist, runs N physics steps through ``/world/<name>/control`` (the world stays paused between calls) and
answers with the pose the robot's OdometryPublisher stamped at the end of them. The program is compiled
against the transport and message libraries of the install's release (the contract's row: ign-transport 11
and ign-msgs 8 for Fortress, gz-transport 13 and gz-msgs 10 for Harmonic, found by ``pkg-config``, which also
looks in ``lib/pkgconfig`` beside the install's libraries) into the user's cache folder under a name carrying
a digest of its source, its prelude and flags, so an edited source or another install gives a fresh build.
"""

from __future__ import annotations

import hashlib
import math
import os
import shutil
import subprocess
import tempfile
from importlib import resources
from pathlib import Path
from typing import IO, Optional

from lxml import etree

from worldgen.errors import OutputError
from worldgen.export.contract import CMD_VEL, GROUND_TRUTH, SIM_GZ_RELEASE, GzRelease, release
from worldgen.export.robot import DEFAULT_NAME
from worldgen.export.xml import safe_parser
from worldgen.files import move_into_place
from worldgen.sim.gazebo import GazeboError, GazeboInstall, GazeboMissingError, GazeboServer, locate, user_cache
from worldgen.sim.gazebo_doors import GazeboDoors

__all__ = ["SOURCE_NAME", "cache_dir", "build_bridge", "prelude", "GazeboBackend", "world_step"]

SOURCE_NAME = "drive_bridge.cc"
_BUILD_HINT = ("apt-get install g++ pkg-config libignition-transport-dev libignition-msgs-dev (Fortress), or an "
               "install that ships its .pc files (Harmonic: shared/gazebo's build)")
#: The headers the bridge uses, under the release's folder (``ignition/``, ``gz/``).
_HEADERS = ("msgs/boolean.pb.h", "msgs/double.pb.h", "msgs/entity_factory.pb.h", "msgs/odometry.pb.h", "msgs/twist.pb.h",
            "msgs/world_control.pb.h", "transport/Node.hh")


def prelude(rel: GzRelease) -> str:
    """What the bridge's source is compiled after (g++ -include): the release's headers and namespaces."""
    return ("".join(f"#include <{rel.cxx}/{h}>\n" for h in _HEADERS)
            + f"namespace wgmsgs = {rel.cxx}::msgs;\nnamespace wgtransport = {rel.cxx}::transport;\n")


def _pkg_config_path(env: dict[str, str]) -> str:
    """PKG_CONFIG_PATH with ``pkgconfig`` folders beside the install's libraries (Harmonic's setup.sh sets none)."""
    found = [str(Path(d) / "pkgconfig") for d in env.get("LD_LIBRARY_PATH", "").split(":")
             if d and (Path(d) / "pkgconfig").is_dir()]
    return ":".join(dict.fromkeys(found + [p for p in env.get("PKG_CONFIG_PATH", "").split(":") if p]))


def cache_dir() -> Path:
    """Where built helpers live: ``$XDG_CACHE_HOME/worldgen`` (default ``~/.cache/worldgen``)."""
    return user_cache() / "worldgen"


def build_bridge(env: dict[str, str] | None = None, rel: GzRelease | None = None) -> Path:
    """The compiled bridge for release ``rel`` (default :data:`SIM_GZ_RELEASE`), built now when the cache has none
    for this source, prelude and flags."""
    rel = rel or release(SIM_GZ_RELEASE)
    env = dict(os.environ if env is None else env)
    env["PKG_CONFIG_PATH"] = _pkg_config_path(env)
    compiler = shutil.which("g++", path=env.get("PATH"))
    if compiler is None or shutil.which("pkg-config", path=env.get("PATH")) is None:
        raise GazeboMissingError(f"driving in Gazebo builds a small C++ program and needs g++ and pkg-config: {_BUILD_HINT}")
    flags = subprocess.run(["pkg-config", "--cflags", "--libs", *rel.transport], capture_output=True, text=True, env=env)
    if flags.returncode != 0:
        raise GazeboMissingError(f"driving in Gazebo {rel.name} needs the {' and '.join(rel.transport)} headers: "
                                 f"{_BUILD_HINT}")
    source, head = resources.files("worldgen.sim").joinpath(SOURCE_NAME).read_bytes(), prelude(rel).encode()
    digest = hashlib.sha256(source + head + flags.stdout.encode()).hexdigest()[:16]
    exe = cache_dir() / f"drive_bridge-{digest}"
    if exe.exists():
        return exe
    try:
        exe.parent.mkdir(parents=True, exist_ok=True)
        with tempfile.TemporaryDirectory(dir=exe.parent) as tmp:
            src = Path(tmp) / SOURCE_NAME
            src.write_bytes(source)
            (Path(tmp) / "prelude.hh").write_bytes(head)
            out = Path(tmp) / "drive_bridge"
            # The libraries' folders as the binary's run path: Harmonic's are not on the system's library path.
            rpath = [f"-Wl,-rpath,{f[2:]}" for f in flags.stdout.split() if f.startswith("-L")]
            cmd = [compiler, "-O2", "-std=c++17", "-pthread", "-include", str(Path(tmp) / "prelude.hh"), str(src),
                   "-o", str(out), *flags.stdout.split(), *rpath]
            built = subprocess.run(cmd, capture_output=True, text=True, env=env, timeout=300)
            if built.returncode != 0:
                raise GazeboError(f"building the Gazebo drive bridge failed: {built.stderr.strip()[:500]}")
            move_into_place(out, exe)  # a rename: a parallel run never starts half a binary
    except OSError as exc:
        raise OutputError(f"cannot build the Gazebo drive bridge in '{exe.parent}' ({exc.strerror or exc}); "
                          "set XDG_CACHE_HOME to a writable folder") from None
    return exe


def world_step(sdf_path: Path) -> float:
    """The world's physics step (s): its ``<physics><max_step_size>``, Gazebo's 0.001 s where none is set."""
    text = etree.parse(str(sdf_path), safe_parser()).getroot().findtext("world/physics/max_step_size")
    return float(text) if text else 0.001


class GazeboBackend:
    """The robot in a headless Gazebo: :meth:`start` spawns it, :meth:`step` drives it N physics steps.

    ``robot_sdf`` is the model (worldgen.export.robot, with its ground truth published at the end of every command);
    poses come back from the simulator, (t, x, y, yaw) in the world frame. ``doors`` (with ``world_text``, the
    world run instead of ``world_sdf``'s bytes, holding their controllers and ``door_topics``, their target
    topics: worldgen.sim.gazebo_doors.world_with_openers) are the pull doors the robot opens on its way.
    """

    def __init__(self, world_sdf: Path, robot_sdf: str, *, dt: float, first_steps: int = 1,
                 install: GazeboInstall | None = None, doors: Optional[GazeboDoors] = None,
                 world_text: Optional[bytes] = None, door_topics: tuple[str, ...] = ()):
        self.world_sdf = Path(world_sdf)
        self.doors, self._world_text, self._door_topics = doors, world_text, tuple(door_topics)
        self._world: IO[bytes] | None = None  # the copy of the world with the door openers, when there is one
        self._pose: Optional[tuple[float, float, float, float]] = None  # the last pose Gazebo gave
        #: rad/s^2 the robot's turn rate can change by (its DiffDrive's limit; None: not limited), for the controller
        self.turn_accel: Optional[float] = None
        #: m/s^2 its speed can change by (likewise)
        self.accel: Optional[float] = None
        self.install = install  # the install to run (its release's tools and libraries); None: locate()'s
        self.first_steps = first_steps  # steps until the first pose: the model's OdometryPublisher's period
        self.dt = dt  # the world's physics step (world_step)
        self._robot_sdf, self._robot_name = robot_sdf, DEFAULT_NAME  # robot_sdf's model name
        self._server: GazeboServer | None = None
        self._bridge: subprocess.Popen | None = None
        self._model: IO[str] | None = None  # the robot's SDF, a file the bridge reads

    def start(self, spawn: tuple[float, float, float, float],
              first: tuple[float, float] = (0.0, 0.0)) -> tuple[float, float, float, float]:
        """Start the server, spawn the robot at (x, y, z, yaw), connect the bridge; the first pose, after
        :attr:`first_steps` steps under the twist ``first`` (v, w)."""
        install = self.install or locate()
        exe = build_bridge(install.env, install.release)
        self._pose = None
        world = self.world_sdf
        if self._world_text is not None:
            self._world = tempfile.NamedTemporaryFile("wb", suffix=".sdf", prefix="worldgen-world-")
            self._world.write(self._world_text)
            self._world.flush()
            world = Path(self._world.name)
        self._server = GazeboServer(world, install=install).start()
        # The server's environment carries its own partition and discovery ports: the bridge must share them.
        env = self._server.env
        self._model = model = tempfile.NamedTemporaryFile("w", suffix=".sdf", prefix="worldgen-robot-")
        model.write(self._robot_sdf)
        model.flush()
        self._bridge = subprocess.Popen(
            [str(exe), self._server.world, CMD_VEL.gazebo_topic, GROUND_TRUTH.gazebo_topic, str(round(self.dt * 1e9)),
             model.name, self._robot_name, *(repr(float(v)) for v in spawn), *self._door_topics],
            env=env, stdin=subprocess.PIPE, stdout=subprocess.PIPE, stderr=subprocess.DEVNULL, text=True, bufsize=1)
        answer = self._read()
        if answer != "ready":
            raise GazeboError(f"the drive bridge did not connect: {answer}")
        return self.step(first[0], first[1], self.first_steps)

    def _read(self) -> str:
        assert self._bridge is not None and self._bridge.stdout is not None
        line = self._bridge.stdout.readline().strip()
        if not line or line.startswith("error:"):
            raise GazeboError(f"the drive bridge stopped: {line or 'no answer'}; Gazebo said: {self.problems()[:3]}")
        return line

    @property
    def doors_opened(self) -> list[str]:
        """The doors whose opener the robot triggered, in order."""
        return self.doors.opened if self.doors is not None else []

    def give_way(self, x: float, y: float, yaw: float, v: float, ahead: float) -> float:
        """The forward speed the robot may take for the next ``ahead`` s (GazeboDoors.give_way)."""
        if self.doors is None or self._pose is None:
            return v
        return self.doors.give_way(self._pose[0], x, y, yaw, v, ahead)

    def step(self, v: float, w: float, n: int) -> tuple[float, float, float, float]:
        assert self._bridge is not None and self._bridge.stdin is not None
        # As in MuJoCo, the doors open from where the robot is when the command starts (none before the first pose:
        # a made-up one could set the rule's state, the robot "entered from the push side").
        if self.doors is not None and self._pose is not None:
            t, x, y, _ = self._pose
            for k, angle in self.doors.targets(t, x, y, int(n) * self.dt):
                self._bridge.stdin.write(f"d {k} {angle!r}\n")
        self._bridge.stdin.write(f"s {int(n)} {v!r} {w!r}\n")
        self._bridge.stdin.flush()
        fields = self._read().split()
        t, x, y, yaw = (float(f) for f in fields[1:5])
        if not all(math.isfinite(f) for f in (t, x, y, yaw)):
            raise GazeboError(f"Gazebo gave a non-finite pose: {fields}")
        self._pose = (t, x, y, yaw)
        return t, x, y, yaw

    def problems(self) -> list[str]:
        return self._server.problems() if self._server is not None else []

    def close(self) -> None:
        if self._bridge is not None:
            if self._bridge.poll() is None and self._bridge.stdin is not None:
                try:
                    self._bridge.stdin.write("q\n")
                    self._bridge.stdin.close()
                except OSError:
                    pass
            try:
                self._bridge.wait(timeout=5)
            except subprocess.TimeoutExpired:
                self._bridge.kill()
                self._bridge.wait()
            if self._bridge.stdout is not None:
                self._bridge.stdout.close()
            self._bridge = None
        for kept in (self._model, self._world):
            if kept is not None:
                kept.close()
        self._model = None
        self._world = None
        if self._server is not None:
            self._server.stop()
            self._server = None
