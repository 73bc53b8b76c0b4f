"""Recorded bags plus the worlds they ran in, judged against acceptance criteria: ``worldgen judge``.

Usage (an example that runs is in :mod:`worldgen.ros`)::

    result = judge(["runs/r0", "runs/r1"], "criteria.yaml", world="worlds/cluttered-s0-1f3a9c0b")
    result.passed, result.report["summary"]["unreadable"]
    write_report(result, "report/")          # worldgen.judge.report

Which world a bag ran in, in order of precedence:

- ``runs``: a CSV table with columns ``bag`` and ``world`` (a world id of ``pack``, or a world
  folder), optional ``task`` and ``run``; relative paths are relative to the table's folder;
- ``world``: one world folder for every bag;
- ``pack``: the world whose id the bag names in its metadata (``custom_data``
  ``worldgen.world_id``, which :func:`worldgen.ros.write_run` and the ROS 2 bundle's
  launch file record).

A bag that names a world in its metadata is checked against the world it is judged in.
Each bag is read (streamed) as its turn comes and only its figures are kept, so a batch
of thousands holds one bag at a time. A bag that cannot be read, or whose world cannot be
found, is a row with ``readable`` False and its ``reason``; it is counted in
``summary.unreadable`` and the verdict does not pass while any bag is unreadable: a gate
must not pass on missing data.
"""

from __future__ import annotations

import csv
import math
import tempfile
from collections import OrderedDict
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Callable, Iterator, Optional, Sequence

import numpy as np

from worldgen.errors import ParameterError, WorldgenError, read_user_text
from worldgen.files import MANIFEST_NAME, METADATA_NAME
from worldgen.testing.figures import Ground

__all__ = ["Item", "JudgeResult", "judge", "plan", "PLOT_POINTS", "DEFAULT_CRITERIA"]

#: The gate when no criteria are given: every run reaches its goal within its time limit and touches nothing.
DEFAULT_CRITERIA = {"navigation": {"success_rate": 1.0}}

#: Most points of a run kept for its picture (decimated evenly in path length; the figures use every sample).
PLOT_POINTS = 400
#: Worlds whose colliders are kept between bags of one batch (bags usually come grouped by world).
_CACHE = 8


@dataclass(frozen=True)
class Item:
    """One bag to judge: the bag, its world folder (None: from the bag's metadata), task and run id."""

    bag: Path
    world: Optional[Path]
    task: Optional[str]
    run: Optional[str]


class _WorldGround(Ground):
    """A world folder's ground truth that also reads as a folder (``path``): the oracles use its colliders
    as they are, evaluate reads its scenario.yaml, and one batch builds each world's colliders once."""

    def __init__(self, folder: Path):
        from worldgen.testing.figures import load

        base = load(folder)
        super().__init__(base.meta, read=base._read)
        self.path = folder


@dataclass
class JudgeResult:
    """The report (``Report.to_dict()`` with every bag's row) and what its pictures need, per run.

    The points each picture is drawn from wait in a scratch folder (removed with the result), not in
    memory: a batch holds its report rows and nothing per bag beside them.
    """

    report: dict
    plots: list[Optional[dict]]   # per row: world folder, task, the .npy of its (m, 3) t, x, y; None when unreadable
    scratch: Any = field(default=None, repr=False)  # the TemporaryDirectory holding the .npy files

    def trajectory(self, k: int) -> Optional[np.ndarray]:
        """The decimated ``t, x, y`` of row k's picture (None for an unreadable bag)."""
        plot = self.plots[k]
        return None if plot is None else np.load(plot["points"])

    @property
    def passed(self) -> bool:
        return bool(self.report["passed"])


def plan(bags: Sequence, *, world=None, pack=None, runs=None) -> list[Item]:
    """The bags to judge with where their worlds are; a mistake in the arguments is one ParameterError line."""
    if runs is not None:
        if bags:
            raise ParameterError("give bags either as arguments or in --runs TABLE, not both")
        return _table(Path(runs), pack)
    if not bags:
        raise ParameterError("give at least one BAG (a rosbag2 folder, .mcap, .db3 or .bag), or --runs TABLE")
    folder = None
    if world is not None:
        folder = Path(world)
        if not (folder / METADATA_NAME).is_file():
            raise ParameterError(f"--world '{folder}' is not a world folder (no world.json)")
    elif pack is None:
        raise ParameterError("say where the worlds are: --world DIR, --pack DIR (worlds named in the bags' metadata) "
                             "or --runs TABLE")
    return [Item(Path(b), folder, None, None) for b in bags]


def _index(pack) -> dict[str, Path]:
    """world id -> world folder of a built pack, or of a folder of world folders (``worldgen generate --out``)."""
    import json

    root = Path(pack)
    if not root.is_dir() and not root.is_file():
        raise ParameterError(f"--pack '{root}' does not exist")
    if (root / MANIFEST_NAME).is_file() or root.is_file():
        from worldgen.pack import Pack

        opened = Pack.open(root)
        try:
            if opened.archive:
                raise ParameterError(f"pack '{root}' is an archive: extract it first (worldgen judge reads world folders)")
            return {w.world_id: Path(w.path) for w in opened if w.path is not None}
        finally:
            opened.close()
    found = {}
    for meta in sorted(root.glob("*/world.json")):
        try:
            found[str(json.loads(meta.read_text())["world_id"])] = meta.parent
        except (OSError, ValueError, KeyError, TypeError):
            continue  # not a world folder: the lookup reports the id as missing
    if not found:
        raise ParameterError(f"--pack '{root}' is neither a pack (no manifest.json) nor a folder of world folders")
    return found


def _pack_world(pack, world_id: str, cache: Optional[dict] = None) -> Path:
    cache = {} if cache is None else cache
    key = str(pack)
    if key not in cache:
        cache[key] = _index(pack)
    if world_id not in cache[key]:
        raise ParameterError(f"world {world_id!r} is not in '{pack}'")
    return cache[key][world_id]


def _table(table: Path, pack) -> list[Item]:
    packs: dict[str, dict[str, Path]] = {}
    text = read_user_text(table, "runs table")
    rows = list(csv.DictReader(text.splitlines()))
    if not rows or "bag" not in rows[0] or "world" not in rows[0]:
        raise ParameterError(f"runs table '{table}' must be CSV with columns bag, world[, task, run], "
                             f"got columns {', '.join(rows[0]) if rows else 'none'}")
    out = []
    for i, row in enumerate(rows, start=2):
        bag, world = (row.get("bag") or "").strip(), (row.get("world") or "").strip()
        if not bag or not world:
            raise ParameterError(f"runs table '{table}' line {i}: bag and world must not be empty")
        candidate = table.parent / world
        if (candidate / METADATA_NAME).is_file():
            folder = candidate
        elif pack is not None:
            folder = _pack_world(pack, world, packs)
        else:
            raise ParameterError(f"runs table '{table}' line {i}: world {world!r} is no world folder; "
                                 "give --pack DIR to look world ids up in a pack")
        out.append(Item(table.parent / bag, folder, (row.get("task") or "").strip() or None,
                        (row.get("run") or "").strip() or None))
    return out


def _decimate(traj: np.ndarray, n: int = PLOT_POINTS) -> np.ndarray:
    """At most ``n`` rows of ``t, x, y``, evenly spaced along the path (first and last kept)."""
    if len(traj) <= n:
        return traj[:, :3].copy()
    s = np.concatenate([[0.0], np.cumsum(np.hypot(*np.diff(traj[:, 1:3], axis=0).T))])
    if s[-1] <= 0:
        keep = np.array([0, len(traj) - 1])
    else:
        keep = np.unique(np.concatenate([np.searchsorted(s, np.linspace(0.0, s[-1], n)), [0, len(traj) - 1]]))
    return traj[np.minimum(keep, len(traj) - 1), :3].copy()


# long: reading each bag, judging it and assembling the rows share the per-world cache
def judge(bags: Sequence = (), criteria: Any = None, *, world=None, pack=None, runs=None,
          start: str = "command", read_options: Optional[dict] = None,
          progress: Optional[Callable[[int], None]] = None) -> JudgeResult:
    """Read every bag, judge the readable runs with :func:`worldgen.testing.evaluate.evaluate`, and return the report.

    ``read_options`` go to :func:`worldgen.ros.reader.read_run` (topic and frame names,
    ``spawn_tolerance``, ``distro``...). ``progress(k)`` is called after each bag. Without
    ``criteria`` the gate is :data:`DEFAULT_CRITERIA`: every run meets its scenario, so a batch of
    crashed runs never passes for want of a criteria file.
    """
    from worldgen.ros.reader import read_run
    from worldgen.testing.evaluate import evaluate, load_criteria

    if criteria is None:
        criteria = DEFAULT_CRITERIA
    load_criteria(criteria)  # a mistake in the criteria stops before any bag is read
    items = plan(bags, world=world, pack=pack, runs=runs)
    options = dict(read_options or {})
    grounds: OrderedDict[Path, _WorldGround] = OrderedDict()
    extra: list[dict] = []        # per bag: the judge's columns (readable ones also get evaluate's)
    plots: list[Optional[dict]] = []
    scratch = tempfile.TemporaryDirectory(prefix="worldgen-judge-")
    names: set[str] = set()
    packs: dict[str, dict[str, Path]] = {}

    def ground(folder: Path) -> _WorldGround:
        key = folder.resolve()
        if key not in grounds:
            grounds[key] = _WorldGround(folder)
            if len(grounds) > _CACHE:
                grounds.popitem(last=False)
        grounds.move_to_end(key)
        return grounds[key]

    def unique(name: str) -> str:
        base, k = name, 2
        while name in names:
            name, k = f"{base}-{k}", k + 1
        names.add(name)
        return name

    def readable() -> Iterator[tuple]:
        for k, item in enumerate(items):
            row: dict[str, Any] = {"bag": str(item.bag), "run": None, "readable": True}
            try:
                folder, task = item.world, item.task
                named = {}
                if folder is None or task is None:
                    from worldgen.ros.reader import peek_metadata
                    named = peek_metadata(item.bag)
                if folder is None:
                    if not named.get("worldgen.world_id"):
                        raise ParameterError(f"bag '{item.bag}': names no world in its metadata (worldgen.world_id); "
                                             "give --world DIR or --runs TABLE")
                    folder = _pack_world(pack, named["worldgen.world_id"], packs)
                g = ground(folder)
                task = task or named.get("worldgen.task")
                got = read_run(item.bag, g, task=task, start=start, **options)
                named = got.metadata.get("worldgen.world_id")
                if named and named != g.meta.get("world_id"):
                    raise ParameterError(f"bag '{item.bag}' was recorded in world {named!r}, "
                                         f"not {g.meta.get('world_id')!r}")
                row["run"] = unique(item.run or got.metadata.get("worldgen.run") or _stem(item.bag))
                row.update(source=got.source, source_detail=got.source_detail, drift_bounded=got.drift_bounded,
                           start=got.start, start_time=got.start_time, world_folder=str(folder))
                extra.append(row)
                points = Path(scratch.name) / f"{len(plots)}.npy"
                np.save(points, _decimate(got.trajectory))
                plots.append({"world": folder, "task": task, "points": points})
                yield got.trajectory, g, task
            except WorldgenError as exc:
                row.update(run=row["run"] or unique(item.run or _stem(item.bag)), readable=False, reason=str(exc),
                           success=False, world_id=None, task=item.task)
                extra.append(row)
                plots.append(None)
            finally:
                if progress is not None:
                    progress(k + 1)

    judged: Optional[dict] = None
    runs_iter = readable()
    try:
        first = next(runs_iter)
    except StopIteration:
        first = None
    if first is not None:
        def chained():
            yield first
            yield from runs_iter
        judged = evaluate(chained(), criteria).to_dict()
    return JudgeResult(_assemble(judged, extra), plots, scratch)


def _stem(bag: Path) -> str:
    return bag.name[: -len(bag.suffix)] if bag.suffix in (".mcap", ".db3", ".bag") else bag.name


def _assemble(judged: Optional[dict], extra: list[dict]) -> dict:
    """Evaluate's report with every bag's row in bag order (unreadable ones included) and the gate's verdict."""
    rows, it = [], iter((judged or {}).get("runs", []))
    for row in extra:
        rows.append((next(it) | row) if row["readable"] else row)
    unreadable = sum(not r["readable"] for r in extra)
    report = dict(judged) if judged else {"passed": False, "failures": [], "summary": {"runs": 0, "successes": 0},
                                          "criteria": []}
    report["runs"] = rows
    report["summary"] = dict(report["summary"]) | {"bags": len(extra), "unreadable": unreadable}
    if unreadable:
        report["failures"] = list(report["failures"]) + [
            f"bags: {unreadable} of {len(extra)} could not be read; a gate does not pass on missing data"]
        report["passed"] = False
    for r in rows:  # JSON has no NaN or inf
        for k, v in r.items():
            if isinstance(v, float) and not math.isfinite(v):
                r[k] = None
    return report
