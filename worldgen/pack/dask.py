"""Past one machine: run a pack's jobs on a dask.distributed cluster (an optional extra).

    pip install "worldgen[dask]"
    worldgen pack build RECIPE --out PACK --executor dask --scheduler tcp://host:8786

Workers only compute: each returns its world's record and file bytes, and this
process writes the folders, the records and the manifest, so workers need the
same worldgen version but no access to the pack's disk. The manifest is built
from records in job order exactly as with the local pool, so it is the same bytes.
"""

from __future__ import annotations

from typing import Iterator, Optional, Sequence

from worldgen.errors import ParameterError

__all__ = ["run_on_dask"]


def run_on_dask(jobs: Sequence, scheduler: Optional[str], render_args: tuple, version: str) -> Iterator[tuple[dict, dict]]:
    """Yield ``(record, blobs)`` per job as the cluster at ``scheduler`` finishes them."""
    if not scheduler:
        raise ParameterError("--executor dask needs --scheduler ADDRESS (e.g. tcp://127.0.0.1:8786)")
    try:
        from distributed import Client, as_completed
    except ImportError:
        raise ParameterError("--executor dask needs dask.distributed: pip install 'worldgen[dask]'") from None
    from worldgen.pack.render import render_job

    try:
        client = Client(scheduler, timeout="10s")
    except (OSError, TimeoutError) as exc:
        raise ParameterError(f"--scheduler {scheduler}: cannot reach the dask scheduler ({exc})") from None
    try:
        futures = client.map(render_job, list(jobs), *([a] * len(jobs) for a in render_args), pure=False)
        for fut in as_completed(futures):
            rec, blobs = fut.result()
            if rec.get("worldgen_version") != version:
                raise ParameterError(
                    f"a dask worker runs worldgen {rec.get('worldgen_version')}, this build {version}: "
                    "every worker needs the same version for the same bytes")
            yield rec, blobs
    finally:
        client.close()
