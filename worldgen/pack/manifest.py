"""manifest.json and index.csv: what a pack holds, in job order, with every file's sha256.

Both are pure functions of the build records, sorted by job index, so the same
recipe gives the same bytes whatever --jobs and whatever order workers finish in.
Nothing here has a timestamp or a host name.
"""

from __future__ import annotations

import csv
import io
import json
from typing import Any, Iterable, Mapping

from worldgen.files import METADATA_NAME, WORLDS_DIR

__all__ = ["SCHEMA_ID", "METRICS", "build_manifest",
           "manifest_bytes", "index_bytes"]

SCHEMA_ID = "worldgen.pack/1"
#: The key metrics copied from each world.json into the manifest and index.csv.
METRICS = ("obstacle_count", "free_area_ratio", "narrowest_passage", "path_length",
           "closest_obstacle_distance_mean", "average_visibility", "dispersion",
           "characteristic_dimension", "tortuosity", "difficulty", "difficulty_level")


def build_manifest(recipe, records: Iterable[Mapping[str, Any]], version: str) -> dict:
    """The manifest: the recipe, the version, built worlds and rejected jobs, in job order."""
    worlds, rejected = [], []
    for rec in sorted(records, key=lambda r: r["job"]):
        if rec.get("world_id"):
            worlds.append({k: rec[k] for k in ("world_id", "preset", "generator", "seed", "level", "request_seed", "params",
                                               "metrics", "files", "job") if k in rec})
        else:
            rejected.append({k: rec[k] for k in ("job", "generator", "seed", "level", "params", "reason")
                             if k in rec})
    return {
        "schema": SCHEMA_ID,
        "name": recipe.name,
        "worldgen_version": version,
        "recipe": recipe.document,
        "formats": list(recipe.formats),
        "sdf_version": recipe.sdf_version,
        "preview": recipe.preview,
        "world_count": len(worlds),
        "worlds": worlds,
        "rejected": rejected,
    }


def manifest_bytes(manifest: Mapping[str, Any]) -> bytes:
    return (json.dumps(manifest, indent=1, sort_keys=True, ensure_ascii=True, allow_nan=False) + "\n").encode()


def world_folder(world: Mapping[str, Any]) -> str:
    """A manifest world's folder, relative to the pack: where its world.json is listed
    (``worlds/<preset>--<world_id>`` for a preset's world, else ``worlds/<world_id>``)."""
    for rel in world["files"]:
        parts = rel.split("/")
        if len(parts) == 3 and parts[0] == WORLDS_DIR and parts[1] not in ("", ".", "..") and parts[2] == METADATA_NAME:
            return f"{WORLDS_DIR}/{parts[1]}"
    return f"{WORLDS_DIR}/{world['world_id']}"


def index_bytes(manifest: Mapping[str, Any]) -> bytes:
    """index.csv: one row per world, its id, generator, seed, the level asked for and its request seed, folder
    and key metrics (``difficulty_level`` among them: the level it landed in, for every world)."""
    buf = io.StringIO()
    w = csv.writer(buf, lineterminator="\n")
    w.writerow(["index", "world_id", "generator", "seed", "level", "request_seed", "folder", *METRICS])
    for i, world in enumerate(manifest["worlds"]):
        m = world["metrics"]
        # level, request_seed: what a level entry asked for (empty for the rest); seed is the draw that landed
        w.writerow([i, world["world_id"], world["generator"], world["seed"], world.get("level", ""),
                    world.get("request_seed", ""), world_folder(world),
                    *("" if m.get(k) is None else repr(m[k]) for k in METRICS)])
    return buf.getvalue().encode()


def key_metrics(meta: Mapping[str, Any]) -> dict[str, Any]:
    """The manifest's metrics of one world.json: its metrics plus the first task's path length."""
    m = dict(meta.get("metrics") or {})
    tasks = meta.get("tasks") or []
    path = tasks[0].get("path") if tasks else None
    m["path_length"] = path.get("length") if path else None
    return {k: m.get(k) for k in METRICS}
