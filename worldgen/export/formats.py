"""The files a world is written as: the formats, their file names, the SDF versions."""

from __future__ import annotations

from typing import Iterable

from worldgen.errors import ParameterError

__all__ = ["FORMATS", "FILE_NAMES", "SDF_VERSIONS", "normalise_formats"]

#: Every format a world can be written in, in the order they are written.
FORMATS = ("sdf", "mjcf", "urdf")
FILE_NAMES = {"sdf": "world.sdf", "mjcf": "world.mjcf.xml", "urdf": "world.urdf"}
#: Versions the SDF exporter writes: 1.9 for Gazebo Fortress-Harmonic, 1.6 for Gazebo classic.
SDF_VERSIONS = ("1.9", "1.6")


def normalise_formats(formats: Iterable[str]) -> tuple[str, ...]:
    """The chosen formats in writing order; a comma-separated string or any iterable of names."""
    if isinstance(formats, str):
        formats = [f for f in formats.split(",") if f.strip()]
    chosen = [f.strip().lower() for f in formats]
    for f in chosen:
        if f not in FORMATS:
            raise ParameterError(f"parameter 'formats' must name formats among {', '.join(FORMATS)}, got {f!r}")
    if not chosen:
        raise ParameterError(f"parameter 'formats' must name at least one of {', '.join(FORMATS)}, got nothing")
    return tuple(f for f in FORMATS if f in chosen)
