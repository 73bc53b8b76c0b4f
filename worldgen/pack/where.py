"""``--where`` filters: ``"narrowest_passage < 1.0 and obstacle_count >= 5"``.

Parsed by hand into (metric, operator, number) clauses joined by ``and``;
nothing is ever evaluated as Python. A world whose metric is null (no path,
say) matches no clause on that metric.
"""

from __future__ import annotations

import math
import operator
import re
from typing import Any, Callable, Mapping, Sequence

from worldgen.errors import ParameterError

__all__ = ["parse_where", "OPERATORS"]

OPERATORS: dict[str, Callable[[float, float], bool]] = {
    "<=": operator.le, ">=": operator.ge, "==": operator.eq, "!=": operator.ne, "<": operator.lt, ">": operator.gt,
}
_CLAUSE = re.compile(r"^\s*([A-Za-z_][A-Za-z0-9_]*)\s*(<=|>=|==|!=|<|>)\s*([-+]?(?:\d+\.?\d*|\.\d+)(?:[eE][-+]?\d+)?)\s*$")
_AND = re.compile(r"\s+and\s+", re.IGNORECASE)


def parse_where(text: str, metrics: Sequence[str]) -> Callable[[Mapping[str, Any]], bool]:
    """A predicate over a world's metrics dict; ParameterError naming the bad clause."""
    if not isinstance(text, str) or not text.strip():
        raise ParameterError("--where needs clauses like 'narrowest_passage < 1.0', joined by 'and'")
    clauses = []
    for part in _AND.split(text.strip()):
        m = _CLAUSE.match(part)
        if not m:
            raise ParameterError(
                f"--where clause {part.strip()!r} is not 'METRIC OP NUMBER' with OP one of {' '.join(OPERATORS)}")
        name, op, number = m.group(1), m.group(2), float(m.group(3))
        if name not in metrics:
            raise ParameterError(f"--where metric '{name}' is unknown; known metrics: {', '.join(metrics)}")
        if not math.isfinite(number):
            raise ParameterError(f"--where number in {part.strip()!r} must be finite")
        clauses.append((name, OPERATORS[op], number))

    def predicate(values: Mapping[str, Any]) -> bool:
        for name, op, number in clauses:
            v = values.get(name)
            if v is None or not op(float(v), number):
                return False
        return True

    return predicate
