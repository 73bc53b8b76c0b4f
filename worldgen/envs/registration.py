"""Registering ``worldgen/Navigation-v0`` with Gymnasium.

Gymnasium 1.x (the ``rl`` extra) has no plugin system: its 1.0 release removed the loading of the
``gymnasium.envs`` entry-point group. An id is known once the module that registers it is imported,
which ``gymnasium.make`` does itself for an id written ``"module:id"``::

    gymnasium.make("worldgen.envs:worldgen/Navigation-v0", preset="drl_arena")

or, after ``import worldgen.envs`` (registration happens on import),
``gymnasium.make("worldgen/Navigation-v0", ...)``. The registration names the environment class by
its import path, so registering imports neither MuJoCo nor the environment's modules.
"""

from __future__ import annotations

__all__ = ["ENV_ID", "ENTRY_POINT", "register_envs"]

#: The environment's Gymnasium id.
ENV_ID = "worldgen/Navigation-v0"
#: Where Gymnasium finds the class when it makes the environment.
ENTRY_POINT = "worldgen.envs.navigation:NavigationEnv"


def register_envs() -> None:
    """Register :data:`ENV_ID` with Gymnasium (again: a no-op); needs Gymnasium installed."""
    from worldgen.envs.deps import require_gymnasium

    gym = require_gymnasium()
    if ENV_ID in gym.envs.registry:
        return
    # No max_episode_steps: the environment truncates at each task's own time_limit.
    gym.register(id=ENV_ID, entry_point=ENTRY_POINT)
