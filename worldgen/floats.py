"""Stable float formatting, shared by every writer.

Output bytes must not depend on the last bits of a float that two machines may
compute differently, so every number that leaves worldgen goes through here:
rounded to a fixed number of decimals, with tiny values snapped to zero and no
negative zero.
"""

from __future__ import annotations

import math

__all__ = ["DECIMALS", "round_float", "fmt", "fmt_seq"]

#: Decimals kept in every written float: 1e-6 m is far below any simulator's tolerance.
DECIMALS = 6
_ZERO = 0.5 * 10.0**-DECIMALS


def round_float(x: float) -> float:
    """Round ``x`` to :data:`DECIMALS`, mapping -0.0 and |x| < 5e-7 to 0.0."""
    x = float(x)
    if not math.isfinite(x):
        raise ValueError(f"non-finite value {x!r} cannot be written")
    if abs(x) < _ZERO:
        return 0.0
    r = round(x, DECIMALS)
    return 0.0 if r == 0 else r


def fmt(x: float) -> str:
    """Shortest text of ``round_float(x)``: ``1`` not ``1.0``, ``0.25`` not ``2.5e-01``."""
    r = round_float(x)
    text = f"{r:.{DECIMALS}f}".rstrip("0").rstrip(".")
    return "0" if text in ("", "-0") else text


def fmt_seq(values) -> str:
    """Space-separated :func:`fmt` of each value, as XML attributes want them."""
    return " ".join(fmt(v) for v in values)
