"""Session-wide settings; every shared helper lives in ``tests/support`` (``from support import ...``)."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import settings
from support import ON_CI

# On CI, Hypothesis replays the same examples every run (a red CI must mean a change broke
# something, not that a new random draw turned up an old bug) and never times out an
# example on a loaded machine; on a laptop it keeps exploring fresh examples.
settings.register_profile("ci", derandomize=True, deadline=None, print_blob=True)
if ON_CI:
    settings.load_profile("ci")


@pytest.fixture
def rng():
    return np.random.default_rng(12345)


# The Gazebo installs the gazebo group runs in (tests/sim, the bundle's Gazebo test): each located once a
# session; a missing one skips on a laptop and fails on CI (support.gazebo).
@pytest.fixture(scope="session")
def install():
    """The default Gazebo install."""
    from support.gazebo import gazebo_install

    return gazebo_install()


@pytest.fixture(scope="session")
def installs():
    """``installs(release)``: the install of that release."""
    from support.gazebo import install_cache

    return install_cache()
