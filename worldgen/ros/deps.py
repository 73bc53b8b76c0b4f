"""The optional dependency of reading and writing bags: rosbags, imported only when a bag is touched.

``import worldgen`` and ``worldgen judge --help`` never import rosbags; this module is where the bag
reader and writer ask for it, and where a missing install becomes one line.
"""

from __future__ import annotations

import importlib

from worldgen.errors import WorldgenError

__all__ = ["MissingRosbagsError", "INSTALL_HINT", "require_rosbags"]

#: What to install for bags (the ``ros`` extra of worldgen's pyproject.toml).
INSTALL_HINT = "pip install 'worldgen[ros]'"


class MissingRosbagsError(WorldgenError, ImportError):
    """rosbags is not installed; the message says what to install."""


def require_rosbags():
    """The ``rosbags`` package, or :class:`MissingRosbagsError` with one line saying what to install."""
    try:
        module = importlib.import_module("rosbags")
        importlib.import_module("rosbags.highlevel")
        return module
    except ImportError:
        raise MissingRosbagsError(f"reading or writing ROS bags needs rosbags, which is not installed: {INSTALL_HINT}") from None
