"""Recorded bags plus the worlds they ran in, judged against acceptance criteria: ``worldgen judge``.

Usage (an example that runs is in :mod:`worldgen.ros`)::

    result = judge(["runs/r0", "runs/r1"], "criteria.yaml", world="worlds/cluttered-s0-1f3a9c0b")
    result.passed, result.report["summary"]["unjudged"]
    write_report(result, "report/")          # worldgen.judge.report

Which world a bag ran in, in order of precedence:

- ``runs``: a CSV table with columns ``bag`` and ``world`` (a world id of ``pack``, or a world
  folder), optional ``task`` and ``run``; relative paths are relative to the table's folder;
- ``world``: one world for every bag: a world folder, a :class:`~worldgen.World` or a pack's world;
- ``pack``: the world whose id the bag names in its metadata (``custom_data``
  ``worldgen.world_id``, which :func:`worldgen.ros.write_run` and the ROS 2 bundle's
  launch file record).

A bag that names a world in its metadata is checked against the world it is judged in.
Each bag is read (streamed) as its turn comes and only its figures are kept, so a batch
of thousands holds one bag at a time. Each row's ``outcome`` is ``success``, ``failure`` or
``unjudged``: a bag that cannot be read, or whose world cannot be found, has no verdict
(``success`` None, ``readable`` False, its ``reason``); it is counted in ``summary.unjudged``, left
out of every rate, and the verdict does not pass while any bag is unjudged: a gate must not pass
on missing data. A bag that reads but whose run is not its task's (it starts far from the spawn,
or names another world) is a failed run with that reason.
"""

from __future__ import annotations

import csv
import math
import tempfile
from collections import OrderedDict
from dataclasses import dataclass, field, replace
from pathlib import Path
from typing import Any, Callable, Iterator, Optional, Sequence

import numpy as np

from worldgen.errors import ParameterError, WorldgenError, read_user_text
from worldgen.files import MANIFEST_NAME
from worldgen.groundtruth.folder import is_world_folder, open_world
from worldgen.groundtruth.ground import Ground, load

__all__ = ["Item", "JudgeResult", "judge", "plan", "PLOT_POINTS", "DEFAULT_CRITERIA"]

#: The gate when no criteria are given: every run reaches its goal within its time limit and touches nothing.
DEFAULT_CRITERIA = {"navigation": {"success_rate": 1.0}}

#: Most points of a run kept for its picture (decimated evenly in path length; the figures use every sample).
PLOT_POINTS = 400
#: Worlds whose colliders are kept between bags of one batch (bags usually come grouped by world).
_CACHE = 8


@dataclass(frozen=True)
class Item:
    """One bag to judge: the bag, its world (a folder, or a World or pack world; None: from the bag's metadata),
    task and run id."""

    bag: Path
    world: Any
    task: Optional[str]
    run: Optional[str]


@dataclass
class JudgeResult:
    """The report (``Report.to_dict()`` with every bag's row) and what its pictures need, per run.

    The points each picture is drawn from wait in a scratch folder (removed with the result), not in
    memory: a batch holds its report rows and nothing per bag beside them.
    """

    report: dict
    plots: list[Optional[dict]]   # per row: world (folder or World), task, the .npy of its (m, 3) t, x, y; None when unreadable
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
        opened = open_world(world, "--world")
        folder = opened.path if isinstance(world, (str, Path)) else world
        if opened.path is None and getattr(world, "feasibility", None) is None and not _archived(world):
            raise ParameterError(f"--world: {opened.label} has no folder on disk to read its scenario.yaml from, "
                                 "nor a World's scenario to build; write it first")
    elif pack is None:
        raise ParameterError("say where the worlds are: --world DIR, --pack DIR (worlds named in the bags' metadata) "
                             "or --runs TABLE")
    return [Item(Path(b), folder, None, None) for b in bags]


def _index(pack) -> dict[str, Path]:
    """world id -> world folder of a built pack, or of a folder of world folders (``worldgen generate --out``)."""
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
    for sub in sorted(p for p in root.iterdir() if is_world_folder(p)):
        try:
            found[open_world(sub).world_id] = sub
        except ParameterError:
            continue  # not a readable world folder: the lookup reports the id as missing
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
        if is_world_folder(candidate):
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


def _run_name(world_id: str, task: str, index: Optional[str], taken: set[str]) -> str:
    """``<world>__<task>__run<k>``: readable, and unique across worlds (the bundle's run index counts per world).

    ``k`` is the run's own index (the table's ``run``, the bag's ``worldgen.run``), else the first free one;
    a run named by a word rather than a number keeps the word (``<world>__<task>__<name>``)."""
    if index is not None:
        index = str(index)
        return _unique(f"{world_id}__{task}__{'run' if index.isdigit() else ''}{index}", taken)
    k = 0
    while f"{world_id}__{task}__run{k}" in taken:
        k += 1
    return _unique(f"{world_id}__{task}__run{k}", taken)


def judge(bags: Sequence = (), criteria: Any = None, *, world=None, pack=None, runs=None,
          start: str = "command", read_options: Optional[dict] = None,
          progress: Optional[Callable[[int], None]] = None) -> JudgeResult:
    """Read every bag, judge the readable runs with :func:`worldgen.judge.evaluate.evaluate`, and return the report.

    ``read_options`` go to :func:`worldgen.ros.reader.read_run` (topic and frame names,
    ``spawn_tolerance``, ``distro``...). ``progress(k)`` is called after each bag. Without
    ``criteria`` the gate is :data:`DEFAULT_CRITERIA`: every run meets its scenario, so a batch of
    crashed runs never passes for want of a criteria file. Each row's ``outcome`` is ``success``,
    ``failure`` (judged, and it failed: a run that started far from its spawn or names another world
    too) or ``unjudged`` (the bag could not be read, or its world not found: no verdict at all).
    """
    from worldgen.judge.evaluate import evaluate, load_criteria

    if criteria is None:
        criteria = DEFAULT_CRITERIA
    load_criteria(criteria)  # a mistake in the criteria stops before any bag is read
    batch = _Batch(plan(bags, world=world, pack=pack, runs=runs), pack, dict(read_options or {}), start, progress)
    report: Optional[dict] = None
    runs_iter = batch.judged()
    try:
        first = next(runs_iter)
    except StopIteration:
        first = None
    if first is not None:
        def chained():
            yield first
            yield from runs_iter
        report = evaluate(chained(), criteria).to_dict()
    return JudgeResult(_assemble(report, batch.extra), batch.plots, batch.scratch)


class _Batch:
    """One call of :func:`judge` as it reads its bags: each world's ground truth (the last :data:`_CACHE` kept),
    per bag its row of the judge's columns (``extra``; judged ones also get evaluate's) and its picture's data
    (``plots``), and the run names taken."""

    def __init__(self, items: list[Item], pack, options: dict, start: str, progress: Optional[Callable[[int], None]]):
        self.items, self.pack, self.options, self.start, self.progress = items, pack, options, start, progress
        self.packs: dict[str, dict[str, Path]] = {}
        if pack is not None:  # a pack that is missing or holds no world is a usage mistake, not 20 unjudged bags
            self.packs[str(pack)] = _index(pack)
        self.grounds: OrderedDict[Any, Ground] = OrderedDict()
        self.extra: list[dict] = []
        self.plots: list[Optional[dict]] = []
        self.scratch = tempfile.TemporaryDirectory(prefix="worldgen-judge-")
        if items and _archived(items[0].world):  # evaluate reads scenario.yaml from a folder: the world's, extracted
            archived = items[0].world
            folder = archived.pack.source.extract_folder(archived.folder, Path(self.scratch.name) / "world")
            self.items = [replace(item, world=folder) for item in items]
        self.names: set[str] = set()

    def ground(self, world) -> Ground:
        key = world.resolve() if isinstance(world, Path) else id(world)  # a World or pack world: the object itself
        if key not in self.grounds:
            self.grounds[key] = load(world)
            if len(self.grounds) > _CACHE:
                self.grounds.popitem(last=False)
        self.grounds.move_to_end(key)
        return self.grounds[key]

    def judged(self) -> Iterator[Any]:
        """What evaluate judges, bag by bag: (trajectory, ground, task) of a run, or a refused run; a bag that
        cannot be read, or whose world is not found, gets its unjudged row instead."""
        for k, item in enumerate(self.items):
            row: dict[str, Any] = {"bag": str(item.bag), "run": None, "readable": True}
            try:
                yield from self._read(item, row)
            except WorldgenError as exc:
                row.update(run=row["run"] or _unique(_stem(item.bag), self.names), readable=False, outcome="unjudged",
                           reason=str(exc), success=None, world_id=None, task=item.task)
                self.extra.append(row)
                self.plots.append(None)
            finally:
                if self.progress is not None:
                    self.progress(k + 1)

    def _read(self, item: Item, row: dict[str, Any]) -> Iterator[Any]:
        """One bag read in its world, its row filled in: the run, or a refused run (read, and not this task's)."""
        from worldgen.ros.reader import RunMismatchError, peek_metadata, read_run

        named = peek_metadata(item.bag)
        folder, task = item.world, item.task or named.get("worldgen.task")
        if folder is None:
            if not named.get("worldgen.world_id"):
                raise ParameterError(f"bag '{item.bag}': names no world in its metadata (worldgen.world_id); "
                                     "give --world DIR or --runs TABLE")
            folder = _pack_world(self.pack, named["worldgen.world_id"], self.packs)
        g = self.ground(folder)
        world_id, task_id = str(g.meta.get("world_id")), g.task(task)["id"]
        row["run"] = _run_name(world_id, task_id, item.run or named.get("worldgen.run"), self.names)
        # None where the world has no folder of its own: an unwritten World, an archive's world extracted
        row["world_folder"] = None if g.path is None or Path(self.scratch.name) in g.path.parents else str(g.path)
        try:
            _same_world(item.bag, named, world_id)
            got = read_run(item.bag, g, task=task, start=self.start, **self.options)
            _same_world(item.bag, got.metadata, world_id)  # a bare storage file carries its own
            if item.run is None and not named.get("worldgen.run") and got.metadata.get("worldgen.run"):
                self.names.discard(row["run"])
                row["run"] = _run_name(world_id, task_id, got.metadata["worldgen.run"], self.names)
        except RunMismatchError as exc:  # read, and not this task's run: a failure, not missing data
            self.extra.append(row)
            self.plots.append(None)
            yield {"world": g, "task": task, "refused": str(exc)}
            return
        row.update(source=got.source, source_detail=got.source_detail, drift_bounded=got.drift_bounded,
                   start=got.start, start_time=got.start_time)
        self.extra.append(row)
        points = Path(self.scratch.name) / f"{len(self.plots)}.npy"
        np.save(points, _decimate(got.trajectory))
        self.plots.append({"world": folder, "task": task, "points": points})
        # evaluate reads the run's scenario from the world's folder, or builds it from an unwritten World
        yield got.trajectory, g if g.path is not None else folder, task


def _archived(world) -> bool:
    """Whether ``world`` is a world inside a pack archive (a PackWorld with no folder on disk)."""
    return bool(getattr(getattr(world, "pack", None), "archive", False))


def _same_world(bag: Path, metadata: dict, world_id: str) -> None:
    """RunMismatchError when the bag's metadata names a world other than the one it is judged in."""
    from worldgen.ros.reader import RunMismatchError

    claimed = metadata.get("worldgen.world_id")
    if claimed and claimed != world_id:
        raise RunMismatchError(f"bag '{bag}' was recorded in world {claimed!r}, not {world_id!r}")


def _unique(name: str, taken: set[str]) -> str:
    base, k = name, 2
    while name in taken:
        name, k = f"{base}-{k}", k + 1
    taken.add(name)
    return name


def _stem(bag: Path) -> str:
    return bag.name[: -len(bag.suffix)] if bag.suffix in (".mcap", ".db3", ".bag") else bag.name


def _assemble(judged: Optional[dict], extra: list[dict]) -> dict:
    """Evaluate's report with every bag's row in bag order (unjudged ones included) and the gate's verdict."""
    rows, it = [], iter((judged or {}).get("runs", []))
    for row in extra:
        if row["readable"]:
            row = next(it) | row
            row["outcome"] = "success" if row.get("success") else "failure"
        rows.append(row)
    unjudged = sum(r["outcome"] == "unjudged" for r in rows)
    report: dict[str, Any] = dict(judged) if judged else {"passed": False, "failures": [], "summary": {"runs": 0, "successes": 0},
                                          "criteria": []}
    report["runs"] = rows
    report["summary"] = dict(report["summary"]) | {"bags": len(extra), "unjudged": unjudged}
    if unjudged:
        report["failures"] = list(report["failures"]) + [
            f"bags: {unjudged} of {len(extra)} could not be judged; a gate does not pass on missing data"]
        report["passed"] = False
    for r in rows:  # JSON has no NaN or inf
        for k, v in r.items():
            if isinstance(v, float) and not math.isfinite(v):
                r[k] = None
    return report
