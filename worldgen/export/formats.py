"""The one table of the formats a world is written in: each format's file, writer, and what it carries.

Everything that needs to know the formats reads :data:`TABLE`: :class:`~worldgen.world.World` renders
through :func:`render`, world.json's notes on movers come from :func:`movers_note`, scenario.yaml names
the first written file, the command line and recipes check names with :func:`normalise_formats`.
A writer is named by ``module:function`` and imported on first use, so the writers can read this
table (the SDF versions) without an import cycle and a program that writes only MJCF never imports
the SDF writer.
"""

from __future__ import annotations

import importlib
from dataclasses import dataclass
from typing import Any, Iterable, Mapping, Optional

from worldgen.errors import ParameterError
from worldgen.files import MJCF_NAME, SDF_NAME, URDF_NAME, USDA_NAME, USDC_NAME

__all__ = ["Format", "TABLE", "FORMATS", "ALL_FORMATS", "FILE_NAMES", "SDF_VERSIONS", "normalise_formats", "render",
           "movers_note", "uses_meshes", "require_formats", "unavailable_formats"]

#: Versions the SDF exporter writes: 1.9 for Gazebo Fortress-Harmonic, 1.6 for Gazebo classic.
SDF_VERSIONS = ("1.9", "1.6")


@dataclass(frozen=True)
class Format:
    """One output format.

    ``writer`` is ``module:function`` taking ``(scene, name=...)`` (and ``version=`` where
    ``versions`` lists some) and returning the file's bytes. ``movers_as`` says how the format
    carries a mover (None: it cannot); ``movers_switch`` names a boolean parameter that, set false,
    leaves the movers out of this format. ``meshes``: the file refers to mesh files beside it.
    ``optional``: written only when asked for (not among :data:`FORMATS`, the default), and named in
    world.json's ``formats`` notes only when written, so a world written without it keeps its bytes.
    ``requires``: ``module:function`` that imports what the writer needs, raising a one-line
    MissingDependencyError when it is not installed. ``world_args``: ``module:function`` giving, for a
    World, the writer's further keyword arguments (USD: the tasks, and how long movers play).
    ``binary``: the file is not text (``World.export_bytes`` gives it, ``World.export`` refuses).
    """

    name: str
    file_name: str
    writer: str
    movers_as: Optional[str]
    movers_switch: Optional[str] = None
    versions: tuple[str, ...] = ()
    meshes: bool = False
    optional: bool = False
    requires: Optional[str] = None
    world_args: Optional[str] = None
    binary: bool = False

    def carries_movers(self, params: Mapping[str, Any]) -> bool:
        return self.movers_as is not None and (self.movers_switch is None or bool(params.get(self.movers_switch, True)))


#: Every format, in the order they are written. USD (Isaac Sim / Isaac Lab) is optional: it needs
#: usd-core (the ``usd`` extra) and is written only when asked for. SDF movers are <actor>s, which Drake rejects: the
#: ``sdf_actors`` parameter leaves them out for Drake users (docs/formats.md).
TABLE: dict[str, Format] = {f.name: f for f in (
    Format("sdf", SDF_NAME, "worldgen.export.sdf:to_sdf", "actor", "sdf_actors", SDF_VERSIONS, meshes=True),
    Format("mjcf", MJCF_NAME, "worldgen.export.mjcf:to_mjcf", "mocap_body"),
    Format("urdf", URDF_NAME, "worldgen.export.urdf:to_urdf", None, meshes=True),
    Format("usd", USDA_NAME, "worldgen.export.usd:to_usd", "kinematic_body", optional=True,
           requires="worldgen.export.usd_prims:require_pxr",
           world_args="worldgen.export.usd_motion:writer_args"),
    # The same stage in USD's binary crate form: smaller (5.0 against 12.7 kB for door seed 0 with a mover), not diffable.
    Format("usdc", USDC_NAME, "worldgen.export.usd:to_usdc", "kinematic_body", optional=True,
           requires="worldgen.export.usd_prims:require_pxr",
           world_args="worldgen.export.usd_motion:writer_args", binary=True),
    # OpenSCENARIO 2 for scenario_execution: one scenario per task over the --ros bundle (docs/osc.md). Its
    # movers are osc_actor fields; world.sdf's <actor>s walk them, so without those (sdf_actors) it has none.
    Format("osc", "world.osc", "worldgen.export.osc:to_osc", "osc_actor", "sdf_actors", optional=True,
           world_args="worldgen.export.osc:writer_args"),
    # A world's crowd for the social-navigation simulators (docs/pedsim.md, docs/hunav.md): each person and
    # scripted mover an agent walking the corners of its world.json walk; refused for a world without people.
    Format("pedsim", "pedsim.xml", "worldgen.export.pedsim:to_pedsim", "agent", optional=True),
    Format("hunav", "hunav_agents.yaml", "worldgen.export.hunav:to_hunav", "agent", optional=True,
           world_args="worldgen.export.hunav:writer_args"),
)}
#: The formats written when none are named; :data:`ALL_FORMATS` adds the optional ones.
FORMATS = tuple(f.name for f in TABLE.values() if not f.optional)
ALL_FORMATS = tuple(TABLE)
FILE_NAMES = {f.name: f.file_name for f in TABLE.values()}


def normalise_formats(formats: Iterable[str]) -> tuple[str, ...]:
    """The chosen formats in writing order; a comma-separated string or any iterable of names."""
    if isinstance(formats, str):
        formats = [f for f in formats.split(",") if f.strip()]
    chosen = [f.strip().lower() for f in formats]
    for f in chosen:
        if f not in TABLE:
            raise ParameterError(f"parameter 'formats' must name formats among {', '.join(ALL_FORMATS)}, got {f!r}")
    if not chosen:
        raise ParameterError(f"parameter 'formats' must name at least one of {', '.join(ALL_FORMATS)}, got nothing")
    return tuple(f for f in ALL_FORMATS if f in chosen)


def _function(ref: str):
    module, function = ref.split(":")
    return getattr(importlib.import_module(module), function)


def require_formats(formats: Iterable[str]) -> None:
    """MissingDependencyError (one line naming the extra) if a chosen format's dependency is not installed.

    Called before any world is drawn or any file written, so that a missing extra stops a command at
    once and leaves nothing behind.
    """
    for f in normalise_formats(formats):
        requires = TABLE[f].requires
        if requires:
            _function(requires)()


def render(fmt: str, scene, name: str, params: Mapping[str, Any], sdf_version: str = "1.9", world=None) -> bytes:
    """The bytes of ``scene`` written as ``fmt`` under the world name ``name``.

    ``world`` gives a format with ``world_args`` what it reads off the world (the tasks, ...)."""
    (chosen,) = normalise_formats([fmt])
    spec = TABLE[chosen]
    if scene.movers and not spec.carries_movers(params):
        scene = scene.with_movers(())
    writer = _function(spec.writer)
    if spec.world_args:
        return writer(scene, name=name, **(_function(spec.world_args)(world) if world is not None else {}))
    return writer(scene, name=name, **({"version": sdf_version} if spec.versions else {}))


def movers_note(params: Mapping[str, Any], written: Iterable[str] = ()) -> dict[str, Optional[str]]:
    """How each format carries a mover of a world with ``params``: world.json's ``dynamic_obstacles[].formats``.

    Every default format, and an optional one only where it is among the ``written`` file keys."""
    written = set(written)
    return {f.name: (f.movers_as if f.carries_movers(params) else None) for f in TABLE.values()
            if not f.optional or f.name in written}


def uses_meshes(formats: Iterable[str]) -> bool:
    """Whether any of ``formats`` refers to mesh files beside it."""
    return any(TABLE[f].meshes for f in formats)


def unavailable_formats(formats: Iterable[str]) -> tuple[str, ...]:
    """Those of ``formats`` whose optional dependency is not installed (``worldgen check`` leaves them out)."""
    from worldgen.errors import MissingDependencyError

    missing = []
    for f in normalise_formats(formats):
        try:
            require_formats([f])
        except MissingDependencyError:
            missing.append(f)
    return tuple(missing)
