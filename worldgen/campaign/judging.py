"""A campaign's run ends as a bag judged as ``worldgen judge`` judges it: where the bag goes, the judging, and the
:class:`Outcome` every system under test returns (:mod:`worldgen.campaign.systems`)."""

from __future__ import annotations

import csv
import io
import shutil
import tempfile
import time
from dataclasses import dataclass
from pathlib import Path
from typing import Any, Optional

from worldgen.errors import ParameterError

__all__ = ["Outcome", "bag_of", "as_walked", "judged", "unjudged", "said"]

@dataclass(frozen=True)
class Outcome:
    """One run's verdict (``passed``, ``failed`` or ``unjudged``), why (empty when passed), the judge's row
    (the columns ``worldgen judge`` writes to report.csv; {} when unjudged) and the run's wall time (s)."""

    verdict: str
    reason: str
    row: dict[str, Any]
    seconds: float


def bag_of(world: Path, task: str, run: str, workdir: Path) -> Path:
    """Where this run's bag goes; a bag left there by a run that was killed is removed (the run starts over).
    A folder that is no world, or a task it does not have, is a ParameterError: the campaign's mistake."""
    from worldgen.groundtruth.ground import load

    if not Path(world).is_dir():
        raise ParameterError(f"parameter 'world' must be a world folder, got '{world}'")
    meta = load(Path(world)).meta  # the folder's world.json, as the judge reads it
    tasks = [str(t["id"]) for t in meta["tasks"]]
    if task not in tasks:
        raise ParameterError(f"parameter 'task' must be one of the world's tasks ({', '.join(tasks)}), got {task!r}")
    bag = Path(workdir) / "bags" / f"{meta['world_id']}__{task}__{run}"
    if bag.is_dir():
        shutil.rmtree(bag)
    elif bag.exists():
        bag.unlink()
    bag.parent.mkdir(parents=True, exist_ok=True)
    return bag


def as_walked(world: Path, meta: dict, walked: dict, into: Path) -> Path:
    """The world folder ``into`` as the run met it: ``world``'s files (linked, not copied) with a world.json whose
    reacting people walk the (k, 3) ``t, x, y`` rows they walked in the episode (``walked``: name -> rows),
    their recorded walk kept as ``recorded_trajectory``, as the environment judges its own episodes
    (:meth:`worldgen.envs.episode.Episode.figures`). Replaces an earlier one at ``into`` whole."""
    import json

    from worldgen.files import METADATA_NAME, atomic_folder

    people = [dict(p, trajectory=walked[str(p["name"])].tolist(), recorded_trajectory=p["trajectory"])
              if str(p["name"]) in walked and len(walked[str(p["name"])]) >= 2 else p for p in meta.get("people") or []]
    into = Path(into)
    with atomic_folder(into.parent, into.name, "run's world folder") as tmp:
        for entry in sorted(Path(world).iterdir()):
            if entry.name != METADATA_NAME:
                (tmp / entry.name).symlink_to(entry.resolve())
        (tmp / METADATA_NAME).write_bytes((json.dumps(dict(meta, people=people), sort_keys=True) + "\n").encode())
    return into


def judged(bag: Path, world: Path, task: str, run: str, criteria: Optional[dict], started: float) -> Outcome:
    """The bag judged with ``worldgen judge --runs`` (a one-row table naming its world, task and run)."""
    from worldgen.judge import judge

    with tempfile.TemporaryDirectory(prefix="worldgen-campaign-") as tmp:
        table = Path(tmp) / "runs.csv"
        buf = io.StringIO()
        out = csv.writer(buf, lineterminator="\n")
        out.writerows([["bag", "world", "task", "run"], [str(Path(bag).resolve()), str(Path(world).resolve()), task, run]])
        table.write_text(buf.getvalue(), encoding="utf-8")
        result = judge(runs=table, criteria=criteria)
    try:
        report = result.report
        row = dict(report["runs"][0])
    finally:
        result.scratch.cleanup()
    seconds = time.perf_counter() - started
    if row.get("outcome") == "unjudged":
        return Outcome("unjudged", f"no readable bag: {row.get('reason')}", {}, seconds)
    if report["passed"]:
        return Outcome("passed", "", row, seconds)
    failures = [f for f in report["failures"] if not f.startswith("navigation.success_rate")]
    # A run that misses its scenario says why in its own words; any other criterion by its failed line.
    reason = "; ".join(([row["reason"]] if not row.get("success") and row.get("reason") else []) + failures)
    return Outcome("failed", reason or "; ".join(report["failures"]), row, seconds)


def unjudged(reason: str, started: float) -> Outcome:
    """A run with no verdict, and why (the command's exit status, its timeout, the policy's error)."""
    return Outcome("unjudged", reason, {}, time.perf_counter() - started)


def said(exc: BaseException) -> str:
    """An exception as one line: its type and its message's first line."""
    text = str(exc).splitlines()[0] if str(exc).strip() else ""
    return f"{type(exc).__name__}: {text}" if text else type(exc).__name__
