"""worldgen: seeded, checked test worlds for robot simulation.

    >>> import worldgen
    >>> world = worldgen.generate("cluttered", seed=7, size=[20, 20], n_obstacles=50)
    >>> world.metadata["tasks"][0]["path"]["length"]        # ground truth for assertions
    >>> folder = world.write("worlds")                      # worlds/<world_id>/world.sdf, ...
"""

from importlib.metadata import PackageNotFoundError, version as _version

try:
    __version__ = _version("worldgen")
except PackageNotFoundError:  # running from a source tree that is not installed
    __version__ = "0.0.0+unknown"

from worldgen.api import generate
from worldgen.presets import generate_preset
from worldgen.errors import InfeasibleError, OutputError, ParameterError, UnknownGeneratorError, WorldgenError
from worldgen.generators import GeneratorSpec, register
from worldgen.world import FORMATS, World
from worldgen.pack import Pack

__all__ = [
    "__version__", "generate", "generate_preset", "World", "FORMATS", "GeneratorSpec", "register",
    "WorldgenError", "ParameterError", "UnknownGeneratorError", "InfeasibleError", "OutputError",
    "Pack",
]
