"""Build a pack from a recipe: in parallel, resumable after a kill, manifest last.

Layout of PACK::

    PACK/worlds/<world_id>/...   one folder per world (World.write: complete or absent)
    PACK/.build/<job key>.json   a record per finished job (built or rejected), written
                                 atomically after its folder exists
    PACK/index.csv, PACK/manifest.json   written last, atomically, from the records

A rerun of the same recipe skips every job that has a record, so a build killed
at any moment finishes without redoing or duplicating worlds. A job whose folder
was renamed into place but whose record was not yet written is simply built
again: the same job gives the same bytes, and the folder is replaced atomically.
Workers write their world folders themselves; only the parent writes records.
"""

from __future__ import annotations

import json
import multiprocessing
import shutil
import time
from collections import Counter
from concurrent.futures import ProcessPoolExecutor, as_completed
from dataclasses import dataclass, field
from pathlib import Path
from typing import Optional, TextIO

from worldgen.errors import InfeasibleError, OutputError, ParameterError
from worldgen.files import INDEX_NAME, MANIFEST_NAME, WORLDS_DIR, write_atomically, write_folder_atomically
from worldgen.pack.manifest import build_manifest, index_bytes, manifest_bytes, world_folder
from worldgen.pack.recipe import Recipe
from worldgen.pack.render import build_job

__all__ = ["build_pack", "BuildSummary", "STATE_DIR"]

STATE_DIR = ".build"
MAX_JOBS = 256


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
    at ``scheduler``; see :mod:`worldgen.pack.dask`).
    """
    import worldgen

    if not 1 <= jobs <= MAX_JOBS:
        raise ParameterError(f"parameter 'jobs' must be in [1, {MAX_JOBS}], got {jobs}")
    if executor not in ("local", "dask"):
        raise ParameterError(f"parameter 'executor' must be one of local, dask, got {executor!r}")
    if scheduler is not None and executor != "dask":
        raise ParameterError(f"parameter 'scheduler' applies only with executor dask (--executor dask), got {scheduler!r}")
    out = Path(out)
    state = out / STATE_DIR
    worlds_dir = out / WORLDS_DIR
    try:
        state.mkdir(parents=True, exist_ok=True)
        worlds_dir.mkdir(exist_ok=True)
    except OSError as exc:
        raise OutputError(f"cannot write pack folder '{out}': {exc.strerror or exc}") from None
    _remove_leftovers(worlds_dir, state)
    records = _load_records(state, recipe)
    todo = [j for j in recipe.jobs if j.key not in records]
    summary = BuildSummary(total=len(recipe.jobs), skipped=len(recipe.jobs) - len(todo))
    start = time.monotonic()
    bar = _Progress(progress, len(todo))
    args = (str(worlds_dir), recipe.formats, recipe.sdf_version, recipe.preview)

    def finished(rec: dict) -> None:
        job = recipe.jobs[rec["job"]]
        write_atomically(state / f"{job.key}.json", json.dumps(rec, sort_keys=True).encode())
        records[job.key] = rec
        if rec.get("world_id"):
            summary.built += 1
            summary.extra_draws += rec["attempts"] - 1
        else:
            summary.rejected_jobs += 1
            summary.rejected_draws.update(rec["failures"])
        bar.step()

    if executor == "dask":
        from worldgen.pack.dask import run_on_dask

        for rec, blobs in run_on_dask(todo, scheduler, args[1:], version or worldgen.__version__):
            if blobs:  # the folder is written here, so workers need no access to the pack's disk
                write_folder_atomically(worlds_dir, rec["folder"], blobs)
            finished(rec)
    elif jobs == 1 or len(todo) <= 1:
        for job in todo:
            finished(build_job(job, *args))
    else:
        ctx = multiprocessing.get_context("fork" if "fork" in multiprocessing.get_all_start_methods() else None)
        with ProcessPoolExecutor(max_workers=jobs, mp_context=ctx) as pool:
            futures = [pool.submit(build_job, job, *args) for job in todo]
            for fut in as_completed(futures):
                finished(fut.result())
    bar.done()
    summary.seconds = time.monotonic() - start
    manifest = build_manifest(recipe, records.values(), version or worldgen.__version__)
    _check_unique(manifest)
    if not manifest["worlds"]:
        why = ", ".join(f"{k} {v}x" for k, v in sorted(summary.rejected_draws.items())) or "no draws"
        raise InfeasibleError(f"no job of recipe '{recipe.name}' made a world ({len(recipe.jobs)} rejected; "
                              f"failed draws: {why}); the pack was not written")
    folders = {world_folder(w).split("/", 1)[1] for w in manifest["worlds"]}
    summary.stale = _remove_stale(out, folders, {j.key for j in recipe.jobs})
    write_atomically(out / INDEX_NAME, index_bytes(manifest))
    write_atomically(out / MANIFEST_NAME, manifest_bytes(manifest))  # last: its presence means complete
    return summary


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
    for p in (out / STATE_DIR).glob("*.json"):
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
