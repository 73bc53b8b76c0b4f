"""Typed, range-checked generator parameters.

Every generator declares its parameters as :class:`Param` objects; validation
fills defaults and rejects unknown names, wrong types and out-of-range values
with one message shape: the parameter, the rule, the value received.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any, Mapping, Optional, Sequence

from worldgen.errors import ParameterError, did_you_mean, quoted
from worldgen.floats import round_float

__all__ = ["Param", "validate_params", "parse_value", "COMMON_PARAMS", "PEOPLE_PARAMS", "MOTION_PARAMS", "describe_range",
           "CLIMB_PARAMS"]

_KINDS = ("float", "int", "bool", "choice", "pair", "range", "triple", "list", "words")
#: Most items a ``list`` or ``words`` parameter may hold.
MAX_ITEMS = 64


@dataclass(frozen=True)
class Param:
    """One parameter.

    ``kind``:
      - ``float`` / ``int``: a number in [low, high];
      - ``bool``;
      - ``choice``: one of ``choices``;
      - ``pair``: two floats, each in [low, high] (e.g. ``size`` = x, y extents);
      - ``range``: two floats lo <= hi, each in [low, high] (a size range to draw from).
      - ``triple``: three floats, each in [low, high] (e.g. a spawn ``[x, y, yaw]``);
      - ``list``: 1 to MAX_ITEMS floats, each in [low, high] (e.g. segment lengths);
      - ``words``: 1 to MAX_ITEMS words, each one of ``choices``, kept as one
        comma-joined string (``"left,right"``) so world.json's params stay plain.
    ``default`` None means "unset" and is allowed only where ``optional``.
    ``option_of`` names the bool parameter that switches on the option it belongs to (the switch names
    itself): while the switch is off, the option's parameters are refused when given and not recorded, so
    that worlds made before the option existed keep their params and bytes (cluttered's ``terrain``).
    """

    name: str
    kind: str
    default: Any
    doc: str
    low: Optional[float] = None
    high: Optional[float] = None
    choices: tuple = ()
    optional: bool = False
    unit: str = ""
    option_of: str = ""

    def __post_init__(self):
        assert self.kind in _KINDS, self.kind

    def check(self, value: Any) -> Any:
        """Return ``value`` normalised, or raise :class:`ParameterError`."""
        if value is None:
            if self.optional:
                return None
            raise self._error("is required", value)
        if self.kind == "bool":
            if isinstance(value, bool):
                return value
            raise self._error("must be true or false", value)
        if self.kind == "choice":
            if value in self.choices:
                return value
            raise self._error(f"must be one of {', '.join(map(str, self.choices))}", value)
        if self.kind in ("float", "int"):
            return self._number(value)
        if self.kind == "words":
            return self._words(value)
        if self.kind == "list":
            if isinstance(value, (str, bytes)) or not isinstance(value, Sequence) or not 1 <= len(value) <= MAX_ITEMS:
                raise self._error(f"must be a list of 1 to {MAX_ITEMS} numbers, each {describe_range(self)}", value)
            return [self._number(v, whole=False) for v in value]
        if self.kind == "triple":
            if isinstance(value, (str, bytes)) or not isinstance(value, Sequence) or len(value) != 3:
                raise self._error(f"must be three numbers, each {describe_range(self)}", value)
            return [self._number(v, whole=False) for v in value]
        # pair / range
        if isinstance(value, (str, bytes)) or not isinstance(value, Sequence) or len(value) != 2:
            raise self._error(f"must be two numbers, each {describe_range(self)}", value)
        a, b = (self._number(v, whole=False) for v in value)
        if self.kind == "range" and a > b:
            raise self._error("must be [min, max] with min <= max", value)
        return [a, b]

    def _number(self, value: Any, whole: bool | None = None) -> Any:
        whole = self.kind == "int" if whole is None else whole
        if isinstance(value, bool):
            raise self._error(f"must be {'an integer' if whole else 'a number'} {describe_range(self)}", value)
        number: float
        try:
            if whole:
                if isinstance(value, float) and not value.is_integer():
                    raise ValueError
                number = int(value)
            else:
                # Rounded as world.json writes it, so the parameters a world records
                # regenerate exactly that world (pi/2 would not survive 6 decimals).
                number = round_float(float(value))
        except (TypeError, ValueError, OverflowError):
            raise self._error(f"must be {'an integer' if whole else 'a number'} {describe_range(self)}", value) from None
        if not math.isfinite(number) or (self.low is not None and number < self.low) or (
            self.high is not None and number > self.high
        ):
            raise self._error(f"must be {describe_range(self)}", value)
        return number

    def _words(self, value: Any) -> str:
        items = value.split(",") if isinstance(value, str) else value
        rule = f"must be 1 to {MAX_ITEMS} comma-separated words, each one of {', '.join(map(str, self.choices))}"
        if isinstance(items, bytes) or not isinstance(items, Sequence) or not 1 <= len(items) <= MAX_ITEMS:
            raise self._error(rule, value)
        words = [w.strip() if isinstance(w, str) else w for w in items]
        if not all(w in self.choices for w in words):
            raise self._error(rule, value)
        return ",".join(words)

    def _error(self, rule: str, value: Any) -> ParameterError:
        return ParameterError(f"parameter '{self.name}' {rule}, got {quoted(value)}")


def describe_range(p: Param) -> str:
    """The allowed values of ``p`` in words, e.g. ``in [0, 2000]``."""
    if p.kind in ("choice", "words"):
        return "one of " + ", ".join(map(str, p.choices))
    if p.kind == "bool":
        return "true or false"
    if p.low is not None and p.low == p.high:  # a common parameter a generator pins (corridor's n_tasks)
        return f"exactly {_num(p.low)}"
    lo = "-inf" if p.low is None else _num(p.low)
    hi = "inf" if p.high is None else _num(p.high)
    return f"in [{lo}, {hi}]"


def _num(x: float) -> str:
    return str(int(x)) if float(x).is_integer() else repr(float(x))


def validate_params(specs: Sequence[Param], given: Mapping[str, Any]) -> dict[str, Any]:
    """Defaults filled, every value checked, unknown names rejected; sorted by name."""
    by_name = {p.name: p for p in specs}
    unknown = sorted(set(given) - set(by_name))
    if unknown:
        raise ParameterError(
            f"unknown parameter '{unknown[0]}'{did_you_mean(unknown[0], by_name)}; "
            f"known parameters: {', '.join(sorted(by_name))}"
        )
    resolved = {}
    for name in sorted(by_name):
        p = by_name[name]
        resolved[name] = p.check(given.get(name, p.default))
    moving = bool(resolved.get("n_people") or resolved.get("n_movers"))
    if not resolved.get("n_people"):
        # People's parameters without people would be accepted and do nothing: a mistake to say.
        _refuse_idle(by_name, given, resolved, [n for n in PEOPLE_PARAMS if n != "n_people"],
                     "sets how people walk, and this world has none: set n_people (1 or more) too", "n_people")
        # A world without people records none of their parameters, so that every world made before
        # people existed keeps its params, content_hash and bytes (docs/people.md).
        for name in PEOPLE_PARAMS:
            resolved.pop(name, None)
    if not moving:
        # The robot's motion limits bound the timed certificate, which only a world with people or movers has.
        _refuse_idle(by_name, given, resolved, list(MOTION_PARAMS), "bounds the timed path among people and "
                     "movers, and this world has neither: set n_people or n_movers (1 or more) too", "n_people")
        for name in MOTION_PARAMS:
            resolved.pop(name, None)
    _drop_idle_options(by_name, given, resolved)
    if resolved.get("people_behaviour") == "impassive":
        # Recorded only when people react to the robot: worlds made before reactions keep their bytes.
        resolved.pop("people_behaviour")
    if resolved.get("group_size") == 1:
        # Recorded only when people walk in groups: worlds with people alone keep their bytes.
        resolved.pop("group_size")
    if "lidar_range_min" in resolved and "lidar_range_max" in resolved:
        # The one rule between two common parameters: a lidar needs a non-empty range.
        if resolved["lidar_range_min"] >= resolved["lidar_range_max"]:
            raise ParameterError(
                f"parameter 'lidar_range_min' must be below lidar_range_max = {resolved['lidar_range_max']!r}, "
                f"got {resolved['lidar_range_min']!r}"
            )
    return resolved


def _drop_idle_options(by_name: Mapping[str, Param], given: Mapping[str, Any], resolved: dict) -> None:
    """An option switched off: its parameters refused when given (they would do nothing), then not recorded."""
    for switch in sorted({p.option_of for p in by_name.values() if p.option_of}):
        if resolved.get(switch):
            continue
        members = [p for p in by_name.values() if p.option_of == switch and p.name != switch]
        idle = [p.name for p in members if given.get(p.name) is not None and resolved[p.name] != p.check(p.default)]
        if idle:
            raise ParameterError(f"parameter '{idle[0]}' belongs to the {switch} option, which is off: set "
                                 f"{switch}=true too, or leave it out; got {idle[0]}={quoted(given[idle[0]])}")
        for p in members:
            resolved.pop(p.name, None)
        resolved.pop(switch, None)


#: The people's parameters: recorded in a world's params only when it has people (n_people > 0).
PEOPLE_PARAMS = ("n_people", "person_radius", "person_speed", "people_duration", "people_scenario", "group_size",
                 "people_behaviour")
#: The robot's motion limits the timed certificate keeps to: recorded only in a world with people or movers.
MOTION_PARAMS = ("robot_turn_rate", "robot_acceleration")


def _refuse_idle(by_name, given, resolved, names, what: str, switch: str) -> None:
    """One line naming the first of ``names`` given a value other than its default, which ``what`` says
    does nothing in this world."""
    idle = [n for n in names if n in by_name and given.get(n) is not None
            and resolved[n] != by_name[n].check(by_name[n].default)]
    if idle:
        raise ParameterError(f"parameter '{idle[0]}' {what}, or leave it out; got {idle[0]}={quoted(given[idle[0]])}"
                             f" and {switch}={quoted(resolved.get(switch, 0))}")


def parse_value(p: Param, text: str) -> Any:
    """Turn command-line text into a value for ``p`` (checked later by :meth:`Param.check`)."""
    t = text.strip()
    if p.optional and t.lower() in ("none", "null"):
        return None
    if p.kind == "bool":
        low = t.lower()
        if low in ("true", "yes", "1", "on"):
            return True
        if low in ("false", "no", "0", "off"):
            return False
        return t
    if p.kind == "words":
        return t
    if p.kind in ("list", "triple"):
        return [_maybe_number(s) for s in t.replace(" ", ",").strip("[]()").split(",") if s]
    if p.kind in ("pair", "range"):
        parts = [s for s in t.replace("x", ",").replace(" ", ",").strip("[]()").split(",") if s]
        return [_maybe_number(s) for s in parts]
    if p.kind in ("float", "int"):
        return _maybe_number(t)
    return t


def _maybe_number(s: str) -> Any:
    try:
        return int(s)
    except ValueError:
        try:
            return float(s)
        except ValueError:
            return s


#: Parameters every generator takes, under the same names, so users can guess them.
COMMON_PARAMS: tuple[Param, ...] = (
    Param("robot_radius", "float", 0.2, "radius of the robot footprint (a vertical cylinder)", 0.01, 5.0, unit="m"),
    Param("robot_height", "float", 0.4, "height of the robot footprint", 0.01, 5.0, unit="m"),
    Param("clearance", "float", 0.05, "margin kept between the footprint's edge and obstacles", 0.0, 2.0, unit="m"),
    Param("max_attempts", "int", 50, "draws tried (each with a derived seed) before giving up", 1, 10000),
    Param("n_tasks", "int", 1, "spawn/goal pairs per world", 1, 64),
    Param("goal_tolerance", "float", 0.2, "distance from the goal that counts as reached", 0.01, 5.0, unit="m"),
    Param("robot_speed", "float", 0.5, "speed assumed for each task's time_limit", 0.01, 20.0, unit="m/s"),
    Param("friction", "float", 1.0, "Coulomb friction of every surface", 0.0, 10.0),
    Param("step_size", "float", 0.002, "physics step in every format", 0.0001, 0.1, unit="s"),
    Param("real_time_factor", "float", 1.0, "Gazebo real-time factor; 0 runs as fast as possible", 0.0, 1000.0),
    Param("n_movers", "int", 0, "person-sized movers walking scripted looping paths on free floor", 0, 64),
    Param("mover_radius", "float", 0.25, "radius of each mover's cylinder", 0.05, 2.0, unit="m"),
    Param("mover_height", "float", 1.7, "height of each mover's cylinder", 0.1, 5.0, unit="m"),
    Param("mover_speed", "float", 1.0, "walking speed of every mover", 0.05, 10.0, unit="m/s"),
    Param("mover_waypoints", "int", 4, "distinct waypoints of each mover's loop", 2, 32),
    Param("sdf_actors", "bool", True, "write movers into the SDF as <actor>s; false leaves them out of the SDF only "
          "(for SDF readers that reject actors, e.g. Drake): they stay in the MJCF and world.json"),
    Param("n_people", "int", 0, "pedestrians walking from place to place by the social force model (docs/people.md)",
          0, 64),
    Param("person_radius", "float", 0.25, "radius of each person's disc", 0.1, 1.0, unit="m"),
    Param("person_speed", "range", [1.0, 1.4], "range each person's preferred walking speed is drawn from",
          0.1, 3.0, unit="m/s"),
    Param("people_duration", "float", 60.0, "how long people walk; afterwards each stands where it stopped",
          1.0, 600.0, unit="s"),
    Param("people_scenario", "choice", "walk", "walk: everyone walks from place to place; head_on / crossing / "
          "overtaking / group_passing / doorway: the first person (group) walks that human-encounter scenario "
          "against the first task (docs/people.md)",
          choices=("walk", "head_on", "crossing", "overtaking", "group_passing", "doorway")),
    Param("group_size", "int", 1, "people walk in groups of this many that keep together (Moussaid et al. 2010; "
          "docs/people.md); 1: alone", 1, 8),
    Param("people_behaviour", "words", "impassive", "how people react to the robot (HuNavSim's behaviours, "
          "docs/people.md): one for everyone, or a comma-separated list cycled over the people; each reaction "
          "stays inside a tube round the person's recorded walk that the timed path is certified clear of",
          choices=("impassive", "regular", "surprised", "scared", "curious")),
    Param("robot_turn_rate", "float", 1.0, "how fast the robot turns on the spot: the timed path among people "
          "and movers turns its corners no faster (docs/people.md)", 0.05, 20.0, unit="rad/s"),
    Param("robot_acceleration", "float", 1.0, "how fast the robot changes speed: the timed path among people "
          "and movers speeds up and slows down no faster (docs/people.md)", 0.05, 20.0, unit="m/s^2"),
    Param("infeasible", "bool", False, "deliberately make the goal unreachable (a negative test world)"),
    # Ground truth written with every world (worldgen.groundtruth).
    Param("lidar_height", "float", 0.3, "height above the floor of the ground-truth lidar at the first spawn",
          0.001, 50.0, unit="m"),
    Param("lidar_fov", "float", 6.283185, "field of view of the ground-truth lidar, centred ahead (6.283185 = full circle)",
          1e-3, 6.283185307179586, unit="rad"),
    Param("lidar_angle_min", "float", None, "angle of the first ray (ranges[0]) from the robot's heading, as ROS "
          "LaserScan angle_min; unset: the field of view is centred ahead", -6.283185307179586, 6.283185307179586,
          optional=True, unit="rad"),
    Param("lidar_samples", "int", 360, "rays of the ground-truth lidar", 1, 100000),
    Param("lidar_range_min", "float", 0.05, "shortest range of the ground-truth lidar (rays start there)", 0.0, 100.0, unit="m"),
    Param("lidar_range_max", "float", 30.0, "longest range of the ground-truth lidar, written where nothing is hit",
          0.01, 10000.0, unit="m"),
    Param("map_height", "float", 0.1,
          "height of the horizontal slice the occupancy map is made from (above the floor slab)", 0.001, 50.0, unit="m"),
    Param("map_resolution", "float", 0.05, "edge of one occupancy map cell", 0.005, 10.0, unit="m"),
)


#: The robot's climbing limits (docs/terrain.md), taken by generators that make terrain: not common, so that
#: a flat world's params (and bytes) stay as they were. Defaults: worldgen.scene.terrain.CLIMB_DEFAULTS.
CLIMB_PARAMS: tuple[Param, ...] = (
    Param("robot_max_incline", "float", 10.0, "steepest ground the robot drives on", 0.0, 45.0, unit="deg"),
    Param("robot_max_step_up", "float", 0.02, "highest step edge the robot climbs", 0.0, 0.5, unit="m"),
    Param("robot_max_step_down", "float", 0.02, "deepest step edge the robot drives down", 0.0, 0.5, unit="m"),
    Param("robot_ground_clearance", "float", 0.03, "height of the chassis above flat ground", 0.0, 0.5, unit="m"),
)
