"""worldgen's own check of an OpenSCENARIO 2 file before it is written: every action and struct called is
one the scenario_execution libraries declare, every argument name is one of its parameters, every
required parameter is given, and every value has its parameter's type, a physical quantity with a unit.

scenario_execution's parser refuses an unknown action and a wrong argument name but takes ``3.0`` for a
length without a unit, so this check is stricter than the tool on what matters most to a scenario:
that every number says what it measures. It knows the declarations the export uses (:data:`ACTIONS`,
:data:`STRUCTS`, :data:`MODIFIERS`: names and types as the libraries ``osc.helpers``, ``osc.ros``,
``osc.gazebo``, ``osc.nav2`` and ``osc.types`` declare them; tests/export/test_osc.py holds them against
those files) and the units of ``osc.types`` (:data:`UNITS`). It reads the subset of OSC 2 the export
writes: imports, one or more scenarios with a modifier, actor fields, and ``serial`` blocks of calls
each on one line, ``emit end``.

    >>> lint("import osc.ros\\nscenario s:\\n    do serial:\\n        wait_for_sim(timeout: 60)\\n")
    Traceback (most recent call last):
    ...
    worldgen.errors.ParameterError: .osc line 4: wait_for_sim's timeout is a time: 60 has no unit (s, ms, min, h)
"""

from __future__ import annotations

import re
from typing import Optional

from worldgen.errors import ParameterError

__all__ = ["UNITS", "STRUCTS", "ACTIONS", "MODIFIERS", "ACTOR_TYPES", "lint"]

#: The units osc.types declares for the physical types the export writes, the short names first (a
#: refusal names the first four).
UNITS: dict[str, tuple[str, ...]] = {
    "length": ("m", "cm", "mm", "km", "meter", "centimeter", "millimeter", "kilometer", "nm", "nanometer",
               "micrometer", "inch", "feet", "mile", "mi"),
    "time": ("s", "ms", "min", "h", "sec", "second", "millisecond", "minute", "hour"),
    "angle": ("rad", "deg", "radian", "degree"),
}
#: (parameter, type, has a default) of each struct the export builds (osc.types).
STRUCTS: dict[str, tuple[tuple[str, str, bool], ...]] = {
    "position_3d": (("x", "length", True), ("y", "length", True), ("z", "length", True)),
    "orientation_3d": (("roll", "angle", True), ("pitch", "angle", True), ("yaw", "angle", True)),
    "pose_3d": (("position", "position_3d", False), ("orientation", "orientation_3d", False)),
    "key_value": (("key", "string", False), ("value", "string", True)),
}
#: (parameter, type, has a default) of each action the export calls; ``actor.action`` for an actor's own.
ACTIONS: dict[str, tuple[tuple[str, str, bool], ...]] = {
    "ros_launch": (("package_name", "string", False), ("launch_file", "string", False),
                   ("arguments", "list of key_value", False), ("wait_for_shutdown", "bool", True),
                   ("shutdown_timeout", "time", True)),
    "wait_for_sim": (("timeout", "time", True), ("world_name", "string", True)),
    "bag_record": (("topics", "list of string", False), ("timestamp_suffix", "bool", True),
                   ("hidden_topics", "bool", True), ("storage", "string", True), ("use_sim_time", "bool", True)),
    "differential_drive_robot.init_nav2": (
        ("initial_pose", "pose_3d", False), ("base_frame_id", "string", True), ("use_initial_pose", "bool", True),
        ("namespace_override", "string", True), ("wait_for_initial_pose", "bool", True),
        ("wait_for_amcl", "bool", True)),
    "differential_drive_robot.nav_to_pose": (
        ("goal_pose", "pose_3d", False), ("namespace_override", "string", True), ("action_topic", "string", True),
        ("success_on_acceptance", "bool", True)),
    "log": (("msg", "string", False),),
}
#: Modifiers (osc.helpers): written as a call on a line of their own, at the head of a block.
MODIFIERS: dict[str, tuple[tuple[str, str, bool], ...]] = {"timeout": (("duration", "time", False),)}
#: The actor types a scenario may declare fields of (osc.ros, osc.gazebo).
ACTOR_TYPES = ("differential_drive_robot", "osc_actor")

_TOKEN = re.compile(r"\s*(?:(?P<str>'[^'\\]*'|\"[^\"\\]*\")|(?P<num>-?\d+(?:\.\d+)?(?:[eE][-+]?\d+)?)(?P<unit>[A-Za-z_]\w*)?"
                    r"|(?P<name>[A-Za-z_]\w*(?:\.[A-Za-z_]\w*)*)|(?P<op>[()\[\],:]))")
_BLOCKS = ("do serial:", "serial:", "parallel:", "emit end")
_FIELD = re.compile(r"([A-Za-z_]\w*): ([A-Za-z_]\w*)$")


class _Line:
    """The tokens of one line and where the reader is among them."""

    def __init__(self, text: str, number: int):
        self.number, self.tokens, at = number, [], 0
        text = text.rstrip()
        while at < len(text):
            m = _TOKEN.match(text, at)
            if m is None or m.end() == at:
                self.fail(f"cannot read {text[at:].strip()!r}")
            assert m is not None
            kind = next(k for k in ("str", "num", "name", "op") if m.group(k) is not None)
            self.tokens.append((kind, m.group(kind), m.group("unit") if kind == "num" else None))
            at = m.end()
        self.at = 0

    def fail(self, message: str):
        raise ParameterError(f".osc line {self.number}: {message}")

    def peek(self) -> tuple:
        return self.tokens[self.at] if self.at < len(self.tokens) else ("end", "", None)

    def take(self, value: Optional[str] = None) -> tuple:
        token = self.peek()
        if value is not None and token[1] != value:
            self.fail(f"expected {value!r}, got {token[1] or 'the end of the line'!r}")
        self.at += 1
        return token


def _value(line: _Line, kind: str, where: str) -> None:
    """Read one value of type ``kind`` (the parameter ``where``) or fail naming what is wrong."""
    token = line.peek()
    if kind.startswith("list of "):
        line.take("[")
        while line.peek()[1] != "]":
            _value(line, kind[len("list of "):], where)
            if line.peek()[1] != "]":
                line.take(",")
        line.take("]")
    elif kind in STRUCTS:
        name = line.take()[1]
        if name != kind:
            line.fail(f"{where} is a {kind}, got {name!r}")
        _arguments(line, kind, STRUCTS[kind])
    elif kind in UNITS:
        if token[0] != "num":
            line.fail(f"{where} is a {kind}: got {token[1]!r}, not a number with a unit")
        if token[2] is None:
            line.fail(f"{where} is a {kind}: {token[1]} has no unit ({', '.join(UNITS[kind][:4])})")
        if token[2] not in UNITS[kind]:
            line.fail(f"{where} is a {kind}: {token[2]!r} is not a unit of {kind} ({', '.join(UNITS[kind][:4])})")
        line.take()
    elif kind == "string":
        if token[0] != "str":
            line.fail(f"{where} is a string, got {token[1]!r}")
        line.take()
    elif kind == "bool":
        if token[1] not in ("true", "false"):
            line.fail(f"{where} is true or false, got {token[1]!r}")
        line.take()
    else:  # a declaration above names a type this check cannot read: refused, never let through
        line.fail(f"{where} is a {kind}, which this check cannot read")


def _arguments(line: _Line, callee: str, params: tuple[tuple[str, str, bool], ...]) -> None:
    """``( [name:] value, ... )`` of ``callee``: known names, no repeats, every required one given."""
    line.take("(")
    given: list[str] = []
    names = [p[0] for p in params]
    named = False
    while line.peek()[1] != ")":
        token = line.peek()
        following = line.tokens[line.at + 1] if line.at + 1 < len(line.tokens) else ("end", "", None)
        if token[0] == "name" and following[1] == ":":
            name = token[1]
            if name not in names:
                line.fail(f"{callee} has no parameter {name!r} (it takes {', '.join(names)})")
            line.take()
            line.take(":")
            named = True
        elif named:
            line.fail(f"{callee}: a positional argument after a named one")
        elif len(given) >= len(names):
            line.fail(f"{callee} takes at most {len(names)} arguments")
        else:
            name = names[len(given)]
        if name in given:
            line.fail(f"{callee}'s {name} is given twice")
        given.append(name)
        _value(line, dict((p[0], p[1]) for p in params)[name], f"{callee.split('.')[-1]}'s {name}")
        if line.peek()[1] != ")":
            line.take(",")
    line.take(")")
    missing = [p[0] for p in params if not p[2] and p[0] not in given]
    if missing:
        line.fail(f"{callee} needs {', '.join(missing)}")


def _call(line: _Line, fields: dict[str, str]) -> None:
    kind, name, _ = line.take()
    if kind != "name":
        line.fail(f"expected an action, got {name!r}")
    actor, _, action = name.rpartition(".")
    if actor:
        if actor not in fields:
            line.fail(f"{actor!r} is not an actor of this scenario ({', '.join(fields) or 'none'})")
        callee = f"{fields[actor]}.{action}"
    else:
        callee = action
    table = ACTIONS if callee in ACTIONS else MODIFIERS if callee in MODIFIERS else None
    if table is None:
        known = sorted({a.split(".")[-1] for a in ACTIONS} | set(MODIFIERS))
        line.fail(f"unknown action {name!r} (known: {', '.join(known)})")
    assert table is not None
    _arguments(line, callee, table[callee])
    if line.peek()[0] != "end":
        line.fail(f"{line.peek()[1]!r} after {name}(...)")


def lint(text: str) -> None:
    """Refuse ``text`` (an .osc file as the export writes it) with one line naming the first fault:
    a ParameterError that the command line reports with exit status 2."""
    fields: dict[str, str] = {}
    scenarios = 0
    for number, raw in enumerate(text.splitlines(), 1):
        stripped = raw.strip()
        if not stripped or stripped.startswith("#") or stripped in _BLOCKS:
            continue
        line = _Line(stripped, number)
        if raw[0] != " ":
            if stripped.startswith("import osc."):
                continue
            m = re.fullmatch(r"scenario ([A-Za-z_]\w*):", stripped)
            if m is None:
                line.fail(f"expected an import or a scenario, got {stripped!r}")
            fields, scenarios = {}, scenarios + 1
            continue
        field = _FIELD.match(stripped)
        if field:
            if field.group(2) not in ACTOR_TYPES:
                line.fail(f"{field.group(1)}'s type {field.group(2)!r} is not an actor type ({', '.join(ACTOR_TYPES)})")
            fields[field.group(1)] = field.group(2)
            continue
        _call(line, fields)
    if not scenarios:
        raise ParameterError(".osc: no scenario in the file")
