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
