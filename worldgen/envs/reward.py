"""The reward: the deep-RL navigation walkthrough's shape by default, weights settable, or any callable.

Default, for one env step that applied ``(v, w)``:

- ``reward_collision`` (-100) when the robot touched anything but the floor;
- else ``reward_goal`` (+100) when it ended within the task's ``goal_tolerance``;
- else ``reward_speed * v - reward_turn * |w| - reward_obstacle * (obstacle_distance - r)``,
  the last term only while the closest noise-free lidar range ``r`` is below
  ``obstacle_distance``. With the defaults (0.5, 0.5, 0.5, 1 m) that is the
  walkthrough's ``v/2 - |w|/2 - (1 - r)/2`` for ``r < 1``: forward progress pays,
  turning and hugging obstacles cost.

``reward_fn``, when given, replaces all of this: it is called with the step's
:class:`StepOutcome` and returns a number.
"""

from __future__ import annotations

from dataclasses import dataclass

__all__ = ["StepOutcome", "default_reward", "reward"]


@dataclass(frozen=True)
class StepOutcome:
    """What happened in one env step, as a reward function sees it.

    ``v``, ``w``: the action applied (m/s, rad/s, after clipping to the action
    space); ``reached_goal``, ``collided``: this step ended at the goal / touched
    something; ``min_range``: closest noise-free lidar range (m);
    ``goal_distance`` / ``previous_goal_distance``: robot centre to goal after /
    before the step (m); ``goal_angle``: bearing of the goal from the heading
    (rad, counter-clockwise); ``time``: simulated seconds since the reset.
    """

    v: float
    w: float
    reached_goal: bool
    collided: bool
    min_range: float
    goal_distance: float
    previous_goal_distance: float
    goal_angle: float
    time: float


def default_reward(o: StepOutcome, cfg) -> float:
    """The walkthrough's reward with ``cfg``'s weights (an :class:`~worldgen.envs.config.EnvConfig`)."""
    if o.collided:
        return float(cfg.reward_collision)
    if o.reached_goal:
        return float(cfg.reward_goal)
    near = max(0.0, cfg.obstacle_distance - o.min_range)
    return float(cfg.reward_speed * o.v - cfg.reward_turn * abs(o.w) - cfg.reward_obstacle * near)


def reward(o: StepOutcome, cfg) -> float:
    """``cfg.reward_fn(o)`` where one is set, else :func:`default_reward`."""
    if cfg.reward_fn is not None:
        return float(cfg.reward_fn(o))
    return default_reward(o, cfg)
