"""Runs against worlds: recorded bags judged against each world's truth (:mod:`~worldgen.judge.runs`)
and the report folder with its pictures (:mod:`~worldgen.judge.report`); ``worldgen judge`` is its command
(docs/judge.md)."""

from worldgen.judge.report import write_report
from worldgen.judge.runs import JudgeResult, judge

__all__ = ["judge", "JudgeResult", "write_report"]
