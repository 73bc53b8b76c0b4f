"""Gymnasium environments over worldgen's worlds (optional extra: ``pip install 'worldgen[rl]'``).

    >>> import gymnasium
    >>> env = gymnasium.make("worldgen.envs:worldgen/Navigation-v0", preset="drl_arena")
    >>> obs, info = env.reset(seed=0)      # a fresh, checked world
    >>> env.observation_space.contains(obs), info["reference_path_length"] > 0
    (True, True)

``worldgen/Navigation-v0`` (:class:`NavigationEnv`): a differential-drive robot
with a planar lidar in MuJoCo, a new world per episode from any generator or
preset, or a pack's worlds in order; scored with SPL against the exact optimal
path. Modules, one concern each: :mod:`~worldgen.envs.config` (settings),
:mod:`~worldgen.envs.source` (worlds), :mod:`~worldgen.envs.robot` (the robot in
the MJCF), :mod:`~worldgen.envs.lidar`, :mod:`~worldgen.envs.movers`,
:mod:`~worldgen.envs.reward`, :mod:`~worldgen.envs.episode` (the run and its
figures), :mod:`~worldgen.envs.curriculum` and :mod:`~worldgen.envs.replay` (curricula),
:mod:`~worldgen.envs.policies` and :mod:`~worldgen.envs.probes` (scripted baselines and the
difficulty probes), :mod:`~worldgen.envs.render`, :mod:`~worldgen.envs.navigation` (the
environment), :mod:`~worldgen.envs.registration`.

Importing this package registers the environment with Gymnasium when Gymnasium
is installed, and does nothing otherwise: using the environment then fails with
one line saying what to install. ``import worldgen`` never imports this package.
"""

from __future__ import annotations

from worldgen.envs.deps import INSTALL_HINT, MissingDependencyError, gymnasium_available
from worldgen.envs.registration import ENV_ID, register_envs

__all__ = ["ENV_ID", "NavigationEnv", "register_envs", "MissingDependencyError", "INSTALL_HINT"]

if gymnasium_available():
    register_envs()


def __getattr__(name):
    if name == "NavigationEnv":  # imports Gymnasium and MuJoCo: only when asked for
        from worldgen.envs.navigation import NavigationEnv
        return NavigationEnv
    raise AttributeError(f"module 'worldgen.envs' has no attribute {name!r}")
