"""What the environment's tests share: Gymnasium if installed (the ``rl`` extra), its id, and ``make``.

``tests/envs/conftest.py`` skips every test there without Gymnasium on a laptop, and fails them on CI.
"""

from __future__ import annotations

try:
    import gymnasium
except ImportError:  # pragma: no cover - exercised on machines without the extra
    gymnasium = None

__all__ = ["ENV_ID", "gymnasium", "make"]

ENV_ID = "worldgen/Navigation-v0"


def make(**kwargs):
    """The unwrapped environment made by id, as a user makes it."""
    return gymnasium.make(ENV_ID, **kwargs).unwrapped
