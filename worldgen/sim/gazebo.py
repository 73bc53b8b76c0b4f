"""Running a world in a real Gazebo Sim server (Fortress's ``ign gazebo`` or Harmonic's ``gz sim``), headless.

The API (stable; the robot-driving loop builds on it)::

    from worldgen.sim.gazebo import GazeboServer, locate

    with GazeboServer("worlds/cluttered-s0-55fec0f6/world.sdf") as gz:   # started paused, world up
        gz.step(500)                                  # 500 physics iterations, unthrottled
        poses = gz.poses()                            # model name -> (x, y, z, qx, qy, qz, qw)
        gz.spawn(robot_sdf_text, name="robot", pose=(1.0, 2.0, 0.0, 0.3))
        gz.echo("/lidar", n=1)                        # parsed messages (worldgen.sim.textproto)
        with gz.subscribe("/scan") as scans: ...      # a subscriber kept while the world steps (sim/topics)
    gz.problems()                                     # Gazebo's errors and warnings, known harmless ones removed

- :func:`locate` finds an install (``WORLDGEN_GAZEBO_SETUP``, else the default place of the release asked for,
  Fortress's without one), reads its setup script's exports into an environment (no shell runs it) and knows
  its release; :class:`GazeboMissingError` says how to install. Both live in :mod:`worldgen.sim.gazebo_install`
  and are importable from here too. The server, its tools (``ign``/``gz``), its message package and its
  partition variable are that release's row of :mod:`worldgen.export.contract`.
- The server is a direct child (an argument list, never a shell) in its own process group; leaving the block
  stops it (SIGINT, SIGTERM, then SIGKILL 3 s later: with a render engine it may ignore the polite signals) and
  checks that no process of its group survives.
- ``ign`` exits 0 even when it fails, so every call here judges by what it printed, not by its status; a reply
  is read from the tool's stdout only (its transport prints other processes' discovery noise on stderr).
"""

from __future__ import annotations

import os
import subprocess
import tempfile
import time
from pathlib import Path

from worldgen.errors import SimulatorError
from worldgen.export.contract import GzRelease
from worldgen.sim import textproto
from worldgen.sim.gazebo_install import (
    DEFAULT_SETUP,
    INSTALL_HINT,
    SETUP_ENV,
    GazeboInstall,
    GazeboMissingError,
    locate,
    user_cache,
)
from worldgen.sim.gazebo_log import ACTOR_NOTES, ANSI, HARMLESS, problems_in
from worldgen.sim.gazebo_log import without_harmless as _without_harmless
from worldgen.sim.procs import group_members, run_tool, stop_group
from worldgen.sim.topics import Subscription

__all__ = ["GazeboMissingError", "GazeboError", "GazeboInstall", "GazeboServer", "locate", "SETUP_ENV",
           "DEFAULT_SETUP", "INSTALL_HINT", "HARMLESS", "ACTOR_NOTES", "problems_in", "world_name", "user_cache",
           "discovery_ports"]

#: The plugin Gazebo 6 asks for by default, and the file Debian 12's ign-physics5 ships instead (no unversioned link).
_DART_DEFAULT = "libignition-physics-dartsim-plugin.so"
_DART_DEBIAN = Path("/usr/lib/x86_64-linux-gnu/ign-physics-5/engine-plugins/libignition-physics5-dartsim-plugin.so.5")


class GazeboError(SimulatorError):
    """Gazebo ran but did not do what was asked (the world did not come up, a service did not answer)."""


def _physics_args(env: dict[str, str], release: GzRelease | None = None) -> list[str]:
    """``--physics-engine`` naming Debian's DART plugin when Gazebo 6's default name exists on none of its paths
    (a later release's install brings its own plugin under its default name)."""
    if release is not None and release.major != 6:
        return []
    dirs = [Path(d) for d in env.get("IGN_GAZEBO_PHYSICS_ENGINE_PATH", "").split(":") if d]
    dirs += [Path(d) for d in env.get("LD_LIBRARY_PATH", "").split(":") if d] + [_DART_DEBIAN.parent]
    if any((d / _DART_DEFAULT).exists() for d in dirs) or not _DART_DEBIAN.exists():
        return []
    return ["--physics-engine", _DART_DEBIAN.name]


def discovery_ports(release: GzRelease) -> tuple[int, int]:
    """The transport's discovery ports (messages, services) for the harness's processes of ``release``.

    Every ign-transport 11 and gz-transport 13 process on the machine meets on one multicast group and, by
    default, ports 10317/10318, with the same wire version: partitions are compared only after a discovery
    message is decoded. A Harmonic tool listing topics (``gz topic -l``) sends a SUBSCRIBERS_REQ (type 8),
    which Fortress's transport does not know: each Fortress process then prints "Unknown message type [8]."
    (measured here, in any partition). Ports of their own per release keep each release's discovery apart,
    and apart from any Gazebo the user runs on the default ports."""
    return 11017 + 20 * release.major, 11018 + 20 * release.major


def _accepted(reply: dict) -> bool:
    """Whether an ``ignition.msgs.Boolean`` reply says yes (protobuf text: ``data: true``)."""
    return textproto.first(reply, "data") == "true"


def world_name(sdf_path: Path) -> tuple[str, int]:
    """The ``<world name>`` of an SDF file and how many ``<actor>``s it holds (parsed without entities or network)."""
    from lxml import etree

    from worldgen.export.xml import safe_parser

    world = etree.parse(str(sdf_path), safe_parser()).getroot().find("world")
    if world is None or not world.get("name"):
        raise GazeboError(f"{sdf_path} holds no <world name=...>")
    return str(world.get("name")), len(world.findall("actor"))


class GazeboServer:
    """One headless server run (``ign gazebo -s``, ``gz sim -s``: the install's release) of one world; a context
    manager (see the module's docstring).

    ``headless_rendering`` loads the render engine through EGL (a gpu_lidar or camera in the world needs it);
    ``verbosity`` is Gazebo's ``-v``; ``real_time_factor`` None runs unthrottled. The server starts paused:
    simulation time moves only through :meth:`step`.
    """

    def __init__(self, world_sdf: str | Path, *, install: GazeboInstall | None = None, headless_rendering: bool = False,
                 verbosity: int = 3, real_time_factor: float | None = None, start_timeout: float = 60.0):
        self.world_sdf = Path(world_sdf).resolve()
        self.install = install or locate()
        self._logdir = tempfile.TemporaryDirectory(prefix="worldgen-gazebo-")
        home = Path(self._logdir.name) / "home"
        home.mkdir()
        # Gazebo's transport finds peers machine-wide: a partition of its own keeps this server and its
        # ign calls apart from any other Gazebo on the machine (same world name, /stats, /clock).
        # A home of its own: Gazebo writes ~/.ignition/gazebo/6/server.config on its first run (6.18 writes
        # gz::sim plugin names, which a 6.7 install then cannot load: measured) and a log folder per run; a
        # test run must not change the user's Gazebo. The cache stays the user's (Mesa's compiled shaders).
        # The release's discovery ports too (discovery_ports says why).
        self.release = self.install.release
        rel = self.release
        self.env = dict(self.install.env, HOME=str(home), XDG_CACHE_HOME=str(user_cache()),
                        **{rel.partition_var: f"worldgen-{os.getpid()}-{id(self):x}"},
                        **{var: str(port) for var, port in zip(rel.discovery_vars, discovery_ports(rel))})
        self.world, self.actors = world_name(self.world_sdf)
        self.headless_rendering = headless_rendering
        self.verbosity = verbosity
        self.real_time_factor = real_time_factor
        self.start_timeout = start_timeout
        self._proc: subprocess.Popen | None = None
        self._iterations = 0
        self._scene: dict | None = None  # the last scene/info reply, until a spawn changes the scene

    # -- life cycle --------------------------------------------------------------------------------------------
    def command(self) -> list[str]:
        """The server's argument list."""
        args = [*self.release.server, "-s", "-v", str(self.verbosity), "-z", str(self.real_time_factor or 1000000)]
        if self.headless_rendering:
            args.append("--headless-rendering")
        return args + _physics_args(self.install.env, self.release) + [str(self.world_sdf)]

    def start(self) -> GazeboServer:
        """Start the server and wait for its world; one that runs but has not served it within ``start_timeout``
        is stopped and started once more (docs/gazebo.md, "A server that hangs")."""
        logdir, attempt = Path(self._logdir.name), 0
        while True:
            attempt, started = attempt + 1, time.monotonic()
            with open(logdir / "stdout", "wb") as out, open(logdir / "stderr", "wb") as err:
                self._proc = subprocess.Popen(self.command(), env=self.env, stdin=subprocess.DEVNULL, stdout=out,
                                              stderr=err, start_new_session=True, cwd=str(self.world_sdf.parent))
            try:
                self._wait_up(started)
            except GazeboError as exc:
                stuck = self._proc.poll() is None
                self.stop()
                if attempt == 1 and stuck:
                    continue
                raise GazeboError(f"{exc} (attempt {attempt}; the server was {'running' if stuck else 'gone'})") from None
            except BaseException:
                self.stop()
                raise
            return self

    def _wait_up(self, started: float) -> None:
        """Until the world's scene service answers (it is served once the world is loaded)."""
        while time.monotonic() - started < self.start_timeout:
            if self._proc is None or self._proc.poll() is not None:
                raise GazeboError(f"Gazebo exited while loading {self.world_sdf}: {self.problems()[:5]}")
            # Long waits, not short polls (a requester that gives up before a busy server answers makes it print
            # "error sending response: Host unreachable"); half the time at most, to ask again if a reply is lost.
            remaining = self.start_timeout - (time.monotonic() - started)
            try:
                reply = self.service(f"/world/{self.world}/scene/info", self.release.msg("Empty"),
                                     self.release.msg("Scene"), "", timeout=max(1.0, min(remaining, self.start_timeout / 2)))
            except GazeboError:
                continue
            if reply:
                self._scene = reply
                return
        raise GazeboError(f"Gazebo did not serve world {self.world!r} within {self.start_timeout:.0f} s")

    def __enter__(self) -> GazeboServer:
        return self.start()

    def __exit__(self, *exc) -> None:
        self.stop()

    def stop(self) -> int | None:
        """Stop the server and its process group; returns its exit status. Raises if a process survives."""
        if self._proc is None:
            return None
        status = stop_group(self._proc, grace=3.0)
        left = group_members(self._proc.pid)
        if left:
            raise GazeboError(f"processes {left} of Gazebo's group {self._proc.pid} survived SIGKILL")
        return status

    # -- what it printed -------------------------------------------------------------------------------------
    def log(self) -> tuple[str, str]:
        """The server's (stdout, stderr) so far, colour codes removed."""
        logdir = Path(self._logdir.name)
        out, err = (ANSI.sub("", (logdir / s).read_text(errors="replace")) if (logdir / s).exists() else ""
                    for s in ("stdout", "stderr"))
        return out, err

    def problems(self) -> list[str]:
        """Gazebo's error and warning lines so far (stdout and stderr), without the known harmless ones (those
        of :data:`ACTOR_NOTES` once per actor of the world)."""
        out, err = self.log()
        return problems_in(out + "\n" + err, self.actors)

    # -- talking to it ---------------------------------------------------------------------------------------
    def _ign(self, args: list[str], timeout: float, errors: list[str] | None = None) -> str:
        """The release's tool (``ign``/``gz``) run with ``args``: its stdout (its stderr appended to ``errors``)."""
        errors = [] if errors is None else errors
        try:
            return run_tool([self.release.cli] + args, self.env, timeout=timeout, errors=errors)
        except subprocess.TimeoutExpired:
            raise GazeboError(f"'{self.release.cli} {' '.join(args[:3])}' got no answer within {timeout:.0f} s "
                              f"({self._state()})") from None

    def _state(self) -> str:
        """Whether the server still runs, for an error message: a live server that stopped answering is stuck."""
        status = None if self._proc is None else self._proc.poll()
        if self._proc is None or status is not None:
            return f"Gazebo exited with status {status}; it said: {self.problems()[-3:]}"
        return "Gazebo still runs but its simulation loop stopped answering; docs/gazebo.md, 'A server that hangs'"

    def echo(self, topic: str, n: int = 1, timeout: float = 20.0, step: int = 0) -> list[dict]:
        """The next ``n`` messages on a topic, parsed (:mod:`worldgen.sim.textproto`).

        ``step`` > 0 keeps the world stepping that many iterations at a time until they came: for a sensor,
        which publishes only while simulation time moves. Ask for a sensor this way only before the world
        has moved, or keep a :meth:`subscribe` open from then on (:mod:`worldgen.sim.topics` says why)."""
        if not step:
            return self._parse_echo(self._ign(["topic", "-e", "-t", topic, "-n", str(n)], timeout))
        with self.subscribe(topic) as sub:
            return sub.wait(n, step, timeout)[:n]

    def subscribe(self, topic: str) -> Subscription:
        """A subscriber to ``topic`` that stays until closed (a context manager): :class:`Subscription`."""
        return Subscription(topic, [self.release.cli, "topic", "-e", "-t", topic], self.env, self.step, self._parse_echo,
                            GazeboError)

    @staticmethod
    def _parse_echo(text: str) -> list[dict]:
        return [textproto.parse(m) for m in textproto.split_messages(_without_harmless(text))]

    def service(self, name: str, reqtype: str, reptype: str, req: str, timeout: float = 10.0) -> dict:
        """Call a service; its reply parsed. Raises :class:`GazeboError` when it does not answer."""
        ms = str(int(timeout * 1000))
        errors: list[str] = []
        text = self._ign(["service", "-s", name, "--reqtype", reqtype, "--reptype", reptype, "--timeout", ms,
                          "--req", req], timeout + 5, errors)
        body = _without_harmless(text).strip()
        if not body or "timed out" in body.lower() or "error" in body.lower():
            said = (body + " " + _without_harmless("".join(errors))).strip()
            raise GazeboError(f"service {name} did not answer: {said[:200]!r}")
        return textproto.parse(body)

    def stats(self) -> dict:
        """One ``/world/<name>/stats`` message (iterations, sim_time, real_time_factor, paused)."""
        return self.echo(f"/world/{self.world}/stats", 1)[0]

    def stats_time(self) -> float:
        """The world's simulation time (s), from one ``stats`` message."""
        sim = textproto.first(self.stats(), "sim_time", {})
        return float(textproto.first(sim, "sec", 0)) + float(textproto.first(sim, "nsec", 0)) * 1e-9

    def step(self, iterations: int, timeout: float = 120.0) -> int:
        """Run ``iterations`` physics steps, then stay paused; returns the world's iteration count."""
        target = self._iterations + int(iterations)
        reply = self.service(f"/world/{self.world}/control", self.release.msg("WorldControl"),
                             self.release.msg("Boolean"), f"pause: true, multi_step: {int(iterations)}")
        if not _accepted(reply):
            raise GazeboError(f"world control refused {iterations} steps: {reply}")
        deadline = time.monotonic() + timeout
        while time.monotonic() < deadline:
            done = int(textproto.first(self.stats(), "iterations", 0))
            if done >= target:
                self._iterations = done
                return done
        raise GazeboError(f"world {self.world!r} did not reach iteration {target} within {timeout:.0f} s")

    def scene_names(self) -> dict[int, str]:
        """Entity id -> scoped name (``model``, ``model::link``) of every model and link, from ``scene/info``
        (asked once, and again after a spawn)."""
        if self._scene is None:
            self._scene = self.service(f"/world/{self.world}/scene/info", self.release.msg("Empty"),
                                       self.release.msg("Scene"), "")
        scene = self._scene
        names: dict[int, str] = {}

        def walk(model: dict, prefix: str) -> None:
            scoped = prefix + str(textproto.first(model, "name", ""))
            names[int(textproto.first(model, "id", 0))] = scoped
            for link in model.get("link", []):
                names[int(textproto.first(link, "id", 0))] = f"{scoped}::{textproto.first(link, 'name', '')}"
            for nested in model.get("model", []):
                walk(nested, scoped + "::")

        for model in scene.get("model", []):
            walk(model, "")
        return names

    def poses(self, dynamic: bool = False, timeout: float = 20.0) -> dict[str, tuple[float, ...]]:
        """Scoped name (``model``, ``model::link``) -> (x, y, z, qx, qy, qz, qw) from one ``pose/info`` (or
        ``dynamic_pose/info``) message. A model's pose is in the world frame, a link's in its model's frame
        (as Gazebo publishes them); entities that are neither (lights, visuals) are left out."""
        if dynamic and self.actors:
            # SceneBroadcaster::PoseUpdate (gz-sim 6.18 and 8.9) reads the Static component of every link's
            # parent once dynamic_pose/info has a subscriber; an actor's link has the actor as its parent,
            # which has none: the server dies of a null dereference (measured here, SIGSEGV).
            raise GazeboError(f"dynamic_pose/info would crash Gazebo: world {self.world!r} has actors "
                              "(docs/gazebo.md); read pose/info, which carries the moving bodies too")
        topic = f"/world/{self.world}/{'dynamic_pose' if dynamic else 'pose'}/info"
        message = self.echo(topic, 1, timeout)[0]
        names = self.scene_names()
        return {names[int(textproto.first(p, "id", 0))]: textproto.pose_of(p) for p in message.get("pose", [])
                if int(textproto.first(p, "id", 0)) in names}

    def spawn(self, sdf: str, name: str, pose: tuple[float, float, float, float] = (0.0, 0.0, 0.0, 0.0)) -> None:
        """Create a model from SDF text (a ``<sdf>`` document) at (x, y, z, yaw) through ``/world/<name>/create``."""
        import json
        import math

        x, y, z, yaw = pose
        req = (f"sdf: {json.dumps(sdf)}, name: {json.dumps(name)}, allow_renaming: false, pose: {{position: "
               f"{{x: {x!r}, y: {y!r}, z: {z!r}}}, orientation: {{z: {math.sin(yaw / 2)!r}, w: {math.cos(yaw / 2)!r}}}}}")
        self._scene = None
        reply = self.service(f"/world/{self.world}/create", self.release.msg("EntityFactory"),
                             self.release.msg("Boolean"), req)
        if not _accepted(reply):
            raise GazeboError(f"Gazebo refused to create {name!r}: {reply}")
