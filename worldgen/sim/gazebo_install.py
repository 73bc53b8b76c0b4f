"""Finding a Gazebo Sim install (Fortress's ``ign gazebo`` or Harmonic's ``gz sim``), which release it is, and
the environment its setup script builds.

:func:`locate` is the one place the policy for a missing simulator lives: ``WORLDGEN_GAZEBO_SETUP``, else the
default place of the release asked for (:data:`DEFAULT_SETUPS`; Fortress when none is named); the script's
``export`` lines are read into an environment (no shell runs it), and the server's ``--versions`` under that
environment must name a version, whose major number says the release (worldgen.export.contract's row).
Anything short of that is a :class:`GazeboMissingError` that says how to install one. Starting a server on
the install is :mod:`worldgen.sim.gazebo`'s part.
"""

from __future__ import annotations

import os
import re
from dataclasses import dataclass, field
from pathlib import Path
from typing import Optional

from worldgen.errors import ParameterError, SimulatorMissingError
from worldgen.export.contract import GZ_RELEASES, SIM_GZ_RELEASE, SIM_GZ_RELEASES, GzRelease, release_of_version
from worldgen.sim.procs import run_tool

__all__ = ["GazeboMissingError", "GazeboInstall", "locate", "user_cache", "SETUP_ENV", "DEFAULT_SETUP",
           "DEFAULT_SETUPS", "INSTALL_HINT"]

#: The environment variable naming an install's setup script, and the scripts used without it: where
#: shared/gazebo's install.sh puts each release's server.
SETUP_ENV = "WORLDGEN_GAZEBO_SETUP"
DEFAULT_SETUPS: dict[str, Path] = dict(zip(SIM_GZ_RELEASES, (Path("/opt/gz-fortress2/setup.sh"),
                                                             Path("/opt/gz-harmonic/setup.sh"))))
DEFAULT_SETUP = DEFAULT_SETUPS[SIM_GZ_RELEASE]
INSTALL_HINT = ("install Gazebo Fortress or Harmonic (on Debian 12: apt-get install libsdformat-dev "
                "libignition-fuel-tools-dev libignition-msgs-dev libignition-plugin-dev libignition-transport-dev, then "
                "bash shared/gazebo/install.sh, which puts both under /opt; see docs/gazebo.md) or point "
                "WORLDGEN_GAZEBO_SETUP at its setup.sh")


class GazeboMissingError(SimulatorMissingError):
    """No usable Gazebo install: the message names where it looked and how to install one."""


@dataclass(frozen=True)
class GazeboInstall:
    """One Gazebo install: its setup script, the environment that script builds, its server's version, and the
    release that version is (the contract's row: its tools, message package and variables)."""

    setup: Path
    env: dict[str, str] = field(repr=False)
    version: str
    release: GzRelease = field(default_factory=lambda: GZ_RELEASES[SIM_GZ_RELEASE], repr=False)


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


def _base_env() -> dict[str, str]:
    """The caller's environment without any release's tool config, plugin paths, partition or discovery ports
    (a shell that sourced another release's setup holds them): ``gz`` reads ``IGN_CONFIG_PATH`` too and stops
    at a Fortress yaml it finds there (measured: "contains a command already registered"). Resource paths
    (models a user keeps) stay."""
    owned = {v for r in GZ_RELEASES.values() for v in (r.plugin_path_var, r.partition_var, *r.discovery_vars)}
    return {k: v for k, v in os.environ.items()
            if k not in owned and not k.endswith(("_CONFIG_PATH", "_PHYSICS_ENGINE_PATH", "_RENDERING_PLUGIN_PATH"))}


def _version(setup: Path, env: dict[str, str]) -> tuple[str, str]:
    """(version, the command that said it). Asked first of the server command of the releases whose plugin
    path the script sets (newest first): a user's PATH may hold another release's tool too."""
    text = setup.read_text()
    rows = sorted(reversed(GZ_RELEASES.values()), key=lambda r: r.plugin_path_var not in text)
    said = []
    for server in dict.fromkeys(r.server for r in rows):
        try:
            out = run_tool([*server, "--versions"], env, timeout=30)
        except FileNotFoundError:
            continue
        versions = [v for v in out.split() if re.fullmatch(r"\d+\.\d+\.\d+", v)]
        if versions:
            return versions[-1], " ".join(server)
        said.append(f"'{' '.join(server)} --versions': {out.strip()[:120]!r}")
    raise GazeboMissingError(f"{setup} names no Gazebo ({'; '.join(said) or 'no server command on its PATH'}); "
                             f"{INSTALL_HINT}")


def locate(setup: str | Path | None = None, release: Optional[str] = None) -> GazeboInstall:
    """The Gazebo install to use; the one place the tool-missing policy lives (raises :class:`GazeboMissingError`).

    ``setup`` (else ``WORLDGEN_GAZEBO_SETUP``) names its setup script; ``release`` asks for a release: its
    default place when no script is named, and a :class:`GazeboMissingError` when the named one is another."""
    if release is not None and release not in DEFAULT_SETUPS:
        raise ParameterError(f"option '--gz-release' must be one of {', '.join(DEFAULT_SETUPS)}, got {release!r}")
    named = setup or os.environ.get(SETUP_ENV)
    path = Path(named or DEFAULT_SETUPS[release or SIM_GZ_RELEASE])
    if not path.is_file():
        raise GazeboMissingError(f"Gazebo not found: no setup script at {path}; {INSTALL_HINT}")
    env = _exports(path, _base_env())
    version, _ = _version(path, env)
    try:
        row = release_of_version(version)
    except ParameterError as exc:
        raise GazeboMissingError(f"{path}: {exc}") from None
    if release is not None and row.name != release:
        if named and not setup:  # WORLDGEN_GAZEBO_SETUP names another release's install: the default place then
            return locate(DEFAULT_SETUPS[release], release)
        raise GazeboMissingError(f"{path} sets up Gazebo {version} ({row.name}), not {release}; {INSTALL_HINT}")
    return GazeboInstall(path, env, version, row)


def user_cache() -> Path:
    """The user's cache folder: ``$XDG_CACHE_HOME``, else ``~/.cache``."""
    return Path(os.environ.get("XDG_CACHE_HOME") or Path.home() / ".cache")
