"""Where the environment's worlds come from: a generator (or preset) per episode, or a built pack in order.

A source hands the environment one :class:`EpisodeWorld` per episode: the
world's MJCF as an lxml element (the env adds its robot to it), the footprint,
the task as world.json describes it, the movers, and lazy access to the
oracles' :class:`~worldgen.groundtruth.ground.Ground` and to world.json (for drawing).

- :class:`GeneratorSource`: ``worldgen.generate(generator, seed, **params)`` in
  memory, a new seed per episode; nothing touches the disk. A preset is a
  generator with its parameters (yours on top).
- :class:`PackSource`: the worlds of a built pack (folder or archive) by index,
  each read from its world.json and world.mjcf.xml (a pack built without MJCF is
  regenerated from its recorded generator, seed and parameters, and must give
  the recorded ``content_hash``).
- :class:`FolderSource`: one written world folder, any of its tasks, every episode (a campaign's
  run of a policy: :mod:`worldgen.campaign.systems`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Callable, Mapping, Optional

from worldgen.errors import ParameterError, quoted
from worldgen.scene import Robot
from worldgen.scene.robot import RobotDescription

__all__ = ["EpisodeWorld", "GeneratorSource", "PackSource", "OneWorldSource", "FolderSource", "make_source"]


@dataclass(eq=False)
class EpisodeWorld:
    """One episode's world, as the environment needs it.

    ``task`` has world.json's ``tasks[]`` shape (``spawn``, ``goal``,
    ``goal_tolerance``, ``path`` with ``waypoints`` and ``length``,
    ``time_limit``); ``movers`` world.json's ``dynamic_obstacles[]`` shape;
    ``floor`` the names of the floor geoms (contacts with them are no collision);
    ``door_leaves`` the names of the door leaves (world.json ``doors[].name``, each
    a hinged body the robot may push open: touching one is a door contact, not a collision);
    ``bounds`` ((x0, y0), (x1, y1)) where the robot may be; :meth:`scene` the world's scene (for the geodesic field);
    ``doors`` world.json's ``doors[]`` (hinge joint, limits, doorway: what an automatic door opens by);
    ``terrain`` whether the world has terrain (the robot is then :mod:`worldgen.envs.terrain`'s base);
    ``description`` the robot the environment builds (sizes, motion limits, lidar), ``robot`` its footprint
    and ``lidar_height`` its lidar's height.
    """

    world_id: str
    mjcf: Any  # lxml root element of the world's MJCF; the environment may change it
    robot: Robot
    task: dict
    movers: list
    floor: frozenset
    lidar_height: float
    params: dict
    _ground: Callable[[], Any] = field(repr=False)
    _metadata: Callable[[], dict] = field(repr=False)
    _cache: dict = field(default_factory=dict, repr=False)
    door_leaves: frozenset = frozenset()
    _scene: Optional[Callable[[], Any]] = field(default=None, repr=False)
    bounds: Optional[tuple] = None
    doors: tuple = ()
    terrain: bool = False
    description: Optional[RobotDescription] = None

    @property
    def reference_path_length(self) -> float:
        """The task's optimal path length for the footprint (world.json ``tasks[].path.length``), m."""
        return float(self.task["path"]["length"])

    def ground(self):
        """The oracles' view of this world (FCL colliders built on first use), built once."""
        if "ground" not in self._cache:
            self._cache["ground"] = self._ground()
        return self._cache["ground"]

    def scene(self):
        """The world's :class:`~worldgen.scene.Scene` (a pack's world is regenerated for it, once)."""
        if "scene" not in self._cache:
            if self._scene is None:
                raise ParameterError(f"world {self.world_id} carries no scene to build the geodesic distance from")
            self._cache["scene"] = self._scene()
        return self._cache["scene"]

    def metadata(self) -> dict:
        """world.json as a dict (for drawing), built once; costly for a generated world (it renders every file)."""
        if "metadata" not in self._cache:
            self._cache["metadata"] = self._metadata()
        return self._cache["metadata"]


def _checked_task(world_id: str, task: dict) -> dict:
    if not task.get("path") or task.get("time_limit") is None:
        raise ParameterError(f"world {world_id} has no reference path for task {task.get('id')!r} (it was made "
                             "infeasible on purpose); the environment needs drivable worlds")
    return task


def _task_of_world(world) -> dict:
    """world.json's ``tasks[0]`` of an in-memory World, without rendering any file."""
    from worldgen.export.tasks import task_entry

    path = world.feasibility.paths[0] if world.feasibility.paths else None
    task = task_entry(world, world.tasks[0], path)
    timed = getattr(world.feasibility, "timed_paths", ())
    if timed and timed[0] is not None:  # among people: the certificate, as world.json has it
        task.update(timed_path=timed[0].rows.tolist(), arrival_time=timed[0].arrival)
    return _checked_task(world.world_id, task)


def episode_world(world) -> EpisodeWorld:
    """An :class:`EpisodeWorld` of an in-memory :class:`~worldgen.World` (no file rendered)."""
    from worldgen.export.metadata import mover_entry, person_entry
    from worldgen.export.xml import parse_bytes
    from worldgen.groundtruth.folder import robot_description_of
    from worldgen.groundtruth.ground import Ground
    from worldgen.scene.doors import door_records

    task = _task_of_world(world)
    # People after the movers (the MJCF's order); a person's entry carries its behaviour and tube, if any.
    movers = [dict(person_entry(m, world.params), loop=False) if m.person else mover_entry(m, world.params)
              for m in world.scene.movers]
    robot, description = world.robot, robot_description_of(world)
    leaves = frozenset(n.name for n in world.scene.nodes if n.role == "door")
    light = {"world_id": world.world_id, "tasks": [task], "dynamic_obstacles": [m for m in movers if m["loop"]],
             "people": [m for m in movers if not m["loop"]],
             "robot": {"radius": robot.radius, "height": robot.height, "clearance": robot.clearance},
             "doors": [{"name": name} for name in sorted(leaves)]}
    return EpisodeWorld(
        world_id=world.world_id, mjcf=parse_bytes(world.to_mjcf().encode()).getroot(), robot=robot,
        task=task, movers=movers, floor=frozenset(n.name for n in world.scene.nodes if n.role == "floor"),
        lidar_height=description.lidar.height, params=dict(world.params),
        _ground=lambda: Ground(light, scene=world.scene), _metadata=lambda: world.metadata_for({}),
        door_leaves=leaves, _scene=lambda: world.scene, bounds=tuple(map(tuple, world.scene.bounds)),
        doors=tuple(door_records(world.scene)) if leaves else (), terrain=world.scene.terrain is not None,
        description=description)


class GeneratorSource:
    """A fresh world per episode from ``generator`` and ``params`` (or a preset), checked up front."""

    def __init__(self, generator: Optional[str] = None, params: Optional[Mapping[str, Any]] = None,
                 preset: Optional[str] = None, difficulty: Any = None):
        from worldgen.generators import get

        if params is not None and not isinstance(params, Mapping):
            raise ParameterError(f"parameter 'params' must be a mapping of generator parameters, got {quoted(params)}")
        params = dict(params or {})
        self.preset = None
        if preset is not None:
            from worldgen.presets import load
            if generator is not None:
                raise ParameterError("parameters 'generator' and 'preset' exclude each other; a preset names its "
                                     f"generator, got generator={generator!r} and preset={preset!r}")
            p = load(preset)
            self.preset, generator, params = p.name, p.generator, p.merged(params)
        if not isinstance(generator, str):
            raise ParameterError(f"parameter 'generator' must be a generator's name, got {quoted(generator)}")
        self.generator = generator
        self.params = params
        self.resolved = get(generator).resolve(params)  # bad parameters fail now, not at the first reset
        #: A difficulty level every world is drawn at ("7/10", worldgen.leveling), or None.
        self.difficulty = difficulty
        if difficulty is not None:
            from worldgen.leveling import check_request

            check_request(generator, difficulty, params)

    def __len__(self) -> int:
        return 0  # unbounded: any seed

    def motion_bound(self) -> tuple[float, float]:
        """(max_speed m/s, turn_rate rad/s) of every world's robot: its parameters' (a generator's worlds
        share them)."""
        from worldgen.groundtruth.folder import motion_limits_of

        return motion_limits_of({"params": self.resolved})[:2]

    def distance_bound(self) -> tuple[float, bool]:
        """(bound, exact): the longest straight line inside any world of this source. Exact from the
        generator's ``size`` (its worlds' extents) where it has one; else the diagonal of the seed-0 world
        (a corridor's extents follow its parameters), not proven for every seed."""
        size = self.resolved.get("size")
        if size is not None:
            return math.hypot(*size), True
        bounds = self.world(0).bounds
        assert bounds is not None, "a generated world's episode has its bounds"
        (x0, y0), (x1, y1) = bounds
        return math.hypot(x1 - x0, y1 - y0), False

    def world(self, seed: int) -> EpisodeWorld:
        return episode_world(self.generated(seed))

    def generated(self, seed: int, difficulty: Any = None):
        """The :class:`~worldgen.World` of ``seed`` (at ``difficulty`` when given, else the source's own; the
        curricula of :mod:`worldgen.envs.curriculum` and :mod:`worldgen.envs.replay` keep and change it)."""
        from worldgen.api import generate

        world = generate(self.generator, seed, difficulty=self.difficulty if difficulty is None else difficulty,
                         **self.params)
        return world.set_provenance(preset=self.preset)


class OneWorldSource:
    """One in-memory world for every episode, driven as it is (the probes' yardsticks drive a world they
    generated once: worldgen.envs.ladder, benchmarks/bench_difficulty.py); set it as an env's ``source``."""

    def __init__(self, world):
        self.world_ = world

    def __len__(self) -> int:
        return 0

    def motion_bound(self) -> tuple[float, float]:
        """(max_speed m/s, turn_rate rad/s) of the world's robot."""
        from worldgen.groundtruth.folder import robot_description_of

        robot = robot_description_of(self.world_)
        return robot.max_speed, robot.turn_rate

    def world(self, seed) -> EpisodeWorld:
        return episode_world(self.world_)


class PackSource:
    """The worlds of a built pack (a :class:`~worldgen.Pack`, or its folder or archive path), by index."""

    def __init__(self, pack):
        from worldgen.pack import Pack

        if isinstance(pack, (str, Path)):
            pack = Pack.open(pack)
        if not isinstance(pack, Pack):
            raise ParameterError(f"parameter 'pack' must be a worldgen.Pack or a pack folder or archive, got {quoted(pack)}")
        if len(pack) == 0:
            raise ParameterError(f"parameter 'pack' must hold at least one world, got pack {pack.name!r} with none")
        self.pack = pack

    def __len__(self) -> int:
        return len(self.pack)

    def distance_bound(self) -> tuple[float, bool]:
        """(bound, exact): the longest diagonal of the pack's worlds' bounds (world.json ``bounds``)."""
        longest = 0.0
        for pw in self.pack:
            b = pw.metadata["bounds"]
            longest = max(longest, math.hypot(b["max"][0] - b["min"][0], b["max"][1] - b["min"][1]))
        return longest, True

    def motion_bound(self) -> tuple[float, float]:
        """(max_speed m/s, turn_rate rad/s): the largest of the pack's worlds' robots (world.json ``robot``)."""
        from worldgen.groundtruth.folder import motion_limits_of

        limits = [motion_limits_of(pw.metadata)[:2] for pw in self.pack]
        return max(v for v, _ in limits), max(w for _, w in limits)

    def world(self, index: int) -> EpisodeWorld:
        from worldgen.groundtruth.ground import load as ground_of

        pw = self.pack[index]
        meta = pw.metadata
        mjcf = pw.reader.file_bytes("mjcf") if "mjcf" in meta.get("files", {}) else None
        return _episode_world(pw.reader, pw.task(), mjcf or self._regenerated(pw, meta).to_mjcf().encode(),
                              ground=lambda: ground_of(pw), scene=lambda: self._regenerated(pw, meta).scene)

    @staticmethod
    def _regenerated(pw, meta):
        """The pack world regenerated from its recorded generator, seed and parameters (same content_hash)."""
        from worldgen.api import generate

        world = generate(meta["generator"], meta["seed"], allow_infeasible=meta["feasibility"].get("allow_infeasible", False),
                         **meta["params"])
        if world.content_hash != meta["content_hash"]:
            raise ParameterError(f"pack world {pw.world_id} does not regenerate with this worldgen version "
                                 f"({world.content_hash} != {meta['content_hash']}); the environment needs its MJCF "
                                 "and, for the geodesic reward, its scene")
        return world


class FolderSource:
    """One written world folder for every episode, driving ``task`` (a task id of its world.json; None: the
    first): what a campaign runs a policy in (worldgen.campaign.systems); set it as an env's ``source``.

    The folder is read as a pack's world is (:meth:`PackSource.world`), through the oracles' ground truth
    (:func:`worldgen.groundtruth.ground.load`); the MJCF must be there (a campaign writes it)."""

    def __init__(self, folder, task: Optional[str] = None):
        from worldgen.groundtruth.folder import open_world
        from worldgen.groundtruth.ground import load

        self.folder = Path(folder)
        self.ground = load(self.folder)
        self.reader = open_world(self.folder)
        ids = list(self.reader.task_ids)
        if task is not None and task not in ids:
            raise ParameterError(f"parameter 'task' must be one of the world's tasks ({', '.join(ids)}), got {task!r}")
        self.task = task if task is not None else ids[0]
        if "mjcf" not in self.reader.metadata.get("files", {}):
            raise ParameterError(f"world folder '{folder}' has no MJCF file; write the world with format mjcf "
                                 "to run it in the environment")

    def __len__(self) -> int:
        return 0

    def motion_bound(self) -> tuple[float, float]:
        """(max_speed m/s, turn_rate rad/s) of the world's robot (world.json ``robot``)."""
        robot = self.reader.robot_description
        return robot.max_speed, robot.turn_rate

    def world(self, seed) -> EpisodeWorld:
        from worldgen.verify import load_world

        # The scene (reacting people, the geodesic reward): the world rebuilt with its recorded edits (a shrunk
        # world, an edited level) and proven the one recorded.
        return _episode_world(self.reader, self.reader.task(self.task), self.reader.file_bytes("mjcf"),
                              ground=lambda: self.ground, scene=lambda: load_world(self.folder).scene)


def _episode_world(reader, task: dict, mjcf: bytes, ground: Callable[[], Any], scene: Callable[[], Any]) -> EpisodeWorld:
    """The episode world of a written world (``reader``: :func:`worldgen.groundtruth.folder.open_world`'s)
    driving ``task``, with its MJCF bytes; its ground truth and scene are made on first use."""
    from lxml import etree

    from worldgen.export.xml import safe_parser

    meta = reader.metadata
    params = dict(meta.get("params", {}))
    description = reader.robot_description
    return EpisodeWorld(
        world_id=reader.world_id, mjcf=etree.fromstring(mjcf, safe_parser()), robot=reader.robot,
        task=_checked_task(reader.world_id, task),
        movers=list(meta.get("dynamic_obstacles") or []) + [dict(p, loop=False) for p in meta.get("people") or []],
        floor=frozenset(e["name"] for e in meta["entities"] if e["role"] == "floor"),
        lidar_height=description.lidar.height, params=params,
        _ground=ground, _metadata=lambda: meta, _scene=scene,
        bounds=(tuple(meta["bounds"]["min"]), tuple(meta["bounds"]["max"])),
        door_leaves=frozenset(str(d["name"]) for d in meta.get("doors") or []), doors=tuple(meta.get("doors") or ()),
        terrain=bool(meta.get("terrain")), description=description)


def make_source(generator=None, params=None, preset=None, pack=None, difficulty=None):
    """The source for the environment's arguments: a pack, a preset, a generator; the ``drl_arena`` preset by default."""
    if pack is not None:
        if generator is not None or preset is not None or params or difficulty is not None:
            raise ParameterError("parameter 'pack' excludes 'generator', 'preset', 'params' and 'difficulty': "
                                 "a pack's worlds are fixed")
        return PackSource(pack)
    if generator is None and preset is None:
        preset = "drl_arena"
    return GeneratorSource(generator, params, preset, difficulty)
