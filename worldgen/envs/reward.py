"""The step reward: potential-based shaping by the exact geodesic distance by default, two named alternatives,
or any callable.

``reward="geodesic"`` (the default), for one env step from state s to s':

    r = R_terminal + gamma * phi(s') - phi(s) - c,     phi(s) = -k * G(s)

- ``R_terminal``: ``reward_collision`` (-100) when the robot touched anything but the floor, else
  ``reward_goal`` (+100) when it ended within the task's ``goal_tolerance``, else 0;
- ``G(s)``: the geodesic distance from the robot's centre to the goal for the robot's footprint
  (the length of the shortest path the feasibility proof would find from there:
  :class:`~worldgen.envs.geodesic.GeodesicField`), so the potential points round obstacles, not into them;
- ``k`` = ``reward_progress`` (10 per m), ``gamma`` = ``reward_discount`` (1 by default: the shaping is
  then the decrease of the geodesic distance, ``k * (G(s) - G(s'))``), ``c`` = ``reward_time`` (0.05 a step).

``gamma * phi(s') - phi(s)`` is potential-based shaping (Ng, Harada & Russell, "Policy invariance
under reward transformations: theory and application to reward shaping", ICML 1999): over an
episode its discounted sum telescopes to ``gamma^T phi(s_T) - phi(s_0)``, a term that depends on
the start and end states alone, while it pays every step for progress along the shortest
feasible path. With ``gamma`` equal to the learner's discount the optimal policy of the
``R_terminal - c`` task is exactly unchanged, but standing still then earns ``(1 - gamma) * k * G - c``
a step, positive far from the goal: PPO (gamma 0.99) learned to stand still with it
(``benchmarks/bench_learning.py``: 0 % success after 100,000 steps). The default ``gamma = 1``
makes standing still cost ``c``; its sum over an episode is ``k * (G(s_0) - G(s_T))``. A terminal
step keeps ``phi(s')`` of where it ended (a collision near the goal costs less than one far from
it). Per step, driving toward the goal along the shortest path earns about ``k * v * dt``;
driving away earns less than standing still.

``reward="walkthrough"``: the deep-RL navigation walkthrough's reward, as it was the default before:
``reward_collision``, else ``reward_goal``, else ``reward_speed * v - reward_turn * |w| -
reward_obstacle * (obstacle_distance - r)``, the last term only while the closest noise-free lidar
range ``r`` is below ``obstacle_distance`` (with the defaults ``v/2 - |w|/2 - (1 - r)/2`` for r < 1).

``reward="euclidean_progress"``: ``R_terminal + k * (d - d') - c`` with ``d``, ``d'`` the straight-line
distances to the goal before and after the step (no shaping guarantee: it points into obstacles).

``reward_fn``, when given, replaces all of this: it is called with the step's
:class:`StepOutcome` and returns a number.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

__all__ = ["StepOutcome", "default_reward", "geodesic_reward", "euclidean_progress_reward", "potential", "reward",
           "shaping", "terminal_reward", "walkthrough_reward", "REWARDS"]


@dataclass(frozen=True)
class StepOutcome:
    """What happened in one env step, as a reward function sees it.

    ``v``, ``w``: the action applied (m/s, rad/s, after clipping to the action
    space); ``reached_goal``, ``collided``: this step ended at the goal / touched
    something; ``min_range``: closest noise-free lidar range (m);
    ``goal_distance`` / ``previous_goal_distance``: robot centre to goal after /
    before the step, straight line (m); ``goal_angle``: bearing of the goal from the heading
    (rad, counter-clockwise); ``time``: simulated seconds since the reset;
    ``geodesic_distance`` / ``previous_geodesic_distance``: the geodesic distance to the goal after /
    before the step (m; NaN when the environment builds no geodesic field, see ``reward``).
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
    geodesic_distance: float = math.nan
    previous_geodesic_distance: float = math.nan


def terminal_reward(o: StepOutcome, cfg) -> float:
    """``reward_collision`` on a collision, else ``reward_goal`` at the goal, else 0."""
    if o.collided:
        return float(cfg.reward_collision)
    if o.reached_goal:
        return float(cfg.reward_goal)
    return 0.0


def potential(geodesic_distance: float, cfg) -> float:
    """phi = -reward_progress x geodesic distance."""
    return -float(cfg.reward_progress) * geodesic_distance


def shaping(o: StepOutcome, cfg) -> float:
    """gamma * phi(s') - phi(s), from the step's geodesic distances."""
    return float(cfg.reward_discount) * potential(o.geodesic_distance, cfg) - potential(o.previous_geodesic_distance, cfg)


def geodesic_reward(o: StepOutcome, cfg) -> float:
    """The default: terminal reward + potential-based shaping by the geodesic distance - time penalty."""
    return terminal_reward(o, cfg) + shaping(o, cfg) - float(cfg.reward_time)


def euclidean_progress_reward(o: StepOutcome, cfg) -> float:
    """Terminal reward + reward_progress x decrease of the straight-line distance - time penalty."""
    return (terminal_reward(o, cfg) + float(cfg.reward_progress) * (o.previous_goal_distance - o.goal_distance)
            - float(cfg.reward_time))


def walkthrough_reward(o: StepOutcome, cfg) -> float:
    """The walkthrough's reward with ``cfg``'s weights (an :class:`~worldgen.envs.config.EnvConfig`)."""
    if o.collided:
        return float(cfg.reward_collision)
    if o.reached_goal:
        return float(cfg.reward_goal)
    near = max(0.0, cfg.obstacle_distance - o.min_range)
    return float(cfg.reward_speed * o.v - cfg.reward_turn * abs(o.w) - cfg.reward_obstacle * near)


#: The named rewards (the ``reward`` setting).
REWARDS = {"geodesic": geodesic_reward, "walkthrough": walkthrough_reward,
           "euclidean_progress": euclidean_progress_reward}


def default_reward(o: StepOutcome, cfg) -> float:
    """The reward ``cfg.reward`` names (``geodesic`` unless set)."""
    return REWARDS[cfg.reward](o, cfg)


def reward(o: StepOutcome, cfg) -> float:
    """``cfg.reward_fn(o)`` where one is set, else the named reward."""
    if cfg.reward_fn is not None:
        return float(cfg.reward_fn(o))
    return default_reward(o, cfg)
