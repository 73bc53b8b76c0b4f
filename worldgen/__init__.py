"""worldgen: seeded, checked test worlds for robot simulation.

    >>> import worldgen
    >>> world = worldgen.generate("cluttered", seed=7, size=[20, 20], n_obstacles=50)
    >>> world.metadata["tasks"][0]["path"]["length"]        # ground truth for assertions
    12.575701
    >>> folder = world.write("worlds")                      # worlds/<world_id>/world.sdf, ...
    >>> sorted(p.name for p in folder.iterdir())[:3]
    ['map.pgm', 'map.yaml', 'preview.png']
"""

from importlib.metadata import PackageNotFoundError
from importlib.metadata import version as _version

try:
    __version__ = _version("worldgen")
except PackageNotFoundError:  # running from a source tree that is not installed
    __version__ = "0.0.0+unknown"

from worldgen.errors import InfeasibleError, OutputError, ParameterError, UnknownGeneratorError, WorldgenError

# The rest is imported on first use (PEP 562): the pytest plugin (worldgen.testing.plugin) is
# loaded by every pytest run in an environment with worldgen installed, and importing the
# package must not drag numpy, FCL and scipy into runs that never ask for a world. Nothing
# but the errors is imported here, so any module may import this package without a cycle.
_LAZY = {
    "generate": "worldgen.api", "generate_preset": "worldgen.presets", "GeneratorSpec": "worldgen.generators",
    "register": "worldgen.generators", "FORMATS": "worldgen.world", "World": "worldgen.world",
    "Pack": "worldgen.pack", "shrink": "worldgen.testing.shrink",
}
#: Public modules that live deeper in the package: ``from worldgen import oracles``.
_MODULES = {"oracles": "worldgen.testing.oracles"}


def __getattr__(name):
    if name in _LAZY:
        import importlib
        value = getattr(importlib.import_module(_LAZY[name]), name)
        globals()[name] = value
        return value
    if name in _MODULES:
        import importlib
        value = globals()[name] = importlib.import_module(_MODULES[name])
        return value
    if not name.startswith("_"):  # ``worldgen.generators.get(...)`` after a bare ``import worldgen``
        import importlib
        try:
            return importlib.import_module(f"{__name__}.{name}")
        except ModuleNotFoundError as exc:
            if exc.name != f"{__name__}.{name}":
                raise
    raise AttributeError(f"module 'worldgen' has no attribute {name!r}")

__all__ = [
    "__version__", "generate", "generate_preset", "World", "FORMATS", "GeneratorSpec", "register",
    "WorldgenError", "ParameterError", "UnknownGeneratorError", "InfeasibleError", "OutputError",
    "Pack", "shrink", "oracles",
]
