"""One job of a pack: its world generated and rendered to a record and file bytes, in any worker.

The local process pool (:mod:`worldgen.pack.build`) and dask workers
(:mod:`worldgen.pack.dask`) both run :func:`render_job`; only where the bytes are
written differs. A local worker writes its job's record and folder itself
(:func:`build_job`), so whatever a worker finished is recorded even when the
build is interrupted before its result reaches the parent.
"""

from __future__ import annotations

import json
import signal
from pathlib import Path
from typing import Any, Optional

from worldgen.errors import InfeasibleError
from worldgen.files import METADATA_NAME, WORLDS_DIR, write_atomically, write_folder_atomically
from worldgen.pack.manifest import key_metrics
from worldgen.pack.recipe import Job

__all__ = ["render_job", "build_job", "save_job", "init_worker"]

#: Set by the parent when the build is cancelled: a worker then starts no further job.
_STOP: Optional[Any] = None


def init_worker(stop) -> None:
    """A pool worker's start: Ctrl-C is the parent's to handle (it reaches the whole process
    group), and ``stop`` (a multiprocessing Event) tells the worker not to start another job."""
    global _STOP
    signal.signal(signal.SIGINT, signal.SIG_IGN)
    _STOP = stop


def render_job(job: Job, formats, sdf_version: str, preview: bool, ros=False) -> tuple[dict, dict[str, bytes]]:
    """Generate one world: its record and its folder's files (no disk; runs in any worker)."""
    import hashlib

    import worldgen

    params = {k: _thaw(v) for k, v in job.params}
    rec: dict[str, Any] = {"job": job.index, "key": job.key, "generator": job.generator, "seed": job.seed,
                           "worldgen_version": worldgen.__version__}
    if job.level is not None:
        rec["level"] = job.level
    try:
        world = worldgen.generate(job.generator, seed=job.seed, difficulty=job.level, **params)
    except InfeasibleError as exc:
        rec.update(params=params, reason=str(exc), failures=dict(sorted(exc.failures.items())))
        return rec, {}
    world.set_provenance(preset=job.preset)
    if job.preset:
        rec["preset"] = job.preset
    if job.level is not None:  # the world's own seed is the draw that landed; the request's is kept beside it
        rec.update(seed=world.seed, request_seed=job.seed)
    blobs = world.folder_blobs(formats, sdf_version, preview, ros)
    meta = json.loads(blobs[METADATA_NAME])
    folder = f"{WORLDS_DIR}/{world.folder_name}"
    rec.update(world_id=world.world_id, folder=world.folder_name, params=meta["params"], metrics=key_metrics(meta),
               attempts=world.attempts,
               files={f"{folder}/{rel}": hashlib.sha256(data).hexdigest() for rel, data in sorted(blobs.items())})
    return rec, blobs


def save_job(rec: dict, blobs: dict[str, bytes], worlds_dir: Path, state_dir: Path) -> None:
    """Record a finished job, then move its folder into place.

    In this order a visible world folder always has its record, whenever the
    process is stopped; a record whose folder never landed is ignored on resume
    and its job built again (the same bytes).
    """
    write_atomically(state_dir / f"{rec['key']}.json", json.dumps(rec, sort_keys=True).encode())
    if blobs:
        write_folder_atomically(worlds_dir, rec["folder"], blobs)


def build_job(job: Job, worlds_dir: str, state_dir: str, formats, sdf_version: str, preview: bool,
              ros=False) -> Optional[dict]:
    """Build, record and write one world; return its record, or None when the build was
    cancelled before this job started (runs in a local worker process or in the parent)."""
    if _STOP is not None and _STOP.is_set():
        return None
    rec, blobs = render_job(job, formats, sdf_version, preview, ros)
    save_job(rec, blobs, Path(worlds_dir), Path(state_dir))
    return rec


def _thaw(value):
    return [_thaw(v) for v in value] if isinstance(value, tuple) else value
