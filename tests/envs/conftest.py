"""Every test of the environment needs Gymnasium: skipped without it on a laptop, failed on CI."""

from __future__ import annotations

import pytest
from support import missing_tool
from support.envs import gymnasium


@pytest.fixture(autouse=True)
def _gymnasium():
    if gymnasium is None:
        missing_tool("gymnasium (pip install 'worldgen[rl]')")
    import worldgen.envs  # noqa: F401  (registers the id)
