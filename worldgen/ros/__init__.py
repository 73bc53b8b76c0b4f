"""ROS 2 runs in and out, without a ROS install (optional extra ``ros``: ``pip install 'worldgen[ros]'``).

    >>> import numpy as np, worldgen
    >>> from worldgen.judge import judge, write_report
    >>> from worldgen.ros import read_run, write_run
    >>> world = worldgen.generate("cluttered", seed=7, size=[8, 8], n_obstacles=6)
    >>> folder = world.write("worlds", preview=False)
    >>> path = np.array(world.metadata["tasks"][0]["path"]["waypoints"])      # the reference path
    >>> t = np.arange(len(path)) * 2.0
    >>> yaw = np.r_[np.arctan2(*np.diff(path, axis=0).T[::-1]), 0.0]
    >>> bag = write_run("runs/r0", np.c_[t, path, yaw], spawn=(*path[0], yaw[0]), world_id=world.world_id,
    ...                 task="task_0", storage="sqlite3", distro="humble")     # a real rosbag2 bag
    >>> run = read_run(bag, folder)         # the true pose over simulation time, from the TF chain
    >>> run.source, len(run.trajectory) > 1
    ('tf', True)
    >>> result = judge([bag], world=folder)        # every run must meet its scenario without criteria
    >>> result.passed, result.report["summary"]["successes"]
    (True, 1)
    >>> write_report(result, "report").name
    'report'

The room of ROS 2 bags: bags in (:mod:`worldgen.ros.reader`, with :mod:`~worldgen.ros.bagio` and the fast
field decoder :mod:`~worldgen.ros.cdr`), bags out (:mod:`worldgen.ros.writer`: :class:`BagWriter`, and
:func:`write_run` over it) and the optional rosbags (:mod:`~worldgen.ros.deps`). The bundle a world
carries for a ROS 2 run is an exporter, :mod:`worldgen.export.ros2`, and the topics and Gazebo releases
both sides agree on are :mod:`worldgen.export.contract`'s. Reader and writer import rosbags only when
called, and say in one line what to install when it is missing. Judging runs against worlds is
:mod:`worldgen.judge`'s (docs/judge.md).
"""

from __future__ import annotations

from worldgen.ros.reader import START_RULES, BagRun, RunMismatchError, read_run
from worldgen.ros.writer import DISTROS, STORAGES, BagWriter, write_run

__all__ = ["read_run", "write_run", "BagWriter", "BagRun", "RunMismatchError", "START_RULES", "STORAGES", "DISTROS"]
