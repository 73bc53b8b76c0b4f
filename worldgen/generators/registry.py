"""Finds generators by name: the built-in ones and those other packages register.

Another package adds a generator through the ``worldgen.generators`` entry-point
group; the entry point must resolve to a :class:`GeneratorSpec`.
"""

from __future__ import annotations

from importlib.metadata import entry_points

from worldgen.errors import UnknownGeneratorError, WorldgenError, did_you_mean
from worldgen.generators.base import GeneratorSpec

__all__ = ["ENTRY_POINT_GROUP", "register", "get", "names", "all_specs"]

ENTRY_POINT_GROUP = "worldgen.generators"

_REGISTRY: dict[str, GeneratorSpec] = {}
_plugins_loaded = False


def register(spec: GeneratorSpec) -> GeneratorSpec:
    """Add ``spec`` under its name; a second registration of a name is an error."""
    existing = _REGISTRY.get(spec.name)
    if existing is not None and existing is not spec:
        raise WorldgenError(f"a generator named '{spec.name}' is already registered")
    _REGISTRY[spec.name] = spec
    return spec


def _load_builtins() -> None:
    # Imported on first lookup, not with the package: each generator pulls in shapely and its
    # geometry. The modules only define their SPEC; registering them is this module's job.
    from worldgen.generators.barn import SPEC as BARN
    from worldgen.generators.cluttered import SPEC as CLUTTERED
    from worldgen.generators.corridor import SPEC as CORRIDOR
    from worldgen.generators.door import SPEC as DOOR
    from worldgen.generators.minimal import SPEC as MINIMAL
    from worldgen.generators.terrain import SPEC as TERRAIN

    for spec in (CLUTTERED, DOOR, MINIMAL, CORRIDOR, BARN, TERRAIN):
        register(spec)


def _load_plugins() -> None:
    global _plugins_loaded
    if _plugins_loaded:
        return
    _plugins_loaded = True
    for ep in sorted(entry_points(group=ENTRY_POINT_GROUP), key=lambda e: e.name):
        if ep.name in _REGISTRY:
            continue
        spec = ep.load()
        if not isinstance(spec, GeneratorSpec):
            raise WorldgenError(f"entry point '{ep.name}' in {ENTRY_POINT_GROUP} is not a GeneratorSpec")
        register(spec)


def all_specs() -> list[GeneratorSpec]:
    _load_builtins()
    _load_plugins()
    return [_REGISTRY[n] for n in sorted(_REGISTRY)]


def names() -> list[str]:
    return [s.name for s in all_specs()]


def get(name: str) -> GeneratorSpec:
    _load_builtins()
    if name not in _REGISTRY:
        _load_plugins()
    try:
        return _REGISTRY[name]
    except KeyError:
        raise UnknownGeneratorError(
            f"unknown generator '{name}'{did_you_mean(name, names())}; available: {', '.join(names())}"
        ) from None
