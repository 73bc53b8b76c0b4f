"""The exceptions worldgen raises.

One root, :class:`WorldgenError`, so a caller (and the CLI) can catch every
mistake worldgen reports on purpose; narrow subclasses say which kind it is.
Anything else that escapes is a bug in worldgen, not a user's mistake.
"""

from __future__ import annotations

__all__ = [
    "WorldgenError",
    "ParameterError",
    "UnknownGeneratorError",
    "InfeasibleError",
    "SceneError",
    "OutputError",
]


class WorldgenError(Exception):
    """Root of every error worldgen raises for a user's input or request."""


class ParameterError(WorldgenError, ValueError):
    """A parameter is unknown, of the wrong type, or outside its allowed range."""


class UnknownGeneratorError(WorldgenError, LookupError):
    """No generator is registered under the requested name."""


class SceneError(WorldgenError, ValueError):
    """The scene asked for cannot exist: a shape of no size, a name used twice, a pose that is not finite."""


class InfeasibleError(WorldgenError):
    """No drivable world was found within the attempt budget.

    ``failures`` maps each feasibility check's name to how many draws failed it.
    """

    def __init__(self, message: str, failures: dict[str, int] | None = None):
        super().__init__(message)
        self.failures = dict(failures or {})


class OutputError(WorldgenError, OSError):
    """The output folder cannot be written (missing permission, not a folder, ...)."""
