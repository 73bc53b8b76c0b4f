"""ROS 2 runs in and out, without a ROS install (optional extra ``ros``: ``pip install 'worldgen[ros]'``).

    >>> from worldgen.ros import read_run, write_run
    >>> run = read_run("runs/r0.mcap", "worlds/cluttered-s0-1f3a9c0b")   # a BagRun
    >>> oracles.run(run.trajectory, world)                              # the oracles take its trajectory
    >>> write_run("runs/r1", trajectory, spawn=(x, y, yaw), storage="sqlite3", distro="humble")

The public face of :mod:`worldgen.testing.bags` (the reader) and
:mod:`worldgen.testing.bagwrite` (the writer); both import rosbags only when called,
and say in one line what to install when it is missing. ``worldgen judge`` turns
many bags into a report (docs/judge.md).
"""

from __future__ import annotations

from worldgen.testing.bags import START_RULES, BagRun, read_run
from worldgen.testing.bagwrite import DISTROS, STORAGES, write_run
from worldgen.testing.judge import JudgeResult, judge
from worldgen.testing.report import write_report

__all__ = ["read_run", "write_run", "BagRun", "START_RULES", "STORAGES", "DISTROS", "judge", "JudgeResult",
           "write_report"]
