"""Stable float formatting, shared by every writer.

Output bytes must not depend on the last bits of a float that two machines may
compute differently, so every number that leaves worldgen goes through here:
rounded to a fixed number of decimals, with tiny values snapped to zero and no
negative zero.
"""

from __future__ import annotations

from worldgen.errors import SceneError

__all__ = ["DECIMALS", "round_float", "fmt", "fmt_seq", "finite_or_none"]

#: Decimals kept in every written float: 1e-6 m is far below any simulator's tolerance.
DECIMALS = 6


def round_float(x: float) -> float:
    """Round ``x`` to :data:`DECIMALS`, mapping -0.0 and |x| < 5e-7 to 0.0."""
    r = round(float(x), DECIMALS)
    if r - r != 0:  # inf - inf and nan - nan are nan: the cheapest finiteness test
        raise SceneError(f"non-finite value {x!r} cannot be written")
    return r if r != 0 else 0.0


def fmt(x: float) -> str:
    """Shortest text of ``round_float(x)``: ``1`` not ``1.0``, ``0.25`` not ``2.5e-01``.

    Formatting with a fixed number of decimals rounds correctly from the exact
    binary value, exactly as ``round`` does, so this equals formatting
    ``round_float(x)``; it is written for speed, being called for every number
    of every exported file.
    """
    text = f"{x:.{DECIMALS}f}"
    if text[-1] in "fn":  # inf, -inf, nan
        raise SceneError(f"non-finite value {x!r} cannot be written")
    text = text.rstrip("0").rstrip(".")
    return "0" if text == "-0" else text


def fmt_seq(values) -> str:
    """Space-separated :func:`fmt` of each value, as XML attributes want them."""
    return " ".join(map(fmt, values))


def finite_or_none(x):
    """None for a missing or unbounded figure (e.g. no obstacle in reach): JSON has no inf."""
    if x is None:
        return None
    x = float(x)
    return x if x - x == 0 else None
