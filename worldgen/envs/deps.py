"""The one optional dependency of worldgen.envs: Gymnasium, imported only when an environment is used.

``import worldgen`` (and the pytest plugin) never imports Gymnasium; this module
is where worldgen.envs asks for it, and where a missing install becomes one line.
"""

from __future__ import annotations

from worldgen.errors import MissingDependencyError, optional_available, require_optional

__all__ = ["MissingDependencyError", "INSTALL_HINT", "gymnasium_available", "require_gymnasium"]

#: What to install for the environments (the ``rl`` extra of worldgen's pyproject.toml).
INSTALL_HINT = "pip install 'worldgen[rl]'"


def gymnasium_available() -> bool:
    """True when Gymnasium can be imported (it is not imported by asking)."""
    return optional_available("gymnasium")


def require_gymnasium():
    """The ``gymnasium`` module, or :class:`MissingDependencyError` naming the ``rl`` extra."""
    return require_optional("gymnasium", "rl", "worldgen.envs needs Gymnasium")
