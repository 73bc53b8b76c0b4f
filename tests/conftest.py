"""Shared test helpers.

Reference tools (libsdformat, check_urdf) may be missing on a developer's
laptop: tests that need them skip there, but fail when ``CI`` is set, because
CI installs them and a silent skip would hide a broken install.
"""

from __future__ import annotations

import os

import numpy as np
import pytest
from hypothesis import settings

ON_CI = bool(os.environ.get("CI"))

# On CI, Hypothesis replays the same examples every run (a red CI must mean a change broke
# something, not that a new random draw turned up an old bug) and never times out an
# example on a loaded machine; on a laptop it keeps exploring fresh examples.
settings.register_profile("ci", derandomize=True, deadline=None, print_blob=True)
if ON_CI:
    settings.load_profile("ci")


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


@pytest.fixture
def rng():
    return np.random.default_rng(12345)
