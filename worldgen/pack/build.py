"""Build a pack from a recipe: in parallel, resumable after a kill or Ctrl-C, manifest last.

Layout of PACK::

    PACK/worlds/<world_id>/...   one folder per world (complete or absent)
    PACK/.build/<job key>.json   a record per finished job (built or rejected), written
                                 atomically just before its folder is renamed into place
    PACK/index.csv, PACK/manifest.json   written last, atomically, from the records

A rerun of the same recipe skips every job that has a record and a folder, so a
build killed at any moment finishes without redoing or duplicating worlds. A job
recorded but killed before its folder landed is simply built again: the same job
gives the same bytes. Each local worker records and writes its own jobs, so what a
worker finished is on disk whatever happens to the parent; Ctrl-C stops the pool
(:meth:`_Run.in_pool`) within about a second.
"""

from __future__ import annotations

import json
import multiprocessing
import shutil
import signal
import threading
import time
from collections import Counter
from contextlib import contextmanager
from dataclasses import dataclass, field
from functools import partial
from pathlib import Path
from typing import Iterator, Optional, TextIO

from worldgen.errors import InfeasibleError, OutputError, ParameterError, WorldgenError
from worldgen.export.formats import require_formats
from worldgen.files import BUILD_STATE_DIR, INDEX_NAME, MANIFEST_NAME, WORLDS_DIR, write_atomically
from worldgen.pack.manifest import build_manifest, index_bytes, manifest_bytes, world_folder
from worldgen.pack.recipe import Recipe
from worldgen.pack.render import build_job, init_worker, save_job

__all__ = ["build_pack", "BuildSummary", "BuildInterrupted", "GRACE_SECONDS"]
MAX_JOBS = 256
#: After Ctrl-C, how long the jobs already running may take to finish before their workers are stopped.
GRACE_SECONDS = 1.0
#: build_job's arguments after the job, by name (the pool passes them to every job).
_JOB_ARGS = ("worlds_dir", "state_dir", "formats", "sdf_version", "preview", "ros")


@dataclass
class BuildSummary:
    total: int = 0
    built: int = 0
    skipped: int = 0  # finished by an earlier run
    rejected_jobs: int = 0
    rejected_draws: Counter = field(default_factory=Counter)  # check name -> draws
    extra_draws: int = 0  # draws of built worlds that failed a check before one passed
    stale: int = 0  # world folders of an earlier recipe removed
    seconds: float = 0.0

    @property
    def rate(self) -> float:
        return self.built / self.seconds if self.seconds > 0 else 0.0

    def lines(self) -> list[str]:
        why = ", ".join(f"{k} {v}x" for k, v in sorted(self.rejected_draws.items())) or "none"
        return [
            f"worlds built: {self.built} (+{self.skipped} from an earlier run) of {self.total} jobs",
            f"jobs rejected as infeasible: {self.rejected_jobs}; failed draws of those: {why}",
            f"extra draws before a feasible one (max_attempts retries): {self.extra_draws}",
            f"time: {self.seconds:.2f} s, {self.rate:.1f} worlds/s",
        ] + ([f"removed {self.stale} world folder(s) an earlier recipe left in the pack"] if self.stale else [])


def build_pack(recipe: Recipe, out, jobs: int = 1, progress: Optional[TextIO] = None,
               version: Optional[str] = None, executor: str = "local",
               scheduler: Optional[str] = None) -> BuildSummary:
    """Build (or finish building) ``recipe`` into ``out``; return the summary.

    ``progress``: a stream for the progress line, or None (quiet). ``executor``
    "local" (a process pool of ``jobs``) or "dask" (the dask.distributed cluster
    at ``scheduler``; see :mod:`worldgen.pack.dask`). Ctrl-C raises
    :class:`BuildInterrupted` within about :data:`GRACE_SECONDS`, with every
    finished world recorded, so a rerun builds only what was cut off.
    """
    import worldgen

    _check_options(jobs, executor, scheduler)
    require_formats(recipe.formats)  # a missing extra (usd) stops the build before any folder is made
    version = version or worldgen.__version__
    out = Path(out)
    created = _first_missing(out)
    try:
        run = _Run(recipe, out, progress)
        run.execute(jobs, executor, scheduler, version)
        _write_manifest(recipe, out, run.records, run.summary, version)
    except WorldgenError:
        # No pack (no world made, two jobs making one world, a scheduler out of reach): a folder
        # this build created goes again, so nothing half-written is left. One that was there
        # before keeps what earlier runs recorded. Ctrl-C is no WorldgenError: its progress stays.
        if created is not None:
            shutil.rmtree(created, ignore_errors=True)
        raise
    return run.summary


def _first_missing(path: Path) -> Optional[Path]:
    """The outermost folder on the way to ``path`` that does not exist yet (None: ``path`` exists)."""
    missing = None
    while not path.exists() and path.parent != path:
        missing, path = path, path.parent
    return missing


class BuildInterrupted(KeyboardInterrupt):
    """Ctrl-C stopped a build; ``summary`` counts what was finished (and recorded) before it."""

    def __init__(self, summary: BuildSummary):
        super().__init__()
        self.summary = summary

    def line(self) -> str:
        s = self.summary
        return (f"interrupted: {s.built + s.rejected_jobs + s.skipped} of {s.total} jobs are done and recorded "
                f"({s.built} built now); rerun the same command to build the rest")


def _check_options(jobs: int, executor: str, scheduler: Optional[str]) -> None:
    if not 1 <= jobs <= MAX_JOBS:
        raise ParameterError(f"parameter 'jobs' must be in [1, {MAX_JOBS}], got {jobs}")
    if executor not in ("local", "dask"):
        raise ParameterError(f"parameter 'executor' must be one of local, dask, got {executor!r}")
    if scheduler is not None and executor != "dask":
        raise ParameterError(f"parameter 'scheduler' applies only with executor dask (--executor dask), got {scheduler!r}")


class _Run:
    """One run of a build: the pack's folders, the records so far, the jobs still to do, the counts."""

    def __init__(self, recipe: Recipe, out: Path, progress: Optional[TextIO]):
        self.recipe, self.out = recipe, out
        self.state, self.worlds_dir = out / BUILD_STATE_DIR, out / WORLDS_DIR
        try:
            self.state.mkdir(parents=True, exist_ok=True)
            self.worlds_dir.mkdir(exist_ok=True)
        except OSError as exc:
            raise OutputError(f"cannot write pack folder '{out}': {exc.strerror or exc}") from None
        _remove_leftovers(self.worlds_dir, self.state)
        self.records = _load_records(self.state, recipe)
        self.todo = [j for j in recipe.jobs if j.key not in self.records]
        self.summary = BuildSummary(total=len(recipe.jobs), skipped=len(recipe.jobs) - len(self.todo))
        self.start = time.monotonic()
        self.bar = _Progress(progress, len(self.todo))
        self.render_args = (recipe.formats, recipe.sdf_version, recipe.preview, recipe.ros)
        self.job_args = (str(self.worlds_dir), str(self.state), *self.render_args)

    def execute(self, jobs: int, executor: str, scheduler: Optional[str], version: str) -> None:
        """Run the jobs still to do; Ctrl-C becomes BuildInterrupted with the counts so far."""
        try:
            if executor == "dask":
                self.on_dask(scheduler, version)
            elif jobs == 1 or len(self.todo) <= 1:
                self.in_process()
            else:
                self.in_pool(jobs)
        except KeyboardInterrupt as exc:
            raise BuildInterrupted(self.stop()) from exc
        self.stop()

    def stop(self) -> BuildSummary:
        self.bar.done()
        self.summary.seconds = time.monotonic() - self.start
        return self.summary

    def finished(self, rec: Optional[dict]) -> None:
        """Count a job whose record is on disk (None: a job the cancel kept from starting)."""
        if rec is None:
            return
        self.records[rec["key"]] = rec
        if rec.get("world_id"):
            self.summary.built += 1
            self.summary.extra_draws += rec["attempts"] - 1
        else:
            self.summary.rejected_jobs += 1
            self.summary.rejected_draws.update(rec["failures"])
        self.bar.step()

    def in_process(self) -> None:
        for job in self.todo:
            self.finished(build_job(job, *self.job_args))

    def on_dask(self, scheduler: Optional[str], version: str) -> None:
        from worldgen.pack.dask import run_on_dask

        # The folders are written here, so workers need no access to the pack's disk.
        for rec, blobs in run_on_dask(self.todo, scheduler, self.render_args, version):
            save_job(rec, blobs, self.worlds_dir, self.state)
            self.finished(rec)

    def in_pool(self, jobs: int) -> None:
        """A local process pool. On Ctrl-C: no job starts any more, the ones running get
        GRACE_SECONDS to finish (each records itself), then the workers are stopped."""
        ctx = multiprocessing.get_context("fork" if "fork" in multiprocessing.get_all_start_methods() else None)
        stop = ctx.Event()
        with _sigint_deferred():  # a worker forked while Ctrl-C arrives must not die with a traceback
            pool = ctx.Pool(jobs, initializer=init_worker, initargs=(stop,))
        try:
            results = pool.imap_unordered(partial(build_job, **dict(zip(_JOB_ARGS, self.job_args))), self.todo)
            try:
                for rec in results:
                    self.finished(rec)
            except KeyboardInterrupt:
                stop.set()
                self._drain(results, time.monotonic() + GRACE_SECONDS)
                raise
        finally:
            pool.terminate()  # returns once the workers have exited
            _remove_leftovers(self.worlds_dir, self.state)  # a worker stopped mid-write left a hidden folder

    def _drain(self, results, deadline: float) -> None:
        """Count the jobs that finish before ``deadline``; the rest are cut off."""
        try:
            while True:
                self.finished(results.next(timeout=max(0.0, deadline - time.monotonic())))
        except (StopIteration, multiprocessing.TimeoutError):
            pass


def _write_manifest(recipe: Recipe, out: Path, records: dict[str, dict], summary: BuildSummary, version: str) -> None:
    """index.csv, then manifest.json (last: its presence means the pack is complete)."""
    manifest = build_manifest(recipe, records.values(), version)
    _check_unique(manifest)
    if not manifest["worlds"]:
        why = ", ".join(f"{k} {v}x" for k, v in sorted(summary.rejected_draws.items())) or "no draws"
        raise InfeasibleError(f"no job of recipe '{recipe.name}' made a world ({len(recipe.jobs)} rejected; "
                              f"failed draws: {why}); the pack was not written")
    folders = {world_folder(w).split("/", 1)[1] for w in manifest["worlds"]}
    summary.stale = _remove_stale(out, folders, {j.key for j in recipe.jobs})
    write_atomically(out / INDEX_NAME, index_bytes(manifest))
    write_atomically(out / MANIFEST_NAME, manifest_bytes(manifest))


@contextmanager
def _sigint_deferred() -> Iterator[None]:
    """Hold Ctrl-C back (blocked, not lost) while worker processes are forked."""
    if not hasattr(signal, "pthread_sigmask") or threading.current_thread() is not threading.main_thread():
        yield
        return
    signal.pthread_sigmask(signal.SIG_BLOCK, {signal.SIGINT})
    try:
        yield
    finally:
        signal.pthread_sigmask(signal.SIG_UNBLOCK, {signal.SIGINT})


def _load_records(state: Path, recipe: Recipe) -> dict[str, dict]:
    """Records of an earlier run of this recipe; a record of another recipe's job is ignored."""
    wanted = {j.key: j for j in recipe.jobs}
    out = {}
    for path in sorted(state.glob("*.json")):
        key = path.stem
        if key not in wanted:
            continue
        try:
            rec = json.loads(path.read_text())
        except (OSError, ValueError):
            continue  # cannot happen with atomic writes; rebuilt if it does
        rec["job"] = wanted[key].index  # the index in this recipe
        if rec.get("world_id") and not (state.parent / WORLDS_DIR / rec.get("folder", rec["world_id"])).is_dir():
            continue
        out[key] = rec
    return out


def _remove_stale(out: Path, folders: set[str], keys: set[str]) -> int:
    """Remove world folders and job records an earlier recipe left in the pack; return how many worlds."""
    stale = [p for p in (out / WORLDS_DIR).iterdir() if not p.name.startswith(".") and p.name not in folders]
    for p in stale:
        shutil.rmtree(p) if p.is_dir() and not p.is_symlink() else p.unlink()
    for p in (out / BUILD_STATE_DIR).glob("*.json"):
        if p.stem not in keys:
            p.unlink()
    return len(stale)


def _remove_leftovers(worlds_dir: Path, state: Path) -> None:
    """Temporary folders and files a killed build left behind (hidden: names start with '.')."""
    for folder in (worlds_dir, state, state.parent):
        for p in sorted(folder.glob(".*.tmp")) + sorted(folder.glob(".*.old")):
            if p.is_dir():
                shutil.rmtree(p, ignore_errors=True)
            else:
                p.unlink(missing_ok=True)


def _check_unique(manifest: dict) -> None:
    seen: dict[str, int] = {}
    for w in manifest["worlds"]:
        if w["world_id"] in seen:
            raise ParameterError(
                f"recipe jobs {seen[w['world_id']]} and {w['job']} make the same world {w['world_id']}: "
                "their parameters differ only where the scene does not; drop one of them")
        seen[w["world_id"]] = w["job"]


class _Progress:
    """``[ 120/1000]  35.2 worlds/s  ETA 25 s`` redrawn in place; silent without a stream."""

    def __init__(self, stream: Optional[TextIO], total: int):
        self.stream, self.total, self.count = stream, total, 0
        self.start = time.monotonic()
        self.last = 0.0

    def step(self) -> None:
        self.count += 1
        now = time.monotonic()
        if self.stream is not None and (now - self.last > 0.1 or self.count == self.total):
            self.last = now
            rate = self.count / max(now - self.start, 1e-9)
            eta = (self.total - self.count) / rate if rate > 0 else 0.0
            width = len(str(self.total))
            self.stream.write(f"\r[{self.count:>{width}}/{self.total}] {rate:6.1f} worlds/s  ETA {eta:5.0f} s")
            self.stream.flush()

    def done(self) -> None:
        if self.stream is not None and self.count:
            self.stream.write("\n")
            self.stream.flush()
