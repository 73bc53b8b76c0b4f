"""The one reader of a written world: its world.json, a task by id, the robot, a file by format key.

A world comes as a written world folder (a path), a world of a built pack (:class:`~worldgen.PackWorld`,
in a folder or an archive) or an in-memory :class:`~worldgen.World`. :func:`open_world` reads any of
them as a :class:`WorldFolder`, which answers as a World and a PackWorld do where those two agree
(``world_id``, ``generator``, ``seed``, ``params``, ``metadata``, ``read(name)``, ``path``, ``robot``,
``file(fmt)``) and adds ``task(id)``, ``task_ids`` and ``file_bytes(fmt)``::

    world = open_world("worlds/cluttered-s0-55fec0f6")   # or a World, or pack[0]
    world.task("task_1")["goal"], world.robot.radius, world.file("mjcf")

Ground truth (:mod:`worldgen.groundtruth.ground`), ``worldgen drive``, the judge, ``worldgen preview``
and the environment's pack source read worlds through it; world.json is read nowhere else but by its
writer and by the checks of a folder's raw bytes (tests/test_layout.py names them).

It sits in groundtruth/ because every room that reads a folder back (export's preview, verify, pack,
the judge, envs, sim, cli) comes after it in the flow, while the Robot it returns comes from scene/,
before it. A format key (``sdf``, ``mjcf``, ...: export/formats.py's table) is looked up in world.json's
own ``files`` table, which the writer keys by that table, so no writer is imported here.
"""

from __future__ import annotations

import json
from functools import cached_property, partial
from pathlib import Path, PurePosixPath
from typing import Any, Callable, Mapping, Optional

from worldgen.errors import ParameterError
from worldgen.files import METADATA_NAME
from worldgen.floats import round_float
from worldgen.scene import Robot
from worldgen.scene.robot import ACCELERATION, CLIMB_DEFAULTS, MAX_SPEED, TURN_RATE, LidarDescription, RobotDescription

__all__ = ["WorldFolder", "open_world", "is_world_folder", "task_of", "robot_of", "robot_description_of",
           "motion_limits_of"]

#: (world.json robot key, parameter, default) of each motion limit: world.json states the limits only in worlds
#: with people; elsewhere the world's recorded parameter, else the parameter's default, applies.
_MOTION = (("max_speed", "robot_speed", MAX_SPEED), ("max_turn_rate", "robot_turn_rate", TURN_RATE),
           ("max_acceleration", "robot_acceleration", ACCELERATION))


def is_world_folder(path) -> bool:
    """Whether ``path`` is a folder holding a world.json (only its presence is looked at)."""
    return (Path(path) / METADATA_NAME).is_file()


def task_of(meta: Mapping[str, Any], task: Optional[str] = None, what: str = "parameter 'task'") -> dict:
    """world.json's ``tasks[]`` entry ``task`` of ``meta`` (its first without one); a ParameterError naming
    the ids that exist otherwise. ``what`` names the argument in the message (``option '--task'``)."""
    tasks = list(meta.get("tasks") or [])
    ids = [str(t.get("id")) for t in tasks]
    if task is None and tasks:
        return tasks[0]
    if task is not None and str(task) in ids:
        return tasks[ids.index(str(task))]
    if not tasks:
        raise ParameterError(f"world {meta.get('world_id')} has no tasks, so {what} names none of them")
    raise ParameterError(f"{what} must be one of {', '.join(ids)}, got {task!r}")


def robot_of(meta: Mapping[str, Any]) -> Robot:
    """The footprint of world.json's ``robot`` (radius, height, clearance) as the :class:`~worldgen.scene.Robot`
    a World carries."""
    r = meta["robot"]
    limits = {k: float(r[k]) for k in CLIMB_DEFAULTS if k in r}  # on terrain only (docs/terrain.md)
    return Robot(float(r["radius"]), float(r["height"]), float(r["clearance"]), **limits)


def robot_description_of(world) -> RobotDescription:
    """The :class:`~worldgen.scene.robot.RobotDescription` of ``world``: world.json's content (a mapping), or
    a generated :class:`~worldgen.World` (read off its robot, parameters and lidar without rendering a file,
    its numbers rounded as world.json rounds them, so both give the same description).

    Motion limits: world.json's ``robot.max_speed``, ``max_turn_rate``, ``max_acceleration`` where present,
    else the recorded ``params`` (``robot_speed``, ``robot_turn_rate``, ``robot_acceleration``), else those
    parameters' defaults. The lidar: world.json's ``sensors.lidar``, its height above the first spawn."""
    if isinstance(world, Mapping):
        return _described(world)
    from worldgen.groundtruth.truth import lidar_spec

    spec = lidar_spec(world)
    robot = world.robot
    spawn_z = world.tasks[0].spawn.z if world.tasks else 0.0
    return _described({"robot": {"radius": robot.radius, "height": robot.height, "clearance": robot.clearance,
                                 **robot.limits()},
                       "params": {k: round_float(v) if isinstance(v, float) else v for k, v in world.params.items()},
                       "tasks": [{"spawn": [0.0, 0.0, round_float(spawn_z)]}],
                       "sensors": {"lidar": {"pose": [round_float(v) for v in spec.pose.as_list()],
                                             "samples": spec.samples, "angle_min": round_float(spec.angle_min),
                                             "angle_max": round_float(spec.angle_max),
                                             "range_min": round_float(spec.range_min),
                                             "range_max": round_float(spec.range_max)}}})


def motion_limits_of(meta: Mapping[str, Any]) -> tuple[float, float, float]:
    """(max_speed m/s, turn_rate rad/s, acceleration m/s^2) of world.json's content ``meta``: its ``robot``
    block's, else its ``params``', else the parameters' defaults (a mapping with only ``params``, a
    generator's resolved parameters, gets those)."""
    r, params = meta.get("robot") or {}, meta.get("params") or {}
    speed, turn, acceleration = (float(r.get(key, params.get(name, default))) for key, name, default in _MOTION)
    return speed, turn, acceleration


def _described(meta: Mapping[str, Any]) -> RobotDescription:
    limits = motion_limits_of(meta)
    lidar = meta["sensors"]["lidar"]
    tasks = meta.get("tasks") or []
    spawn_z = float(tasks[0]["spawn"][2]) if tasks else 0.0
    mount = LidarDescription(round_float(float(lidar["pose"][2]) - spawn_z), int(lidar["samples"]),
                             float(lidar["angle_min"]), float(lidar["angle_max"]), float(lidar["range_min"]),
                             float(lidar["range_max"]))
    return RobotDescription(robot_of(meta), *limits, mount)


class WorldFolder:
    """One written world, read on demand through ``read`` (a file of the world by its relative name).

    ``path`` is its folder on disk (None for an unwritten World or a world inside a pack archive);
    ``label`` how messages name it; ``metadata`` a callable giving world.json's dict where the world has
    it already (a World, whose metadata is built, not read); ``scene`` the World's scene, else None.
    """

    def __init__(self, read: Callable[[str], bytes], path: Optional[Path] = None, *, label: str,
                 metadata: Optional[Callable[[], dict]] = None, scene: Any = None,
                 description: Optional[Callable[[], RobotDescription]] = None):
        self._read = read
        self._description = description
        self.path = None if path is None else Path(path)
        self.label = label
        self._built = metadata
        self.scene = scene

    @classmethod
    def open(cls, folder, what: str = "parameter 'world'") -> "WorldFolder":
        """The world written in ``folder`` (or ``folder`` naming its world.json), its world.json read now: a
        folder that is not a world is one ParameterError line naming ``what`` (``--world``, ``argument WORLD``)."""
        path = Path(folder)
        if path.name == METADATA_NAME and path.is_file():
            path = path.parent
        if not is_world_folder(path):
            raise ParameterError(f"{what} '{folder}' is not a world folder (no {METADATA_NAME})")
        world = cls(partial(_read_in, path), path, label=f"{what} '{folder}'")
        world.metadata  # noqa: B018 -- read at once: a broken world.json is the caller's mistake, found here
        return world

    def __repr__(self) -> str:
        return f"<WorldFolder {self.label}>"

    # -- what a World and a PackWorld both offer ----------------------------------------------------------
    @cached_property
    def metadata(self) -> dict:
        """world.json as a dict."""
        if self._built is not None:
            return self._built()
        try:
            meta = json.loads(self.read(METADATA_NAME))
        except ValueError as exc:
            raise ParameterError(f"{self.label}: {METADATA_NAME} cannot be read as JSON ({exc})") from None
        if not isinstance(meta, dict) or not isinstance(meta.get("world_id"), str):
            raise ParameterError(f"{self.label}: {METADATA_NAME} is not a world's metadata "
                                 "(a JSON object with a world_id)")
        return meta

    def read(self, name: str) -> bytes:
        """A file of the world by its name in the folder (``world.sdf``, ``meshes/...``, ``world.json``)."""
        try:
            return self._read(name)
        except OSError as exc:
            raise ParameterError(f"{self.label}: cannot read {name} ({exc.strerror or exc})") from None

    @property
    def world_id(self) -> str:
        return str(self.metadata["world_id"])

    @property
    def generator(self) -> str:
        return str(self.metadata["generator"])

    @property
    def seed(self) -> int:
        return int(self.metadata["seed"])

    @property
    def params(self) -> dict:
        return dict(self.metadata.get("params") or {})

    @property
    def robot(self) -> Robot:
        """The footprint (world.json ``robot``)."""
        return robot_of(self.metadata)

    @property
    def robot_description(self) -> RobotDescription:
        """The robot every simulator builds (:func:`robot_description_of`): footprint, motion limits, lidar."""
        return self._description() if self._description is not None else robot_description_of(self.metadata)

    def file(self, fmt: str) -> Path:
        """Path on disk of the world's file of format key ``fmt`` (``sdf``, ``mjcf``, ``urdf``, ``usd``, ``usdc``,
        ``map_pgm``, ...; ``json``: world.json itself), as :meth:`worldgen.World.file` gives it."""
        rel = self.file_name(fmt)
        if self.path is None:
            raise ParameterError(f"{self.label} has no folder on disk (an unwritten World, or a world inside a pack "
                                 f"archive): write or extract it to use its {fmt} file")
        path = self.path / _inside(rel)
        if not path.is_file():
            raise ParameterError(f"{self.label}: its {fmt} file {rel} is missing")
        return path

    # -- what only the reader adds --------------------------------------------------------------------------
    def task(self, task: Optional[str] = None, what: str = "parameter 'task'") -> dict:
        """world.json's ``tasks[]`` entry of id ``task`` (the first without one); an unknown id is a
        ParameterError naming the ids the world has."""
        return task_of(self.metadata, task, what)

    @property
    def task_ids(self) -> tuple[str, ...]:
        return tuple(str(t["id"]) for t in self.metadata.get("tasks") or [])

    def file_name(self, fmt: str) -> str:
        """The relative name of the file of format key ``fmt`` (world.json ``files[fmt].path``)."""
        if fmt == "json":
            return METADATA_NAME
        files = self.metadata.get("files") or {}
        entry = files.get(fmt)
        if not isinstance(entry, Mapping) or not isinstance(entry.get("path"), str):
            kinds = ", ".join(k for k in sorted(files) if ":" not in k)  # formats and the map, not every mesh
            raise ParameterError(f"{self.label} has no {fmt} file (it has {kinds or 'none'}); "
                                 "write the world with that format")
        return str(entry["path"])

    def file_bytes(self, fmt: str) -> bytes:
        """The bytes of the world's file of format key ``fmt``, wherever the world is (no folder needed)."""
        return self.read(self.file_name(fmt))


def _read_in(folder: Path, name: str) -> bytes:
    """The bytes of ``folder/name`` (a module-level function, not a closure, so a reader pickles)."""
    return (folder / _inside(name)).read_bytes()


def _inside(rel: str) -> str:
    """``rel`` when it names a file inside the world's folder; a ParameterError otherwise (a world.json that
    names ``../x`` must not make a reader open a file outside)."""
    pure = PurePosixPath(rel)
    if pure.is_absolute() or ".." in pure.parts or not pure.parts:
        raise ParameterError(f"refusing to read {rel!r}: it is not a file inside the world folder")
    return rel


def open_world(world, what: str = "parameter 'world'") -> WorldFolder:
    """A :class:`WorldFolder` for a World, a PackWorld, a world folder (str or Path) or a WorldFolder (returned
    as it is); anything else, or a folder that is not a world, is one ParameterError line naming ``what``."""
    if isinstance(world, WorldFolder):
        return world
    if isinstance(world, (str, Path)):
        return WorldFolder.open(world, what)
    own = getattr(world, "reader", None)
    if isinstance(own, WorldFolder):  # a PackWorld reads itself through one
        return own
    kind = type(world)  # asked of the class: a World's metadata is rendered on first use, not to be looked at
    if hasattr(kind, "metadata") and hasattr(kind, "read") and hasattr(world, "world_id"):  # a World
        return WorldFolder(world.read, getattr(world, "path", None), label=f"world {world.world_id}",
                           metadata=lambda: world.metadata, scene=getattr(world, "scene", None),
                           description=lambda: robot_description_of(world))
    raise ParameterError(f"{what} must be a World, a PackWorld or a world folder, got {type(world).__name__}")
