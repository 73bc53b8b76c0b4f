"""One scan of the robot's gpu_lidar in Gazebo at a task's spawn, to hold against world.json's ground truth::

    from worldgen.sim.scan import gazebo_scan
    ranges = gazebo_scan("worlds/cluttered-s0-55fec0f6")     # world.json's rays, m (needs Gazebo)

The world runs with the Sensors system (ogre2, EGL: ``--headless-rendering``), the robot
(:mod:`worldgen.export.robot`) is spawned at the first task's spawn, the world steps until the lidar
has published, and the first ``/scan`` is returned, a ray that hit nothing at ``range_max`` as world.json
writes it (Gazebo publishes +inf there). :func:`edge_rays` names the rays that graze an
obstacle's edge: where the true range jumps between neighbouring rays, a renderer's depth
resolution and its sub-pixel sampling put the ray on either side of the jump.
"""

from __future__ import annotations

import tempfile
from pathlib import Path

import numpy as np

from worldgen.groundtruth.folder import open_world
from worldgen.sim.gazebo import GazeboError, GazeboServer, locate

__all__ = ["gazebo_scan", "read_scan", "edge_rays", "EDGE_JUMP"]

#: A ray is an edge ray where the true range differs from a neighbour's by more than this (m).
EDGE_JUMP = 0.1


def _world_with_sensors(folder: Path, sdf: Path, gz_release: str) -> str:
    from worldgen.export.ros2 import with_plugins

    text = sdf.read_text(encoding="utf-8")
    return with_plugins(text, gz_release, str(folder.resolve()) + "/").decode()


def gazebo_scan(world, *, lidar_noise: float = 0.0, timeout: float = 60.0, gz_release: str | None = None) -> np.ndarray:
    """The ranges (m) of the first scan the robot's gpu_lidar publishes at the first task's spawn in ``world``."""
    return read_scan(world, lidar_noise=lidar_noise, timeout=timeout, gz_release=gz_release)[0]


def read_scan(world, *, lidar_noise: float = 0.0, timeout: float = 60.0,
              gz_release: str | None = None) -> tuple[np.ndarray, str]:
    """(ranges, m; the message's header ``frame_id``) of the first scan the robot's gpu_lidar publishes at the
    first task's spawn in ``world`` (a world folder, a written World or a pack folder's world: Gazebo loads
    its world.sdf from disk). The frame is what a ROS 2 bridge passes on. ``gz_release`` picks the Gazebo
    release (:func:`~worldgen.sim.gazebo_install.locate`); the world's systems and the robot are written for it."""
    from worldgen.export.contract import SCAN
    from worldgen.export.robot import robot_sdf
    from worldgen.sim.textproto import first

    opened = open_world(world)
    meta = opened.metadata
    spawn = opened.task()["spawn"]
    source = opened.file("sdf")
    install = locate(release=gz_release)
    rel = install.release.name
    with tempfile.TemporaryDirectory(prefix="worldgen-scan-") as tmp:
        sdf = Path(tmp) / source.name  # the world folder is left untouched; its meshes are named absolutely
        sdf.write_text(_world_with_sensors(opened.file("json").parent, source, rel), encoding="utf-8")
        with GazeboServer(sdf, install=install, headless_rendering=True) as gz:
            gz.spawn(robot_sdf(meta, gz_release=rel, lidar_noise=lidar_noise), name="robot",
                     pose=(spawn[0], spawn[1], spawn[2], spawn[5]))
            got = gz.echo(SCAN.gazebo_topic, 1, timeout, step=50)  # the world is paused: stepped until the scan came
    if not got:
        raise GazeboError(f"no {SCAN.gazebo_topic} within {timeout:.0f} s")
    ranges = np.array([float(r) for r in got[0].get("ranges", [])])
    if len(ranges) != int(first(got[0], "count", len(ranges))):
        raise GazeboError(f"{SCAN.gazebo_topic} held {len(ranges)} ranges for a count of {first(got[0], 'count')}")
    frame = next((first(d, "value") for h in got[0].get("header", []) for d in h.get("data", [])
                  if first(d, "key") == "frame_id"), "")
    # Gazebo reports +inf for a ray that hits nothing (REP 117); world.json writes range_max there.
    return np.where(np.isposinf(ranges), float(meta["sensors"]["lidar"]["range_max"]), ranges), str(frame)


def edge_rays(truth) -> np.ndarray:
    """Indices of the rays whose true range jumps by more than :data:`EDGE_JUMP` to a neighbour."""
    jump = np.abs(np.diff(np.asarray(truth, dtype=float))) > EDGE_JUMP
    return np.flatnonzero(np.r_[jump, False] | np.r_[False, jump])
