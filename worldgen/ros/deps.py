"""The optional dependency of reading and writing bags: rosbags, imported only when a bag is touched.

``import worldgen`` and ``worldgen judge --help`` never import rosbags; the bag reader and writer ask
for it here, through the package's one mechanism for optional extras (:func:`worldgen.errors.require_optional`).
"""

from __future__ import annotations

from worldgen.errors import require_optional

__all__ = ["require_rosbags"]


def require_rosbags():
    """The ``rosbags`` package (with its high-level reader), or MissingDependencyError naming the ``ros`` extra."""
    needs = "reading or writing ROS bags needs rosbags"
    require_optional("rosbags.highlevel", "ros", needs)
    return require_optional("rosbags", "ros", needs)
