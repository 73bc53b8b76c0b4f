"""Run a campaign: the strategy proposes points, each point's world is made and run by the system under test,
and each result is told back to the strategy as it arrives.

With ``jobs=1`` and no scheduler the points run one after another in this process: ask, run, tell, so the
campaign is the same for a seed (the same points, worlds and verdicts, given a system that decides the same
way). Otherwise they run on Dask, as pack builds do (a ``LocalCluster`` of ``jobs`` worker processes, or the
dask.distributed cluster at ``scheduler``): as many points are out as there are workers, and each result is
told as it arrives, then the next point asked, so which points are asked depends on the order results come
back in (the worlds of given points and their verdicts do not). Workers write the worlds and the systems'
files into the output folder themselves, so a cluster's workers need that folder on a shared disk.

Every finished point is recorded at once (:mod:`worldgen.campaign.output`), so a kill loses only the points
running then, and a rerun of the same recipe runs those again and goes on to the budget; Ctrl-C raises
:class:`CampaignInterrupted` after writing the tables of every finished run.
"""

from __future__ import annotations

import logging
import shutil
import time
from dataclasses import dataclass
from pathlib import Path
from typing import Any, Optional, Union

from worldgen.campaign.output import (
    asked_points,
    claim_folder,
    load_records,
    refuse_other,
    save_asked,
    save_record,
    write_manifest,
    write_tables,
)
from worldgen.campaign.recipe import CampaignRecipe, load_campaign
from worldgen.campaign.space import Point, cell, descriptors, make_world
from worldgen.campaign.strategies import Strategy
from worldgen.errors import InfeasibleError, ParameterError, WorldgenError
from worldgen.files import RUNS_DIR, WORLDS_DIR

__all__ = ["run", "evaluate", "CampaignSummary", "CampaignInterrupted", "MAX_JOBS", "MAX_BARREN", "CONNECT_TIMEOUT"]

MAX_JOBS = 256
#: Points in a row without a world after which a campaign stops: its space holds (almost) no worlds.
MAX_BARREN = 100
#: How long a campaign waits for a Dask scheduler to answer before it says it cannot reach it.
CONNECT_TIMEOUT = "10s"
_progress = logging.getLogger("worldgen.progress")
_VERDICT_ORDER = ("failed", "passed", "unjudged")


@dataclass
class CampaignSummary:
    points: int = 0
    runs: int = 0
    passed: int = 0
    failed: int = 0
    unjudged: int = 0
    no_world: int = 0
    seconds: float = 0.0
    stopped: str = ""  # why the campaign stopped asking: the budget's runs, its seconds, or a barren space

    def lines(self) -> list[str]:
        return [f"points: {self.points} ({self.no_world} without a world); runs: {self.runs}: {self.failed} failed, "
                f"{self.passed} passed, {self.unjudged} unjudged",
                f"stopped: {self.stopped}; time: {self.seconds:.1f} s"]


class CampaignInterrupted(KeyboardInterrupt):
    """Ctrl-C stopped a campaign; ``summary`` counts what was finished (and recorded) before it."""

    def __init__(self, summary: CampaignSummary):
        super().__init__()
        self.summary = summary

    def line(self) -> str:
        s = self.summary
        return (f"interrupted: {s.runs} runs of {s.points} points are recorded ({s.failed} failed); "
                "rerun the same command to go on to the budget")


def evaluate(point_data: dict, system: Any, out: str) -> dict:
    """Make point ``point_data``'s world, run ``system`` on each of its tasks; the point's record (no search)."""
    point = Point.from_dict(point_data)
    start = time.monotonic()
    world, why = make_world(point)
    if world is None:
        desc = descriptors(point, None)
        return {"point": point.as_dict(), "world_id": None, "folder": None, "reason": why, "descriptors": desc,
                "cell": list(cell(desc)), "runs": [], "verdict": None, "seconds": time.monotonic() - start}
    folder = world.write(Path(out) / WORLDS_DIR, preview=False)
    meta = world.metadata
    runs = []
    for task in meta["tasks"]:
        name = f"p{point.index:05d}"
        workdir = Path(out) / RUNS_DIR / f"{world.world_id}__{task['id']}__{name}"
        workdir.mkdir(parents=True, exist_ok=True)
        try:
            got = system.run(folder, task["id"], name, workdir)
            verdict, reason, row, seconds = got.verdict, got.reason, dict(got.row), float(got.seconds)
        except WorldgenError as exc:  # the system could not be run: never the robot's failure
            verdict, reason, row, seconds = "unjudged", " ".join(str(exc).split()), {}, 0.0
        runs.append({"task": task["id"], "run": name, "verdict": verdict, "reason": reason, "row": row,
                     "seconds": seconds})
    desc = descriptors(point, meta)
    verdict = next((v for v in _VERDICT_ORDER if any(r["verdict"] == v for r in runs)), "unjudged")
    return {"point": point.as_dict(), "world_id": world.world_id, "folder": f"{WORLDS_DIR}/{folder.name}", "reason": "",
            "descriptors": desc, "cell": list(cell(desc)), "runs": runs, "verdict": verdict,
            "seconds": time.monotonic() - start}


def run(recipe: Union[CampaignRecipe, str, Path], out, *, jobs: int = 1, scheduler: Optional[str] = None,
        system: Any = None, report: bool = True, shrink: bool = True) -> CampaignSummary:
    """Run (or resume) ``recipe`` into ``out``; return the summary.

    ``system``: a System object to test instead of the recipe's ``system:`` block. ``report``: write the
    failure map and report.md at the end (``shrink``: with each distinct failure shrunk; it runs the system
    again on smaller worlds). Bad input (the recipe, the system, an output folder holding something else)
    is a ParameterError before anything is written.
    """
    import worldgen

    recipe = recipe if isinstance(recipe, CampaignRecipe) else load_campaign(recipe)
    if isinstance(jobs, bool) or not isinstance(jobs, int) or not 1 <= jobs <= MAX_JOBS:
        raise ParameterError(f"parameter 'jobs' must be an integer in [1, {MAX_JOBS}], got {jobs!r}")
    out = Path(out)
    refuse_other(out, recipe)
    system = system if system is not None else _system(recipe)
    strategy = Strategy(recipe.strategy, recipe.seed, recipe.entries)
    created = _first_missing(out)
    claim_folder(out, recipe)
    loop = _Loop(recipe, out, strategy, system)
    try:
        if jobs == 1 and scheduler is None:
            loop.in_process()
        else:
            loop.on_dask(jobs, scheduler)
    except WorldgenError:
        # A scheduler out of reach, a missing extra: a folder this call created and nothing finished in it goes
        # again, so a mistake leaves nothing written. Finished runs are never removed.
        if created is not None and not loop.summary.points:
            shutil.rmtree(created, ignore_errors=True)
        raise
    except KeyboardInterrupt as exc:
        loop.finish(worldgen.__version__, complete=False)
        raise CampaignInterrupted(loop.summary) from exc
    records = loop.finish(worldgen.__version__, complete=True)
    if not loop.summary.runs:
        raise InfeasibleError(f"campaign '{recipe.name}': no point of its space made a world "
                              f"({loop.summary.no_world} tried); the first refusal: {records[0]['reason'] if records else ''}")
    if report:
        from worldgen.campaign.report import write_report

        write_report(out, records, system=system if shrink else None)
    return loop.summary


def _first_missing(path: Path) -> Optional[Path]:
    """The outermost folder on the way to ``path`` that does not exist yet (None: ``path`` exists)."""
    missing = None
    while not path.exists() and path.parent != path:
        missing, path = path, path.parent
    return missing


def _system(recipe: CampaignRecipe):
    if recipe.system is None:
        raise ParameterError(f"campaign '{recipe.name}' has no 'system:' block and no system was given")
    from worldgen.campaign.systems import system_from_spec

    return system_from_spec(recipe.system, criteria=recipe.verdict)


class _Loop:
    """One process's part of a campaign: the records so far, the budget, asking and telling."""

    def __init__(self, recipe: CampaignRecipe, out: Path, strategy: Strategy, system: Any):
        self.recipe, self.out, self.strategy, self.system = recipe, out, strategy, system
        finished = load_records(out)
        self.pending = asked_points(out, (r["point"]["index"] for r in finished))
        indexes = [r["point"]["index"] for r in finished] + [p["point"]["index"] for p in self.pending]
        strategy.restore(finished, max(indexes, default=-1) + 1)
        self.summary = CampaignSummary()
        for rec in finished:
            self.count(rec)
        self.barren, self.out_now, self.start = 0, 0, time.monotonic()

    def count(self, rec: dict) -> None:
        s = self.summary
        s.points += 1
        s.no_world += rec.get("world_id") is None
        for r in rec["runs"]:
            s.runs += 1
            setattr(s, r["verdict"], getattr(s, r["verdict"]) + 1)

    def more(self) -> bool:
        """Whether the budget allows asking one more point (points still out count as one run each)."""
        r = self.recipe
        if r.runs is not None and self.summary.runs + self.out_now >= r.runs:
            self.summary.stopped = f"the budget's {r.runs} runs"
        elif r.seconds is not None and time.monotonic() - self.start >= r.seconds:
            self.summary.stopped = f"the budget's {r.seconds:g} s"
        elif self.barren >= MAX_BARREN:
            self.summary.stopped = f"{MAX_BARREN} points in a row made no world"
        else:
            return True
        return False

    def ask(self) -> tuple[dict, dict]:
        if self.pending:
            rec = self.pending.pop(0)
            return rec["point"], rec["search"]
        point, search = self.strategy.ask()
        save_asked(self.out, point.as_dict(), search)
        return point.as_dict(), search

    def told(self, result: dict, search: dict) -> None:
        rec = dict(result, search=search)
        save_record(self.out, rec)
        self.strategy.tell(rec["point"]["index"], search, rec["verdict"], tuple(rec["cell"]))
        self.count(rec)
        self.barren = self.barren + 1 if rec.get("world_id") is None else 0
        s = self.summary
        _progress.info("campaign %s: %d runs (%d failed, %d unjudged), %d points without a world", self.recipe.name,
                       s.runs, s.failed, s.unjudged, s.no_world)

    def in_process(self) -> None:
        while self.pending or self.more():
            point, search = self.ask()
            self.told(evaluate(point, self.system, str(self.out)), search)

    def on_dask(self, jobs: int, scheduler: Optional[str]) -> None:
        from worldgen.errors import require_optional

        require_optional("distributed", "dask", "a campaign with --jobs > 1 or a scheduler runs on dask.distributed")
        from distributed import Client, LocalCluster, as_completed

        cluster = None
        try:
            if scheduler is None:
                cluster = LocalCluster(n_workers=jobs, threads_per_worker=1, processes=True, dashboard_address=None,
                                       silence_logs=logging.ERROR)
            client = Client(scheduler or cluster, timeout=CONNECT_TIMEOUT)
        except (OSError, TimeoutError) as exc:
            if cluster is not None:
                cluster.close()
            raise ParameterError(f"--scheduler {scheduler}: cannot reach the dask scheduler ({exc})") from None
        try:
            width = jobs if scheduler is None else max(sum(client.nthreads().values()), 1)
            futures = as_completed()
            searches: dict[Any, dict] = {}

            def submit() -> None:
                point, search = self.ask()
                fut = client.submit(evaluate, point, self.system, str(self.out.resolve()), pure=False)
                searches[fut] = search
                futures.add(fut)
                self.out_now += 1

            while len(searches) < width and (self.pending or self.more()):
                submit()
            for fut in futures:
                search = searches.pop(fut)
                self.out_now -= 1
                self.told(fut.result(), search)
                if self.pending or self.more():
                    submit()
        finally:
            client.close()
            if cluster is not None:
                cluster.close()

    def finish(self, version: str, complete: bool) -> list[dict]:
        self.summary.seconds = time.monotonic() - self.start
        records = load_records(self.out)
        write_tables(self.out, records, self.strategy.state())
        write_manifest(self.out, self.recipe, records, version, complete)
        return records
