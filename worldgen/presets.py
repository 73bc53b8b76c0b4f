"""Presets: named, documented parameter sets for the standard scenarios of simulation testing.

A preset is one YAML file (``templates/presets/<name>.yaml``) with exactly
these keys::

    name: narrow_corridor          # the file's stem
    description: one line, shown by `worldgen presets`
    reproduces: which standard test scenario it stands for, and what to assert
    generator: corridor            # a registered generator
    params: {width: 0.8}           # that generator's parameters (checked on load)

It is read with PyYAML's ``safe_load`` only (plain data, no object tags), and
every mistake in it is one line naming the file and the key. The one API:
:func:`generate_preset` (``worldgen generate --preset NAME`` on the command
line); overrides win over the preset's params, so a preset is a starting point,
not a cage. A path to a ``.yaml`` file works wherever a name does.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from importlib import resources
from pathlib import Path
from typing import Any, Mapping, Optional

from worldgen.errors import ParameterError, WorldgenError, did_you_mean, quoted, read_user_text

__all__ = ["Preset", "PRESET_KEYS", "names", "all_presets", "load", "generate_preset"]

#: Every key of a preset file; all are required, no other is allowed.
PRESET_KEYS = ("name", "description", "reproduces", "generator", "params")
_FOLDER = "presets"


@dataclass(frozen=True)
class Preset:
    """One preset as read from ``source`` (a file path, for messages)."""

    name: str
    description: str
    reproduces: str
    generator: str
    params: Mapping[str, Any] = field(default_factory=dict)
    source: str = ""

    def merged(self, overrides: Optional[Mapping[str, Any]] = None) -> dict[str, Any]:
        """The preset's params with ``overrides`` on top (a new dict)."""
        out = dict(self.params)
        out.update(overrides or {})
        return out


def _shipped():
    return resources.files("worldgen.templates").joinpath(_FOLDER)


def names() -> list[str]:
    """Names of the shipped presets, sorted."""
    folder = _shipped()
    return sorted(p.name[: -len(".yaml")] for p in folder.iterdir() if p.name.endswith(".yaml"))


def all_presets() -> list[Preset]:
    """Every shipped preset, by name."""
    return [load(n) for n in names()]


def load(name_or_path: str) -> Preset:
    """A shipped preset by name, or a preset file by path (ending in .yaml or .yml); checked."""
    text_name = str(name_or_path)
    if text_name.endswith((".yaml", ".yml")):
        path = Path(text_name)
        return _parse(read_user_text(path, "preset file"), str(path), path.stem)
    available = names()
    if text_name not in available:
        raise ParameterError(f"unknown preset '{text_name}'{did_you_mean(text_name, available)}; "
                             f"available: {', '.join(available)}")
    entry = _shipped().joinpath(f"{text_name}.yaml")
    return _parse(entry.read_text(encoding="utf-8"), f"templates/{_FOLDER}/{text_name}.yaml", text_name)


def _parse(text: str, source: str, stem: str) -> Preset:
    import yaml  # read only here: importing worldgen stays light

    try:
        doc = yaml.safe_load(text)
    except yaml.YAMLError as exc:
        mark = getattr(exc, "problem_mark", None)
        where = f" at line {mark.line + 1}" if mark is not None else ""
        raise ParameterError(f"preset file '{source}' is not valid YAML{where}: {getattr(exc, 'problem', exc)}") from None
    if not isinstance(doc, dict):
        raise ParameterError(f"preset file '{source}' must hold a mapping with keys {', '.join(PRESET_KEYS)}")
    unknown = sorted(str(k) for k in doc if k not in PRESET_KEYS)
    if unknown:
        raise ParameterError(f"preset file '{source}': unknown key '{unknown[0]}'; allowed: {', '.join(PRESET_KEYS)}")
    for key in PRESET_KEYS:
        if key not in doc:
            raise ParameterError(f"preset file '{source}': key '{key}' is missing")
    for key in ("name", "description", "reproduces", "generator"):
        if not isinstance(doc[key], str) or not doc[key].strip():
            raise ParameterError(f"preset file '{source}': key '{key}' must be a non-empty string, got {quoted(doc[key])}")
    if doc["name"] != stem:
        raise ParameterError(f"preset file '{source}': key 'name' must equal the file's name '{stem}', got {quoted(doc['name'])}")
    params = doc["params"]
    if params is None:
        params = {}
    if not isinstance(params, dict) or not all(isinstance(k, str) for k in params):
        raise ParameterError(f"preset file '{source}': key 'params' must be a mapping of parameter names to values, "
                             f"got {quoted(params)}")
    preset = Preset(doc["name"], " ".join(doc["description"].split()), " ".join(doc["reproduces"].split()),
                    doc["generator"], dict(params), source)
    from worldgen.generators import get

    try:
        get(preset.generator).resolve(preset.params)
    except WorldgenError as exc:
        raise type(exc)(f"preset file '{source}': key 'params' (generator '{preset.generator}'): {exc}") from None
    return preset


def generate_preset(name: str, seed: int = 0, *, allow_infeasible: bool = False, **overrides: Any):
    """Generate the world of preset ``name`` (or a preset file path), ``overrides`` on top of its params.

    The returned World records the underlying generator and every resolved
    parameter, so ``worldgen.generate(world.generator, seed, **world.params)``
    rebuilds it without the preset; ``world.preset`` (world.json ``preset``, and
    the folder name ``<preset>--<world_id>``) says where it came from.
    """
    from worldgen.api import generate

    preset = load(name)
    world = generate(preset.generator, seed, allow_infeasible=allow_infeasible, **preset.merged(overrides))
    return world.set_provenance(preset=preset.name)
