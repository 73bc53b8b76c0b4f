"""Acceptance criteria: what a criteria file may say, read and checked key by key.

    navigation:  success_rate (>=, 0..1; a number is the point estimate, {min, confidence} the
                 one-sided Clopper-Pearson lower bound), path_efficiency (<=, mean recorded/reference
                 length over successful runs)
    safety:      obstacle_clearance (>=, m, smallest over all runs), min_obstacle_distance (>=, m,
                 from movers), collision_tolerance (<=, total contacts), max_velocity (<=, m/s)
    performance: max_time (<=, s, slowest successful run), avg_time_to_goal (<=, s, mean over
                 successes), barn_score (>=, mean BARN Challenge score over all runs, failures 0)
    social:      with people (worldgen.judge.social): min_person_distance (>=, m, smallest gap over
                 all runs), personal_space_time (<=, s, the longest of a run), min_time_to_collision
                 (>=, s, smallest over all runs); each holds in a world without people
    scoring:     settings, not criteria: barn_k (the BARN score's lower clip, optimal times) and
                 reference_speed (m/s, optimal time = reference path length / reference_speed)

Every key is optional; an unknown section or key, or a value out of range, is a one-line
:class:`~worldgen.errors.ParameterError`.
"""

from __future__ import annotations

import math
from pathlib import Path
from typing import Any, Mapping

from worldgen.errors import ParameterError
from worldgen.judge.figures import BARN_K, BARN_REFERENCE_SPEED

__all__ = ["CRITERIA", "SCORING", "DEFAULT_CONFIDENCE", "load_criteria"]

#: section -> key -> (comparison, what is measured)
CRITERIA: dict[str, dict[str, tuple[str, str]]] = {
    "navigation": {"success_rate": (">=", "share of runs meeting their scenario"),
                   "path_efficiency": ("<=", "mean recorded length / reference length of successful runs")},
    "safety": {"obstacle_clearance": (">=", "smallest footprint-to-collider distance (m)"),
               "min_obstacle_distance": (">=", "smallest footprint-to-mover gap (m)"),
               "collision_tolerance": ("<=", "total contacts"),
               "max_velocity": ("<=", "highest speed between samples (m/s)")},
    "performance": {"max_time": ("<=", "slowest time to goal of a successful run (s)"),
                    "avg_time_to_goal": ("<=", "mean time to goal of successful runs (s)"),
                    "barn_score": (">=", "mean BARN Challenge score of all runs (failed runs score 0)")},
    "social": {"min_person_distance": (">=", "smallest footprint-to-person gap (m)"),
               "personal_space_time": ("<=", "longest time of a run within a person's personal space (s)"),
               "min_time_to_collision": (">=", "smallest time to collision with a person (s)")},
}

#: The settings section: key -> (default, what it sets).
SCORING: dict[str, tuple[float, str]] = {
    "barn_k": (BARN_K, "the BARN score's lower clip, in optimal times (BARN 2022: 4, since: 2)"),
    "reference_speed": (BARN_REFERENCE_SPEED, "m/s: optimal time = reference path length / this speed"),
}

#: The confidence of ``success_rate: {min: ...}`` when the file gives none.
DEFAULT_CONFIDENCE = 0.95


def _number(where: str, name: str, value: Any) -> float:
    if isinstance(value, bool) or not isinstance(value, (int, float)) or not math.isfinite(value) or value < 0:
        raise ParameterError(f"{where}: {name} must be a finite number >= 0, got {value!r}")
    return float(value)


def _success_rate(where: str, value: Any):
    """A number (the point estimate's minimum) or {min, confidence} (the lower bound's)."""
    if isinstance(value, Mapping):
        unknown = set(value) - {"min", "confidence"}
        if unknown or "min" not in value:
            raise ParameterError(f"{where}: navigation.success_rate as a mapping takes min (required) and confidence, "
                                 f"got keys {', '.join(sorted(map(str, value))) or 'none'}")
        minimum = _number(where, "navigation.success_rate.min", value["min"])
        confidence = value.get("confidence", DEFAULT_CONFIDENCE)
        if isinstance(confidence, bool) or not isinstance(confidence, (int, float)) or not 0.5 <= confidence < 1:
            raise ParameterError(f"{where}: navigation.success_rate.confidence must be in [0.5, 1), e.g. 0.95, "
                                 f"got {confidence!r}")
        if minimum > 1:
            raise ParameterError(f"{where}: navigation.success_rate.min must be in [0, 1], got {value['min']!r}")
        return {"min": minimum, "confidence": float(confidence)}
    rate = _number(where, "navigation.success_rate", value)
    if rate > 1:
        raise ParameterError(f"{where}: navigation.success_rate must be in [0, 1], got {value!r}")
    return rate


def _scoring(where: str, keys: Mapping) -> dict[str, float]:
    out = {}
    for key, value in keys.items():
        if key not in SCORING:
            raise ParameterError(f"{where}: unknown key scoring.{key}; allowed in scoring: {', '.join(SCORING)}")
        out[key] = _number(where, f"scoring.{key}", value)
    if "barn_k" in out and not 0 < out["barn_k"] <= 8:
        raise ParameterError(f"{where}: scoring.barn_k must be in (0, 8] (BARN used 4, then 2), got {keys['barn_k']!r}")
    if "reference_speed" in out and out["reference_speed"] <= 0:
        raise ParameterError(f"{where}: scoring.reference_speed must be > 0 (m/s), got {keys['reference_speed']!r}")
    return out


def load_criteria(criteria) -> dict[str, dict[str, Any]]:
    """Criteria from a YAML file path, a YAML text or a mapping, checked key by key.

    Values are floats, except ``navigation.success_rate`` in its confidence form:
    ``{"min": float, "confidence": float}``. A ``scoring`` section, if given, holds its settings.
    """
    import yaml

    where = "criteria"
    is_file_name = isinstance(criteria, str) and "\n" not in criteria and criteria.endswith((".yaml", ".yml"))
    if isinstance(criteria, Path) or is_file_name:
        where = str(criteria)
        try:
            criteria = Path(criteria).read_text()
        except OSError as exc:
            raise ParameterError(f"parameter 'criteria': cannot read '{where}': {exc.strerror}") from None
    if isinstance(criteria, str):
        try:
            criteria = yaml.safe_load(criteria) or {}
        except yaml.YAMLError as exc:
            raise ParameterError(f"parameter 'criteria': {where} is not valid YAML ({str(exc).splitlines()[0]})") from None
    sections = ", ".join([*CRITERIA, "scoring"])
    if not isinstance(criteria, Mapping):
        raise ParameterError(f"parameter 'criteria' must be a mapping of sections {sections}, got {type(criteria).__name__}")
    out: dict[str, dict[str, Any]] = {}
    for section, keys in criteria.items():
        if section not in CRITERIA and section != "scoring":
            raise ParameterError(f"{where}: unknown section {section!r}; allowed: {sections}")
        if not isinstance(keys, Mapping):
            raise ParameterError(f"{where}: section {section!r} must be a mapping of criteria, got {type(keys).__name__}")
        if section == "scoring":
            out[section] = _scoring(where, keys)
            continue
        out[section] = {}
        for key, value in keys.items():
            if key not in CRITERIA[section]:
                raise ParameterError(f"{where}: unknown key {section}.{key}; "
                                     f"allowed in {section}: {', '.join(CRITERIA[section])}")
            out[section][key] = (_success_rate(where, value) if key == "success_rate"
                                 else _number(where, f"{section}.{key}", value))
    return out
