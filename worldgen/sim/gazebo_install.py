"""Finding a Gazebo Sim install (Fortress, ``ign gazebo``) and the environment its setup script builds.

:func:`locate` is the one place the policy for a missing simulator lives: ``WORLDGEN_GAZEBO_SETUP``, else
``/opt/gz-fortress2/setup.sh``; the script's ``export`` lines are read into an environment (no shell runs
it), and ``ign gazebo --versions`` under that environment must name a version. Anything short of that is
a :class:`GazeboMissingError` that says how to install one. Starting a server on the install is
:mod:`worldgen.sim.gazebo`'s part.
"""

from __future__ import annotations

import os
import re
from dataclasses import dataclass, field
from pathlib import Path

from worldgen.errors import SimulatorMissingError
from worldgen.sim.procs import run_tool

__all__ = ["GazeboMissingError", "GazeboInstall", "locate", "user_cache", "SETUP_ENV", "DEFAULT_SETUP", "INSTALL_HINT"]

#: The environment variable naming an install's setup script, and the script used without it.
SETUP_ENV = "WORLDGEN_GAZEBO_SETUP"
DEFAULT_SETUP = Path("/opt/gz-fortress2/setup.sh")
INSTALL_HINT = ("install Gazebo Fortress (on Debian 12: apt-get install libsdformat-dev libignition-fuel-tools-dev "
                "libignition-msgs-dev libignition-plugin-dev libignition-transport-dev, then bash shared/gazebo/install.sh; "
                "see docs/gazebo.md) or point WORLDGEN_GAZEBO_SETUP at its setup.sh")


class GazeboMissingError(SimulatorMissingError):
    """No usable Gazebo install: the message names where it looked and how to install one."""


@dataclass(frozen=True)
class GazeboInstall:
    """One Gazebo install: its setup script, the environment that script builds, its ``ign gazebo`` version."""

    setup: Path
    env: dict[str, str] = field(repr=False)
    version: str


def _exports(setup: Path, base: dict[str, str]) -> dict[str, str]:
    """The environment after ``export NAME=value`` lines of ``setup`` (``$VAR``/``${VAR:-}`` expanded)."""
    env = dict(base)

    def expand(value: str) -> str:
        value = value.strip().strip('"').strip("'")
        return re.sub(r"\$\{(\w+)(?::-[^}]*)?\}|\$(\w+)", lambda m: env.get(m.group(1) or m.group(2), ""), value)

    for line in setup.read_text().splitlines():
        m = re.match(r"\s*export\s+(\w+)=(.*)$", line)
        if m:
            env[m.group(1)] = expand(m.group(2)).rstrip(":")
    return env


def locate(setup: str | Path | None = None) -> GazeboInstall:
    """The Gazebo install to use; the one place the tool-missing policy lives (raises :class:`GazeboMissingError`)."""
    setup = Path(setup or os.environ.get(SETUP_ENV) or DEFAULT_SETUP)
    if not setup.is_file():
        raise GazeboMissingError(f"Gazebo not found: no setup script at {setup}; {INSTALL_HINT}")
    env = _exports(setup, {k: v for k, v in os.environ.items()})
    try:
        out = run_tool(["ign", "gazebo", "--versions"], env, timeout=30)
    except FileNotFoundError:
        raise GazeboMissingError(f"Gazebo's 'ign' command is not on the PATH {setup} sets; {INSTALL_HINT}") from None
    versions = [v for v in out.split() if re.fullmatch(r"\d+\.\d+\.\d+", v)]
    if not versions:
        raise GazeboMissingError(f"'ign gazebo --versions' with {setup} names no Gazebo ({out.strip()[:200]!r}); "
                                 f"{INSTALL_HINT}")
    return GazeboInstall(setup, env, versions[-1])


def user_cache() -> Path:
    """The user's cache folder: ``$XDG_CACHE_HOME``, else ``~/.cache``."""
    return Path(os.environ.get("XDG_CACHE_HOME") or Path.home() / ".cache")
