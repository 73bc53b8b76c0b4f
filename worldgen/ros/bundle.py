"""Deprecated: the ROS 2 bundle is an exporter now, :mod:`worldgen.export.ros2`; the Gazebo releases and the
topics it reads are :mod:`worldgen.export.contract`'s tables. Importing this module warns and gives the
same functions; its tables keep their old shapes, built from the contract."""

from __future__ import annotations

import warnings

from worldgen.export.contract import BRIDGED, DEFAULT_GZ_RELEASE, RECORDED
from worldgen.export.contract import GZ_RELEASES as _RELEASES
from worldgen.export.ros2 import (
    BUNDLE_DIR,
    DEFAULT_ROBOT_NAME,
    ROBOT_SDF,
    ROBOT_URDF,
    bridge_config,
    bundle,
    dumps,
    nav2_map,
    nav2_overrides,
    plugins,
    release_of,
    ros_name,
    tasks_spec,
    with_plugins,
)

__all__ = ["BUNDLE_DIR", "ROBOT_SDF", "ROBOT_URDF", "GZ_RELEASES", "GZ_SERVERS", "DEFAULT_GZ_RELEASE",
           "DEFAULT_ROBOT_NAME", "TOPICS", "RECORDED_TOPICS", "ros_name", "release_of", "plugins", "with_plugins",
           "bridge_config", "nav2_map", "nav2_overrides", "tasks_spec", "bundle", "dumps"]

warnings.warn("worldgen.ros.bundle is deprecated: import the bundle from worldgen.export.ros2 and the Gazebo "
              "releases and topics from worldgen.export.contract", DeprecationWarning, stacklevel=2)

#: Release -> (plugin file, plugin class, message package), as this module gave it.
GZ_RELEASES = {n: (r.plugin_file, r.plugin_class, r.msgs) for n, r in _RELEASES.items()}
#: Release -> (server command, takes --seed, plugin path variable), as this module gave it.
GZ_SERVERS = {n: (r.server, r.seed, r.plugin_path_var) for n, r in _RELEASES.items()}
#: ROS topic -> (ROS type, Gazebo type, Gazebo topic, direction) of every bridged topic.
TOPICS = {t.name: (t.ros_type, t.gz_type, t.gz_topic, t.direction) for t in BRIDGED}
RECORDED_TOPICS = tuple(t.name for t in RECORDED)
