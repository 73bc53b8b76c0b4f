"""The names a scene may give its nodes, joints and movers: plain identifiers, because every
exported format uses them as element names, attribute values and file-system-safe keys."""

from __future__ import annotations

import re

__all__ = ["NAME_PATTERN"]

NAME_PATTERN = re.compile(r"^[A-Za-z][A-Za-z0-9_]{0,63}$")
