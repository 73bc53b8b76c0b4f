"""Parameter validation: one message shape (parameter, rule, value) for every mistake."""

import pytest

from worldgen.errors import ParameterError
from worldgen.generators import get
from worldgen.params import Param, parse_value, validate_params

SPECS = (
    Param("n", "int", 3, "count", 0, 10),
    Param("x", "float", 1.0, "length", 0.0, 5.0),
    Param("flag", "bool", True, "flag"),
    Param("mode", "choice", "a", "mode", choices=("a", "b")),
    Param("size", "pair", [1.0, 2.0], "size", 0.5, 100.0),
    Param("span", "range", [0.1, 0.2], "span", 0.0, 1.0),
    Param("opt", "float", None, "optional", 0.0, 1.0, optional=True),
)


def test_defaults_filled_and_sorted():
    resolved = validate_params(SPECS, {})
    assert list(resolved) == sorted(resolved)
    assert resolved["n"] == 3 and resolved["opt"] is None and resolved["size"] == [1.0, 2.0]


@pytest.mark.parametrize(
    "given, message",
    [
        ({"n": 11}, "parameter 'n' must be in [0, 10], got 11"),
        ({"n": 2.5}, "parameter 'n' must be an integer in [0, 10], got 2.5"),
        ({"n": True}, "parameter 'n' must be an integer in [0, 10], got True"),
        ({"x": "far"}, "parameter 'x' must be a number in [0, 5], got 'far'"),
        ({"x": float("nan")}, "parameter 'x' must be a number in [0, 5], got nan"),
        ({"flag": "maybe"}, "parameter 'flag' must be true or false, got 'maybe'"),
        ({"mode": "c"}, "parameter 'mode' must be one of a, b, got 'c'"),
        ({"size": [1.0]}, "parameter 'size' must be two numbers, each in [0.5, 100], got [1.0]"),
        ({"size": [1.0, 0.1]}, "parameter 'size' must be in [0.5, 100], got 0.1"),
        ({"span": [0.5, 0.2]}, "parameter 'span' must be [min, max] with min <= max, got [0.5, 0.2]"),
        ({"nope": 1}, "unknown parameter 'nope'; known parameters: flag, mode, n, opt, size, span, x"),
    ],
)
def test_each_mistake_has_one_clear_line(given, message):
    with pytest.raises(ParameterError) as info:
        validate_params(SPECS, given)
    assert str(info.value) == message
    assert "\n" not in str(info.value)


def test_parse_value_from_command_line_text():
    by = {p.name: p for p in SPECS}
    assert parse_value(by["size"], "20,20") == [20, 20]
    assert parse_value(by["size"], "20x15") == [20, 15]
    assert parse_value(by["flag"], "false") is False
    assert parse_value(by["x"], "0.5") == 0.5
    assert parse_value(by["opt"], "none") is None


def test_cluttered_cross_checks():
    spec = get("cluttered")
    with pytest.raises(ParameterError, match="parameter 'size' must exceed"):
        spec.resolve({"size": [1, 10], "robot_radius": 0.6})
    with pytest.raises(ParameterError, match=r"parameter 'min_spawn_goal_distance' must be in \[0, "):
        spec.resolve({"size": [3, 3], "min_spawn_goal_distance": 10})


def test_common_parameter_names_everywhere():
    for name in ("robot_radius", "robot_height", "clearance", "max_attempts"):
        assert name in {p.name for p in get("cluttered").all_params}
