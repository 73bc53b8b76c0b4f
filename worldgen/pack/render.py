"""One job of a pack: its world generated and rendered to a record and file bytes, in any worker.

The local process pool (:mod:`worldgen.pack.build`) and dask workers
(:mod:`worldgen.pack.dask`) both run :func:`render_job`; only where the bytes are
written differs.
"""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

from worldgen.errors import InfeasibleError
from worldgen.files import METADATA_NAME, WORLDS_DIR, write_folder_atomically
from worldgen.pack.manifest import key_metrics
from worldgen.pack.recipe import Job

__all__ = ["render_job", "build_job"]


def render_job(job: Job, formats, sdf_version: str, preview: bool) -> tuple[dict, dict[str, bytes]]:
    """Generate one world: its record and its folder's files (no disk; runs in any worker)."""
    import hashlib

    import worldgen

    params = {k: _thaw(v) for k, v in job.params}
    rec: dict[str, Any] = {"job": job.index, "key": job.key, "generator": job.generator, "seed": job.seed,
                           "worldgen_version": worldgen.__version__}
    try:
        world = worldgen.generate(job.generator, seed=job.seed, **params)
    except InfeasibleError as exc:
        rec.update(params=params, reason=str(exc), failures=dict(sorted(exc.failures.items())))
        return rec, {}
    world.preset = job.preset
    if job.preset:
        rec["preset"] = job.preset
    blobs = world.folder_blobs(formats, sdf_version, preview)
    meta = json.loads(blobs[METADATA_NAME])
    folder = f"{WORLDS_DIR}/{world.folder_name}"
    rec.update(world_id=world.world_id, folder=world.folder_name, params=meta["params"], metrics=key_metrics(meta),
               attempts=world.attempts,
               files={f"{folder}/{rel}": hashlib.sha256(data).hexdigest() for rel, data in sorted(blobs.items())})
    return rec, blobs


def build_job(job: Job, worlds_dir: str, formats, sdf_version: str, preview: bool) -> dict:
    """Build and write one world; return its record (runs in a local worker process)."""

    rec, blobs = render_job(job, formats, sdf_version, preview)
    if blobs:
        write_folder_atomically(Path(worlds_dir), rec["folder"], blobs)
    return rec


def _thaw(value):
    return [_thaw(v) for v in value] if isinstance(value, tuple) else value
