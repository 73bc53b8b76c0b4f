"""Every setting of the navigation environment: defaults in one place, checked up front.

Each setting is a :class:`worldgen.params.Param`, so a bad value gets the same
one-line :class:`~worldgen.errors.ParameterError` as a generator parameter:
``parameter 'lidar_beams' must be an integer in [1, 4096], got 0``.
:func:`resolve` checks them all, then the rules between two of them.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, fields
from typing import Any, Callable, Mapping, Optional

from worldgen.envs.doors import DOOR_MODES
from worldgen.errors import ParameterError, quoted
from worldgen.params import Param, validate_params

__all__ = ["SETTINGS", "EnvConfig", "resolve"]

#: The settings, their defaults and allowed ranges (``NavigationEnv(**settings)``).
SETTINGS: tuple[Param, ...] = (
    Param("control_period", "float", 0.1, "seconds of simulation per env step (a whole number of the world's "
          "physics steps)", 0.001, 10.0, unit="s"),
    Param("linear_velocity", "range", None, "[min, max] forward speed v the action may ask for, and the robot's "
          "servo range (unset: [0, max_speed] of the world's robot, world.json robot.max_speed or its default)",
          -10.0, 10.0, optional=True, unit="m/s"),
    Param("angular_velocity", "float", None, "largest turn rate |w| the action may ask for, and the robot's "
          "(unset: the world's robot's turn rate, world.json robot.max_turn_rate or its default)", 0.001, 20.0,
          optional=True, unit="rad/s"),
    Param("lidar_beams", "int", 360, "rays of the planar lidar", 1, 4096),
    Param("lidar_fov", "float", 2.0 * math.pi, "field of view of the lidar, centred ahead unless lidar_angle_min "
          "is set (6.283185 = full circle)", 0.001, 2.0 * math.pi, unit="rad"),
    Param("lidar_angle_min", "float", None, "angle of the first ray from the heading (unset: the field of "
          "view is centred ahead)", -2.0 * math.pi, 2.0 * math.pi, optional=True, unit="rad"),
    Param("lidar_range_min", "float", 0.05, "shortest range reported (closer readings are clipped up to it)",
          0.0, 100.0, unit="m"),
    Param("lidar_range_max", "float", 10.0, "longest range; reported where nothing is hit", 0.01, 1000.0, unit="m"),
    Param("lidar_height", "float", None, "height of the lidar above the floor (unset: the world's lidar_height)",
          0.001, 50.0, optional=True, unit="m"),
    Param("lidar_sectors", "int", None, "bin the beams into this many sectors, each reporting its minimum "
          "(unset: every beam)", 1, 4096, optional=True),
    Param("lidar_noise", "float", 0.0, "standard deviation of Gaussian range noise on every hit", 0.0, 10.0, unit="m"),
    Param("reward", "choice", "geodesic", "the step reward: geodesic (potential-based shaping by the exact geodesic "
          "distance to the goal), walkthrough (the deep-RL walkthrough's v/2 - |w|/2 - (1 - r)/2) or "
          "euclidean_progress (the decrease of the straight-line distance); see worldgen.envs.reward",
          choices=("geodesic", "walkthrough", "euclidean_progress")),
    Param("reward_progress", "float", 10.0, "scale of the progress terms: the potential is -reward_progress x "
          "geodesic distance (geodesic); reward_progress x decrease of the straight-line distance "
          "(euclidean_progress)", 0.0, 1e6, unit="1/m"),
    Param("reward_discount", "float", 1.0, "gamma of the potential-based shaping gamma * phi(s') - phi(s) (1: the "
          "decrease of the geodesic distance, standing still earns -reward_time; the learner's discount: exact "
          "policy invariance, but standing still earns (1 - gamma) k G - reward_time)", 0.0, 1.0),
    Param("reward_time", "float", 0.05, "time penalty subtracted every step (geodesic, euclidean_progress)",
          0.0, 1e6),
    Param("time_limit_factor", "float", 2.0, "time limit as a multiple of the optimal time L / v_max (L the exact "
          "shortest path's length; among people the certified arrival_time where longer), plus a half turn "
          "pi / w_max; unset: the task's own time_limit (world.json)",
          0.1, 1000.0, optional=True),
    Param("geodesic_spacing", "float", 0.1, "grid spacing of the geodesic distance field built at each reset "
          "(see worldgen.envs.geodesic for its error bound)", 0.01, 10.0, unit="m"),
    Param("goal_distance_max", "float", None, "upper bound of the observed goal distance (unset: the diagonal of "
          "the largest world the source can make; see NavigationEnv); larger distances are clipped to it",
          0.01, 1e6, optional=True, unit="m"),
    Param("reward_goal", "float", 100.0, "reward on reaching the goal", -1e6, 1e6),
    Param("reward_collision", "float", -100.0, "reward on a collision", -1e6, 1e6),
    Param("reward_speed", "float", 0.5, "weight of the forward speed v in the step reward", -1e6, 1e6),
    Param("reward_turn", "float", 0.5, "weight of the turn rate |w| subtracted in the step reward", -1e6, 1e6),
    Param("reward_obstacle", "float", 0.5, "weight of (obstacle_distance - closest range) subtracted while an "
          "obstacle is nearer than obstacle_distance", -1e6, 1e6),
    Param("obstacle_distance", "float", 1.0, "closest lidar range below which the obstacle penalty applies",
          0.0, 1000.0, unit="m"),
    Param("terminate_on_collision", "bool", True, "end the episode at the first contact (else count contacts "
          "and drive on)"),
    Param("doors", "choice", "auto", "how door leaves open (worldgen.envs.doors): auto (a door the robot comes to "
          "from the side its leaf swings into opens by itself; from the other side the robot pushes it), "
          "automatic (every door opens by itself as the robot comes near), push (leaves are only pushed: a pull "
          "door stays shut)", choices=DOOR_MODES),
    Param("door_trigger", "float", 2.0, "distance from a doorway's centre within which its automatic door opens",
          0.0, 1000.0, unit="m"),
    Param("door_speed", "float", 2.0, "opening speed of an automatic door's leaf", 0.01, 100.0, unit="rad/s"),
)


@dataclass(frozen=True)
class EnvConfig:
    """The resolved settings (see :data:`SETTINGS` for each one's meaning and unit)."""

    control_period: float
    linear_velocity: Optional[tuple[float, float]]
    angular_velocity: Optional[float]
    lidar_beams: int
    lidar_fov: float
    lidar_angle_min: Optional[float]
    lidar_range_min: float
    lidar_range_max: float
    lidar_height: Optional[float]
    lidar_sectors: Optional[int]
    lidar_noise: float
    reward: str
    reward_progress: float
    reward_discount: float
    reward_time: float
    time_limit_factor: Optional[float]
    geodesic_spacing: float
    goal_distance_max: Optional[float]
    reward_goal: float
    reward_collision: float
    reward_speed: float
    reward_turn: float
    reward_obstacle: float
    obstacle_distance: float
    terminate_on_collision: bool
    doors: str
    door_trigger: float
    door_speed: float
    reward_fn: Optional[Callable[..., float]] = None

    @property
    def observation_size(self) -> int:
        """Length of the observation vector: the scan (beams or sectors), goal distance and angle, last (v, w)."""
        return (self.lidar_sectors or self.lidar_beams) + 4

    def substeps(self, step_size: float) -> int:
        """Physics steps in one control period for a world stepping at ``step_size`` s.

        A period that is not a whole number of physics steps (within 1e-6) is a
        :class:`ParameterError`: one env step must be exactly ``control_period``.
        """
        n = round(self.control_period / step_size)
        if n < 1 or abs(n * step_size - self.control_period) > 1e-6 * max(1.0, self.control_period):
            raise ParameterError(f"parameter 'control_period' must be a whole multiple of the world's physics "
                                 f"step_size = {step_size:g} s, got {self.control_period!r}")
        return n


def resolve(settings: Mapping[str, Any]) -> EnvConfig:
    """Every setting checked and defaults filled; ``reward_fn`` (a callable or None) passes through."""
    settings = dict(settings)
    reward_fn = settings.pop("reward_fn", None)
    if reward_fn is not None and not callable(reward_fn):
        raise ParameterError(f"parameter 'reward_fn' must be a callable (StepOutcome -> float) or None, "
                             f"got {quoted(reward_fn)}")
    values = validate_params(SETTINGS, settings)
    if values["linear_velocity"] is not None:
        v_lo, v_hi = values["linear_velocity"]
        if v_lo >= v_hi:
            raise ParameterError(f"parameter 'linear_velocity' must be [min, max] with min < max, got {[v_lo, v_hi]!r}")
        values["linear_velocity"] = (v_lo, v_hi)
    if values["lidar_range_min"] >= values["lidar_range_max"]:
        raise ParameterError(f"parameter 'lidar_range_min' must be below lidar_range_max = "
                             f"{values['lidar_range_max']!r}, got {values['lidar_range_min']!r}")
    sectors, beams = values["lidar_sectors"], values["lidar_beams"]
    if sectors is not None and (sectors > beams or beams % sectors):
        raise ParameterError(f"parameter 'lidar_sectors' must divide lidar_beams = {beams} (a whole number of beams "
                             f"per sector), got {sectors!r}")
    names = {f.name for f in fields(EnvConfig)}
    return EnvConfig(**{k: v for k, v in values.items() if k in names}, reward_fn=reward_fn)
