"""A campaign's output folder: the records of its points, and the tables written from them.

Layout of OUT::

    OUT/campaign.yaml            the recipe (what makes it this campaign; a rerun with another is refused)
    OUT/worlds/<world_id>/       every world a point made, as `worldgen generate` writes it
    OUT/runs/<world_id>__<task>__<run>/   what the system under test wrote for that run (bags, logs)
    OUT/.campaign/<k>.json       point k's record (its world, descriptors, every run's verdict and judge row),
                                 written atomically when the point is finished; <k>.asked.json when it is sent
    OUT/verdicts.csv, OUT/failures.csv   every run, and the failed ones (unjudged runs are never failures)
    OUT/strategy.json            the search's state (worldgen.campaign.strategies)
    OUT/failure_map.csv, OUT/plots/, OUT/report.md, OUT/shrunk/   (worldgen.campaign.report)
    OUT/manifest.json            written last: its presence means the campaign ran to its budget

A rerun reads the records and goes on from there: a point asked but not finished is run again (the same point
gives the same world), and every finished run is kept.
"""

from __future__ import annotations

import csv
import io
import json
from pathlib import Path
from typing import Any, Iterable, Mapping, Optional

import yaml

from worldgen.campaign.recipe import CampaignRecipe, identity_of
from worldgen.campaign.space import DESCRIPTORS
from worldgen.errors import OutputError, ParameterError
from worldgen.files import (
    CAMPAIGN_RECIPE_NAME,
    CAMPAIGN_STATE_DIR,
    FAILURES_NAME,
    MANIFEST_NAME,
    STRATEGY_NAME,
    VERDICTS_NAME,
    write_atomically,
)

__all__ = ["claim_folder", "refuse_other", "load_records", "save_record", "save_asked", "asked_points", "write_tables",
           "write_manifest", "run_rows", "VERDICT_COLUMNS"]

#: The first columns of verdicts.csv and failures.csv; the judge's row's other columns follow, sorted.
VERDICT_COLUMNS = ["point", "world_id", "task", "run", "verdict", "reason", "seconds", *DESCRIPTORS, "params", "seed",
                   "folder"]


def claim_folder(out: Path, recipe: CampaignRecipe) -> None:
    """Refuse ``out`` when it holds anything but this campaign (nothing is written then); write campaign.yaml."""
    refuse_other(out, recipe)
    try:
        (out / CAMPAIGN_STATE_DIR).mkdir(parents=True, exist_ok=True)
    except OSError as exc:
        raise OutputError(f"cannot write campaign folder '{out}': {exc.strerror or exc}") from None
    text = yaml.safe_dump(recipe.document, sort_keys=False, allow_unicode=True)
    write_atomically(out / CAMPAIGN_RECIPE_NAME, text.encode())


def refuse_other(out: Path, recipe: CampaignRecipe) -> None:
    """A one-line ParameterError when ``out`` exists and holds anything but a campaign of ``recipe``."""
    if out.exists():
        if not out.is_dir():
            raise ParameterError(f"--out '{out}' is not a folder")
        stored = out / CAMPAIGN_RECIPE_NAME
        if stored.is_file():
            try:
                other = yaml.safe_load(stored.read_text(encoding="utf-8"))
            except (OSError, yaml.YAMLError) as exc:
                raise ParameterError(f"--out '{out}' holds a campaign whose recipe cannot be read: {exc}") from None
            if identity_of(other) != recipe.identity:
                name = other.get("name") if isinstance(other, dict) else None
                raise ParameterError(f"--out '{out}' holds another campaign ({name or 'another recipe'}); "
                                     "give a new folder, or the same recipe to resume it")
        elif any(out.iterdir()):
            raise ParameterError(f"--out '{out}' exists and is not a campaign folder; give a new or empty folder")


def _state(out: Path) -> Path:
    return Path(out) / CAMPAIGN_STATE_DIR


def save_asked(out: Path, point: Mapping[str, Any], search: Mapping[str, Any]) -> None:
    write_atomically(_state(out) / f"{point['index']:06d}.asked.json", _json({"point": point, "search": search}))


def save_record(out: Path, rec: Mapping[str, Any]) -> None:
    write_atomically(_state(out) / f"{rec['point']['index']:06d}.json", _json(rec))


def load_records(out: Path) -> list[dict]:
    """Every finished point's record, in point order."""
    out_recs = []
    for path in sorted(_state(out).glob("[0-9]*[0-9].json")):
        try:
            out_recs.append(json.loads(path.read_text(encoding="utf-8")))
        except (OSError, ValueError):
            continue  # cannot happen with atomic writes; the point is asked again if it does
    return sorted(out_recs, key=lambda r: r["point"]["index"])


def asked_points(out: Path, finished: Iterable[int]) -> list[dict]:
    """Points sent out by an earlier process that never finished, in point order."""
    done = set(finished)
    found = []
    for path in sorted(_state(out).glob("*.asked.json")):
        rec = json.loads(path.read_text(encoding="utf-8"))
        if rec["point"]["index"] not in done:
            found.append(rec)
    return found


def run_rows(records: Iterable[Mapping[str, Any]]) -> list[dict]:
    """One row per run of every record (points without a world have no runs)."""
    rows = []
    for rec in records:
        point = rec["point"]
        for r in rec.get("runs", ()):
            row = {"point": point["index"], "world_id": rec.get("world_id"), "task": r["task"], "run": r["run"],
                   "verdict": r["verdict"], "reason": r["reason"], "seconds": r["seconds"], **rec["descriptors"],
                   "params": json.dumps(point["params"], sort_keys=True), "seed": point["seed"],
                   "folder": rec.get("folder")}
            for k, v in (r.get("row") or {}).items():
                row.setdefault(k if k not in row else f"judge_{k}", v)
            rows.append(row)
    return rows


def _csv(rows: list[dict]) -> bytes:
    others = sorted({k for r in rows for k in r} - set(VERDICT_COLUMNS))
    buf = io.StringIO()
    w = csv.writer(buf, lineterminator="\n")
    w.writerow(VERDICT_COLUMNS + others)
    for r in rows:
        w.writerow([_cell(r.get(k)) for k in VERDICT_COLUMNS + others])
    return buf.getvalue().encode()


def _cell(v: Any) -> str:
    if v is None:
        return ""
    if isinstance(v, float):
        return f"{v:.6g}"
    if isinstance(v, (dict, list)):
        return json.dumps(v, sort_keys=True)
    return str(v)


def write_tables(out: Path, records: list[dict], strategy_state: Optional[Mapping[str, Any]]) -> None:
    rows = run_rows(records)
    write_atomically(out / VERDICTS_NAME, _csv(rows))
    write_atomically(out / FAILURES_NAME, _csv([r for r in rows if r["verdict"] == "failed"]))
    if strategy_state is not None:
        write_atomically(out / STRATEGY_NAME, _json(strategy_state))


def write_manifest(out: Path, recipe: CampaignRecipe, records: list[dict], version: str, complete: bool) -> None:
    runs = run_rows(records)
    count = {v: sum(r["verdict"] == v for r in runs) for v in ("passed", "failed", "unjudged")}
    manifest = {"campaign": recipe.name, "identity": recipe.identity, "worldgen_version": version,
                "strategy": recipe.strategy, "seed": recipe.seed, "complete": complete,
                "points": len(records), "points_without_world": sum(r.get("world_id") is None for r in records),
                "runs": len(runs), **count,
                "worlds": sorted({r["folder"] for r in records if r.get("folder")})}
    write_atomically(out / MANIFEST_NAME, _json(manifest))


def _json(data: Any) -> bytes:
    return (json.dumps(data, sort_keys=True, indent=1, default=str) + "\n").encode()
