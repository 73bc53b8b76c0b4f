"""A generated, checked world: its scene, tasks and feasibility report, exportable on demand."""

from __future__ import annotations

import hashlib
import json
from functools import cached_property
from pathlib import Path
from typing import Any, Iterable, Mapping, Optional, Sequence, Union

from worldgen.errors import OutputError, ParameterError
from worldgen.export import formats as formats_table
from worldgen.export.formats import FILE_NAMES, FORMATS, SDF_VERSIONS, normalise_formats
from worldgen.files import METADATA_NAME, PREVIEW_NAME, refuse_other_world, write_folder_atomically
from worldgen.scene import Robot, Scene, Task

__all__ = ["World", "FORMATS", "FILE_NAMES", "SDF_VERSIONS", "normalise_formats"]


#: set_provenance's "leave it as it is".
_UNCHANGED: Any = object()

class World:
    """One world. Nothing here touches the disk until :meth:`write`.

    ``params`` holds every parameter resolved (defaults filled in), so
    ``generate(generator, seed, **params)`` rebuilds exactly this world.
    ``attempts`` is how many draws it took (1 = the first draw passed).
    ``allow_infeasible`` records how it was asked for, so that it regenerates the same way.
    ``preset`` names the preset it came from (None otherwise): recorded in
    world.json and in the folder's name, never in ``world_id``.
    """

    def __init__(self, generator: str, seed: int, params: Mapping[str, Any], scene: Scene,
                 tasks: Sequence[Task], robot: Robot, feasibility, attempts: int, allow_infeasible: bool = False):
        self.generator = generator
        self.seed = seed
        self.params = dict(params)
        self.scene = scene
        self.tasks = tuple(tasks)
        self.robot = robot
        self.feasibility = feasibility
        self.attempts = attempts
        self.allow_infeasible = bool(allow_infeasible)
        self.path: Optional[Path] = None  # the folder once written
        self._preset: Optional[str] = None
        self._difficulty_request: Optional[dict] = None
        self._blobs: dict[tuple, bytes] = {}  # export_bytes()'s renderings, by (format, SDF version)

    @property
    def preset(self) -> Optional[str]:
        """The preset this world came from (world.json ``preset``, the folder name), or None."""
        return self._preset

    @property
    def difficulty_request(self) -> Optional[dict]:
        """How a world asked for at a difficulty level was reached (worldgen.leveling), or None."""
        return self._difficulty_request

    def set_provenance(self, *, preset: Any = _UNCHANGED, difficulty_request: Any = _UNCHANGED) -> "World":
        """Record where this world came from: the one place its preset and its level request are set.

        Neither is part of the world's identity (``content_hash``); both are written to world.json. Returns
        the world, so a caller can chain it after ``generate``.
        """
        if preset is not _UNCHANGED:
            if preset is not None and not isinstance(preset, str):
                raise ParameterError(f"a world's preset must be a preset's name or None, got {preset!r}")
            self._preset = preset
        if difficulty_request is not _UNCHANGED:
            if difficulty_request is not None and not isinstance(difficulty_request, dict):
                raise ParameterError(f"a world's difficulty_request must be a dict or None, got {difficulty_request!r}")
            self._difficulty_request = difficulty_request
        return self

    def __repr__(self) -> str:
        try:
            return f"<World {self.world_id} feasible={self.feasibility.feasible}>"
        except Exception:  # a repr must never raise
            return f"<World {self.generator} seed={self.seed}>"

    @cached_property
    def content_hash(self) -> str:
        """``sha256:<hex>`` of everything the written files depend on, so equal hashes mean equal worlds.

        The scene's canonical description (geometry, joints, movers, physics),
        plus the generator, seed, every resolved parameter (which fix the robot,
        the tasks, the sensors and the map) and whether it was asked for with
        ``allow_infeasible``. Not the preset's name: a preset's world is the
        generator's world with those parameters, written to its own folder
        (``folder_name``) so that the two never replace each other. Not the
        worldgen version, nor the formats chosen: those change how a world is
        written, not which world it is.
        """
        identity = {
            "scene": self.scene.content_hash(),
            "generator": self.generator,
            "seed": self.seed,
            "params": self.params,
            "allow_infeasible": self.allow_infeasible,
        }
        text = json.dumps(identity, sort_keys=True, separators=(",", ":"))
        return "sha256:" + hashlib.sha256(text.encode()).hexdigest()

    @cached_property
    def world_id(self) -> str:
        """``<generator>-s<seed>-<8 hex of content_hash>``: stable and filesystem-safe."""
        return f"{self.generator}-s{self.seed}-{self.content_hash.split(':', 1)[1][:8]}"

    @property
    def folder_name(self) -> str:
        """The folder :meth:`write` makes: ``<preset>--<world_id>`` for a preset's world, ``L<k>-r<request seed>--``
        before the id for a world asked for at level k (its own seed is the draw that landed, 19 digits long), else
        ``world_id``: worlds of several presets, or levels, over one generator can be told apart in one folder."""
        name = self.world_id
        if self.difficulty_request:
            level = str(self.difficulty_request["level"]).split("/")[0]
            name = f"L{level}-r{self.difficulty_request['seed']}--{name}"
        return f"{self.preset}--{name}" if self.preset else name

    # -- in-memory exports -------------------------------------------------
    def to_sdf(self, version: str = "1.9") -> str:
        """The world as SDFormat ``version`` (1.9 for Gazebo Fortress-Harmonic, 1.6 for classic)."""
        return self.export("sdf", version)

    def to_mjcf(self) -> str:
        """The world as MJCF, loadable with ``mujoco.MjModel.from_xml_string``."""
        return self.export("mjcf")

    def to_urdf(self) -> str:
        """The world as one URDF robot: a root link with every entity a link joined to it."""
        return self.export("urdf")

    def export(self, fmt: str, sdf_version: str = "1.9") -> str:
        """The world's text in ``fmt`` (a text format: not ``usdc``, whose bytes :meth:`export_bytes` gives)."""
        if fmt in formats_table.TABLE and formats_table.TABLE[fmt].binary:
            raise OutputError(f"format {fmt!r} is binary, not text: use World.export_bytes({fmt!r})")
        return self.export_bytes(fmt, sdf_version).decode()

    def export_bytes(self, fmt: str, sdf_version: str = "1.9") -> bytes:
        """The bytes of the world's file in ``fmt``, rendered once per world: ``to_*``, ``metadata`` and
        ``write`` share them (a World is a value: its scene and params do not change)."""
        key = (fmt, sdf_version if fmt == "sdf" else None)
        data = self._blobs.get(key)
        if data is None:
            data = self._blobs[key] = self._render(fmt, sdf_version)
        return data

    def _render(self, fmt: str, sdf_version: str) -> bytes:
        return formats_table.render(fmt, self.scene, self.world_id, self.params, sdf_version, world=self)

    def mesh_files(self) -> dict[str, bytes]:
        """Mesh files the exported formats refer to: relative path -> bytes."""
        from worldgen.export import meshes
        return meshes.mesh_files(self.scene)

    def metadata_for(self, files: Mapping[str, tuple[str, bytes]]) -> dict:
        """world.json as a dict, for the given ``{key: (relative path, bytes)}`` files."""
        from worldgen.export import metadata
        return metadata.build(self, {k: (p, hashlib.sha256(b).hexdigest()) for k, (p, b) in files.items()})

    def rendered_files(self, formats: Iterable[str] = FORMATS, sdf_version: str = "1.9") -> dict[str, tuple[str, bytes]]:
        """Every file of the world but world.json: ``{key: (relative path, bytes)}``."""
        formats = normalise_formats(formats)
        formats_table.require_formats(formats)  # a missing extra: one line, before anything is rendered
        files = {fmt: (FILE_NAMES[fmt], self.export_bytes(fmt, sdf_version)) for fmt in formats}
        if formats_table.uses_meshes(formats):
            for rel, data in self.mesh_files().items():
                files[f"mesh:{rel}"] = (rel, data)
        from worldgen.groundtruth import truth
        files.update(truth.map_files(self))  # the occupancy map goes with every world
        from worldgen.export import scenario
        files.update(scenario.files(self, formats))  # scenario.yaml: the tasks as a scenario spec (worldgen.export.scenario)
        return files

    @cached_property
    def _default_files(self) -> dict[str, tuple[str, bytes]]:
        # Every format, SDF 1.9: what .metadata describes and what write() writes by default,
        # rendered once for both.
        return self.rendered_files()

    @cached_property
    def metadata(self) -> dict:
        """world.json of this world written in every format (SDF 1.9)."""
        return self.metadata_for(self._default_files)

    def read(self, name: str) -> bytes:
        """A file of this world by its name in the folder (``world.sdf``, ``meshes/...``, ``world.json``).

        The bytes :meth:`write` would write with its defaults; preview.png is not among them.
        """
        if name == METADATA_NAME:
            from worldgen.export import metadata
            return metadata.dumps(self.metadata).encode()
        for rel, data in self._default_files.values():
            if rel == name:
                return data
        raise OutputError(f"world {self.world_id} has no file {name!r}")

    def to_json(self, formats: Iterable[str] = FORMATS, sdf_version: str = "1.9") -> str:
        from worldgen.export import metadata
        return metadata.dumps(self.metadata_for(self.rendered_files(formats, sdf_version)))

    # -- disk --------------------------------------------------------------
    def write(self, out_dir, formats: Iterable[str] = FORMATS, sdf_version: str = "1.9",
              preview: bool = True, overwrite: bool = False, ros: Union[bool, str] = False) -> Path:
        """Write ``out_dir/<folder_name>/`` (the world's files and world.json); return that folder.

        The folder appears complete or not at all: files are written into a
        temporary folder beside it, which is then renamed into place.
        ``preview`` adds preview.png, a top-down picture (worldgen.export.preview).
        ``ros`` adds the ROS 2 bundle in ``ros2/`` (worldgen.export.ros2): True for the default
        Gazebo release, or a release's name (``fortress``, ``harmonic``, ...).
        A folder of the same name that holds another world (another
        ``content_hash``, or no readable world.json) is an :class:`OutputError`
        unless ``overwrite``; the same world is simply written again.
        """
        out_dir = Path(out_dir)
        if not overwrite:
            refuse_other_world(out_dir / self.folder_name, self.content_hash)
        blobs = self.folder_blobs(formats, sdf_version, preview, ros)
        target = write_folder_atomically(out_dir, self.folder_name, blobs)
        self.path = target
        return target

    def folder_blobs(self, formats: Iterable[str] = FORMATS, sdf_version: str = "1.9",
                     preview: bool = True, ros: Union[bool, str] = False) -> dict[str, bytes]:
        """Every file :meth:`write` puts in the folder, world.json included: relative path -> bytes."""
        from worldgen.export import metadata

        default = normalise_formats(formats) == FORMATS and sdf_version == "1.9"
        files = self._default_files if default else self.rendered_files(formats, sdf_version)
        meta = self.metadata_for(files)  # afresh: a caller may have edited .metadata's dict
        blobs = {path: data for path, data in files.values()}
        if preview:  # a picture of world.json, not listed in its `files` (see worldgen.export.preview)
            from worldgen.export.preview import render
            blobs[PREVIEW_NAME] = render(meta)
        blobs[METADATA_NAME] = metadata.dumps(meta).encode()
        if ros:  # derived from the world like preview.png, so not listed in world.json's `files` either
            from worldgen.export.ros2 import bundle, release_of
            blobs.update(bundle(self, sdf_version, release_of(ros)))
        return blobs

    def file(self, fmt: str) -> Path:
        """Path of a written file (``sdf``, ``mjcf``, ``urdf`` or ``json``)."""
        if self.path is None:
            raise OutputError("this world has not been written yet; call World.write(folder) first")
        return self.path / (METADATA_NAME if fmt == "json" else FILE_NAMES[fmt])

