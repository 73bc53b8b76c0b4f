"""Runs against worlds, from one run's figures to a batch's verdict (docs/judge.md):
:mod:`~worldgen.judge.figures` (every figure of one run, with the people's in
:mod:`~worldgen.judge.social` and :mod:`~worldgen.judge.proxemics`), :mod:`~worldgen.judge.criteria` (the
acceptance criteria file), :mod:`~worldgen.judge.evaluate` (many runs against the criteria),
:mod:`~worldgen.judge.stats` (confidence bounds, the tests behind ``worldgen compare``),
:mod:`~worldgen.judge.runs` (recorded bags judged against each world's truth) and
:mod:`~worldgen.judge.report` (the report folder with its pictures); ``worldgen judge`` is its command.

``judge``, ``JudgeResult`` and ``write_report`` load on first use (PEP 562): the statistics and the
criteria are imported by ``worldgen compare`` and the environment, which need neither numpy's batch nor
the pictures.
"""

from typing import TYPE_CHECKING

if TYPE_CHECKING:  # what the names below are, for type checkers; at run time they load on first use
    from worldgen.judge.report import write_report
    from worldgen.judge.runs import JudgeResult, judge

__all__ = ["judge", "JudgeResult", "write_report"]

_LAZY = {"judge": "worldgen.judge.runs", "JudgeResult": "worldgen.judge.runs", "write_report": "worldgen.judge.report"}


def __getattr__(name):
    if name in _LAZY:
        import importlib

        value = globals()[name] = getattr(importlib.import_module(_LAZY[name]), name)
        return value
    raise AttributeError(f"module 'worldgen.judge' has no attribute {name!r}")
