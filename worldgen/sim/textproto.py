"""Reading the protobuf text format that ``ign topic -e`` and ``ign service`` print.

A message is a dict from field name to a list of values (a field may repeat: ``pose`` in a
``Pose_V``); a value is a number, a string, a bare enum word, or a nested message (a dict). Keeping
every field a list means a repeated field with one element reads the same as one with many. Several
messages printed one after another (``ign topic -e -n 3``) are split by :func:`split_messages`. Text
that is not the format raises :class:`~worldgen.errors.SimulatorError`.
"""

from __future__ import annotations

import re

from worldgen.errors import SimulatorError

__all__ = ["parse", "split_messages", "first", "pose_of", "poses_by_name"]

_TOKEN = re.compile(r'\s*(?:(?P<open>\{)|(?P<close>\})|(?P<key>[A-Za-z_][\w.]*)\s*:?|"(?P<str>(?:[^"\\]|\\.)*)"'
                    r"|(?P<num>[-+]?(?:\d+\.?\d*(?:[eE][-+]?\d+)?|\.\d+(?:[eE][-+]?\d+)?|inf|nan))"
                    r"|(?P<word>[A-Za-z_]\w*))")


def _tokens(text: str):
    pos = 0
    while pos < len(text):
        if text[pos:].strip() == "":
            return
        m = _TOKEN.match(text, pos)
        if not m:
            raise SimulatorError(f"not protobuf text at offset {pos}: {text[pos:pos + 40]!r}")
        pos = m.end()
        yield m


def _value(m):
    if m.group("str") is not None:
        return bytes(m.group("str"), "utf-8").decode("unicode_escape")
    num = m.group("num")
    if num is not None:
        return float(num) if any(c in num for c in ".eEn") else int(num)
    return m.group("word") or m.group("key")


def parse(text: str) -> dict:
    """One message's text -> {field: [values]} (nested messages are dicts of the same shape)."""
    stack: list[dict] = [{}]
    pending: str | None = None
    for m in _tokens(text):
        if m.group("open"):
            if pending is None:
                raise SimulatorError("a '{' with no field name before it")
            child: dict = {}
            stack[-1].setdefault(pending, []).append(child)
            stack.append(child)
            pending = None
        elif m.group("close"):
            if len(stack) == 1:
                raise SimulatorError("an unmatched '}'")
            stack.pop()
        elif pending is None and m.group("key") is not None:
            pending = m.group("key")
        elif pending is not None:
            stack[-1].setdefault(pending, []).append(_value(m))
            pending = None
        else:
            raise SimulatorError(f"a value with no field name: {m.group(0)!r}")
    if len(stack) != 1 or pending is not None:
        raise SimulatorError("the message ends inside a field")
    return stack[0]


def split_messages(text: str) -> list[str]:
    """``ign topic -e`` prints messages separated by blank lines; nested braces never hold a blank line."""
    out: list[str] = []
    current: list[str] = []
    depth = 0
    for line in text.splitlines():
        if not line.strip() and depth == 0:
            if any(x.strip() for x in current):
                out.append("\n".join(current))
            current = []
            continue
        current.append(line)
        depth += line.count("{") - line.count("}")
    if any(x.strip() for x in current):
        out.append("\n".join(current))
    return out


def first(message: dict, field: str, default=None):
    """The first value of ``field`` (protobuf text omits fields at their default, so pass that default)."""
    values = message.get(field)
    return values[0] if values else default


def pose_of(message: dict) -> tuple[float, ...]:
    """(x, y, z, qx, qy, qz, qw) of an ``ignition.msgs.Pose`` dict; omitted fields are 0 (w is 1 only when the
    whole orientation is omitted, as gz-msgs writes an identity quaternion with w: 1 explicitly)."""
    position = first(message, "position", {})
    orientation = first(message, "orientation", None)
    xyz = tuple(float(first(position, k, 0.0)) for k in "xyz")
    if orientation is None:
        return xyz + (0.0, 0.0, 0.0, 1.0)
    return xyz + tuple(float(first(orientation, k, 0.0)) for k in "xyzw")


def poses_by_name(pose_v: dict) -> dict[str, tuple[float, ...]]:
    """name -> pose of every entry of an ``ignition.msgs.Pose_V`` dict (``pose/info``, ``dynamic_pose/info``)."""
    return {str(first(p, "name", "")): pose_of(p) for p in pose_v.get("pose", [])}
