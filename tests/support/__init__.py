"""What the tests share: the one place a test file imports helpers from (never another test file).

- ``missing_tool``: reference tools (libsdformat, check_urdf) may be missing on a developer's laptop:
  tests that need them skip there, but fail when ``CI`` is set, because CI installs them and a silent
  skip would hide a broken install.
- ``draft``: one unchecked draw of a generator.
- the modules beside this one: ``reftools_*`` (the reference consumers of each format), ``scenes``
  (hand-built scenes that use every feature), ``exact_reference`` (an independent exact planner),
  ``cli`` (running the command), ``checks`` (geometric re-checks of a world), ``fuzzing``; for campaigns,
  ``planted`` (a policy with a planted weakness), ``bag_command`` and ``stand_in_ros2`` (stand-in robot stacks
  that leave bags); for the ROS 2 bundle, ``bundle`` (its world, loading its scripts) and
  ``launch_standins`` (ROS's launch API, launch's handling of a description and of a process's exit,
  `ros2 launch` processes).
"""

from __future__ import annotations

import os

import pytest

__all__ = ["ON_CI", "missing_tool", "draft"]

ON_CI = bool(os.environ.get("CI"))


def missing_tool(what: str):
    """Skip (laptop) or fail (CI) a test that needs a reference tool that is absent."""
    if ON_CI:
        pytest.fail(f"{what} is required on CI but missing (is .ci/run installing it?)", pytrace=False)
    pytest.skip(f"{what} is not installed here")


def draft(generator: str = "cluttered", seed: int = 0, **params):
    """One unchecked draw of a generator: (scene, tasks). Fast; no feasibility."""
    from worldgen.generators import get
    from worldgen.seeding import attempt_rng

    spec = get(generator)
    resolved = spec.resolve(params)
    for attempt in range(resolved["max_attempts"]):
        d = spec.build(resolved, attempt_rng(seed, attempt))
        if d.rejected is None:
            return d.scene, d.tasks
    raise AssertionError(f"no draft for {generator} seed {seed} {params}")
