"""A campaign's report: the failure map (a table and plots), each distinct failure shrunk, and report.md.

``write_report(out)`` redraws everything from the records in the output folder (``worldgen campaign report
DIR``); with the ``system`` under test it also shrinks each distinct failure (:func:`worldgen.shrink`: the
fewest obstacles and movers, and people where shrink removes them, that still make the system fail) into
``shrunk/<k>-<world_id>/``, with the run's picture from the judge's drawing beside it. A failure's kind is its
reason with the numbers and the names' indices taken out (``collision with person_# at # s``); two failures
are distinct when their kind, generator, level, people and door state differ. Without the system (a redraw),
the shrunk folders already there are listed again.
"""

from __future__ import annotations

import json
import re
import shutil
import tempfile
from pathlib import Path
from typing import Any, Mapping, Optional, Sequence

import numpy as np

from worldgen.campaign.failuremap import CONFIDENCE, failure_map, map_rows_csv, plot_map
from worldgen.campaign.output import load_records, run_rows
from worldgen.campaign.recipe import CampaignRecipe, parse_campaign
from worldgen.campaign.space import Point, make_world
from worldgen.errors import ParameterError, WorldgenError
from worldgen.files import CAMPAIGN_RECIPE_NAME, FAILURE_MAP_NAME, PLOTS_DIR, REPORT_MD_NAME, SHRUNK_DIR, write_atomically

__all__ = ["write_report", "distinct_failures", "failure_kind", "slot_of", "MAX_SHRINK_CALLS", "MAX_SHRUNK"]

#: Runs of the system one failure's shrinking may make.
MAX_SHRINK_CALLS = 40
#: Distinct failures shrunk, the most frequent first (each costs up to MAX_SHRINK_CALLS runs of the system).
MAX_SHRUNK = 10


def failure_kind(reason: str) -> str:
    """``reason`` with its numbers and the indices of names taken out: what kind of failure it is."""
    return re.sub(r"\d+(\.\d+)?", "#", reason or "failed").strip()


def distinct_failures(records: Sequence[Mapping[str, Any]]) -> list[dict[str, Any]]:
    """One entry per distinct failure: its key, how many runs showed it, and the smallest world that did."""
    found: dict[tuple, dict[str, Any]] = {}
    for rec in records:
        d = rec["descriptors"]
        for r in rec.get("runs", ()):
            if r["verdict"] != "failed":
                continue
            key = (failure_kind(r["reason"]), d["generator"], d["level"], d["people"], d["door_state"])
            size = (d.get("obstacles") or 0, d["people"], rec["point"]["index"])
            got = found.get(key)
            if got is None or size < got["size"]:
                found[key] = {"key": key, "size": size, "count": (got or {}).get("count", 0), "record": rec, "run": r}
            found[key]["count"] += 1
    return [found[k] for k in sorted(found, key=lambda k: (-found[k]["count"], [str(x) for x in k]))]


def _recipe(out: Path) -> CampaignRecipe:
    """The campaign's recipe as stored; its verdict left out: the report needs none, and a criteria path
    relative to where the recipe was is not relative to the campaign folder."""
    import yaml

    path = out / CAMPAIGN_RECIPE_NAME
    document = yaml.safe_load(path.read_text(encoding="utf-8"))
    if isinstance(document, dict):
        document.pop("verdict", None)
    return parse_campaign(yaml.safe_dump(document, sort_keys=False), str(path), out.name)


def write_report(out, records: Optional[list] = None, system: Any = None) -> Path:
    """Write failure_map.csv, plots/, report.md (and shrunk/ with ``system``) in campaign folder ``out``."""
    out = Path(out)
    if not (out / CAMPAIGN_RECIPE_NAME).is_file():
        raise ParameterError(f"'{out}' is not a campaign folder (it has no {CAMPAIGN_RECIPE_NAME})")
    recipe = _recipe(out)
    records = load_records(out) if records is None else records
    rows = failure_map(records, recipe.entries)
    write_atomically(out / FAILURE_MAP_NAME, map_rows_csv(rows))
    plots = plot_map(rows, out / PLOTS_DIR, recipe.name)
    failures = distinct_failures(records)
    shrunk = [_shrink(out, k, f, system) if system is not None and k < MAX_SHRUNK else _shrunk_before(out, k, f)
              for k, f in enumerate(failures)]
    write_atomically(out / REPORT_MD_NAME, _markdown(recipe, records, rows, plots, failures, shrunk, out).encode())
    return out / REPORT_MD_NAME


def slot_of(out: Path, k: int, failure: Mapping[str, Any]) -> Path:
    """Where distinct failure number ``k`` is shrunk (its note beside it, ``.json``)."""
    return out / SHRUNK_DIR / f"{k + 1:02d}-{failure['record']['world_id']}"


def _shrunk_before(out: Path, k: int, failure: Mapping[str, Any]) -> dict[str, Any]:
    slot = slot_of(out, k, failure)
    note = slot.with_suffix(".json")
    if note.is_file():
        return json.loads(note.read_text(encoding="utf-8"))
    if k >= MAX_SHRUNK:
        return {"shrunk": False, "why": f"not shrunk: only the {MAX_SHRUNK} most frequent distinct failures are"}
    return {"shrunk": False, "why": "not shrunk: the report was drawn without running the system (--no-shrink, or a redraw)"}


def _shrink(out: Path, k: int, failure: Mapping[str, Any], system: Any) -> dict[str, Any]:
    from worldgen.testing.shrink import shrink

    rec, run = failure["record"], failure["run"]
    slot = slot_of(out, k, failure)
    world, why = make_world(Point.from_dict(rec["point"]))
    info: dict[str, Any] = {"shrunk": False, "why": why, "original": rec["folder"], "task": run["task"]}
    if world is None:
        return _note(slot, info)
    work = Path(tempfile.mkdtemp(prefix=".shrink.", suffix=".tmp", dir=out))
    last: dict[str, Any] = {}

    def still_fails(candidate) -> bool:
        folder = candidate.write(work / "worlds", preview=False, overwrite=True)
        name = f"shrink{len(last.setdefault('calls', []))}"
        workdir = work / f"{folder.name}__{run['task']}__{name}"
        workdir.mkdir(parents=True, exist_ok=True)
        got = system.run(folder, run["task"], name, workdir)
        last["calls"].append(got.verdict)
        if got.verdict == "failed":  # the last failing call is on the smallest world shrink keeps
            last.update(row=dict(got.row), reason=got.reason, trajectory=_trajectory(got.row, folder, run["task"]))
        return got.verdict == "failed"

    try:
        result = shrink(world, still_fails, slot, max_calls=MAX_SHRINK_CALLS)
    except (ParameterError, WorldgenError) as exc:
        info["why"] = f"not shrunk: {' '.join(str(exc).split())}"
        shutil.rmtree(work, ignore_errors=True)
        return _note(slot, info)
    shutil.rmtree(work, ignore_errors=True)
    folder = Path(result.path)
    row = dict(last.get("row") or run.get("row") or {}, run=f"shrunk {k + 1:02d}", success=False,
               reason=last.get("reason", run["reason"]))
    picture: Optional[Path] = slot / f"{folder.name}.png"
    meta: Mapping[str, Any] = getattr(result.world, "metadata")  # ShrinkResult.world is typed object: a World
    try:
        _picture(folder, run["task"], row, last.get("trajectory")).save(slot / f"{folder.name}.png")
    except (WorldgenError, OSError, KeyError) as exc:
        info["picture_error"] = " ".join(str(exc).split())
        picture = None
    info.update(shrunk=True, why="", folder=str(folder.relative_to(out)), removed=list(result.removed),
                calls=result.calls, picture=str(picture.relative_to(out)) if picture else None,
                obstacles=(meta.get("metrics") or {}).get("obstacle_count"), people=len(meta.get("people") or []))
    return _note(slot, info)


def _trajectory(row: Mapping[str, Any], world: Path, task: str) -> Optional[np.ndarray]:
    """The run's trajectory from the bag its judge's row names (read before shrinking's folder goes), or None."""
    if not row.get("bag"):
        return None
    from worldgen.ros.reader import read_run

    try:
        return read_run(row["bag"], world, task=task).trajectory
    except (WorldgenError, OSError):
        return None


def _picture(folder: Path, task: str, row: dict, trajectory: Optional[np.ndarray]):
    """The judge's picture of the run on the shrunk world: its trajectory and contacts where the system left a
    readable bag, else the world with the run's verdict alone."""
    from worldgen.judge.report import draw_run

    if trajectory is None or len(trajectory) < 2:
        return draw_run(folder, task, np.zeros((0, 4)), dict(row, collisions=[]))
    return draw_run(folder, task, trajectory, row)


def _note(slot: Path, info: dict[str, Any]) -> dict[str, Any]:
    slot.parent.mkdir(parents=True, exist_ok=True)
    write_atomically(slot.with_suffix(".json"), (json.dumps(info, sort_keys=True, indent=1) + "\n").encode())
    return info


def _crossed(records) -> list[str]:
    """Level by people: failed / judged in each cell, where both vary (how people change the level curve)."""
    cells: dict[tuple, list[int]] = {}
    for rec in records:
        d = rec["descriptors"]
        for r in rec.get("runs", ()):
            if r["verdict"] in ("passed", "failed"):
                c = cells.setdefault((d["level"], d["people"]), [0, 0])
                c[0] += 1
                c[1] += r["verdict"] == "failed"
    levels = sorted({k[0] for k in cells if k[0] is not None})
    people = sorted({k[1] for k in cells})
    if len(levels) < 2 or len(people) < 2:
        return []
    out = ["Failed / judged runs by level and people:", "",
           "| level | " + " | ".join(f"{p} people" for p in people) + " |", "|---" * (len(people) + 1) + "|"]
    for lv in levels:
        out.append(f"| {lv} | " + " | ".join(f"{cells[(lv, p)][1]} / {cells[(lv, p)][0]}" if (lv, p) in cells else "-"
                                              for p in people) + " |")
    return out + [""]


def _pct(x: float) -> str:
    return f"{100 * x:.0f} %"


def _markdown(recipe: CampaignRecipe, records, rows, plots, failures, shrunk, out: Path) -> str:
    runs = run_rows(records)
    judged = [r for r in runs if r["verdict"] in ("passed", "failed")]
    failed = sum(r["verdict"] == "failed" for r in runs)
    unjudged = len(runs) - len(judged)
    no_world = sum(r.get("world_id") is None for r in records)
    lines = [f"# Campaign {recipe.name}", "",
             f"Strategy `{recipe.strategy}` (seed {recipe.seed}); {len(records)} points, {no_world} of them without a "
             f"world (the generator refused them; never counted as runs); {len(runs)} runs: **{failed} failed**, "
             f"{len(judged) - failed} passed, {unjudged} unjudged (neither: the system could not be run or judged).", ""]
    if judged:
        from worldgen.judge.stats import clopper_pearson_interval

        lo, hi = clopper_pearson_interval(failed, len(judged), CONFIDENCE)
        lines += [f"Failure rate over the judged runs: {_pct(failed / len(judged))} "
                  f"({int(CONFIDENCE * 100)} % Clopper-Pearson interval {_pct(lo)} to {_pct(hi)}). "
                  + ("The runs were drawn uniformly over the space, so the rates are what a uniform draw of "
                     "worlds would see." if recipe.strategy == "random" else
                     "The runs were placed by the strategy, not drawn uniformly: rates per bin say where it "
                     "fails, not how often a uniform draw of worlds would see it."), ""]
    worst = sorted((r for r in rows if r["failed"]), key=lambda r: (-r["low"], -r["rate"], r["dimension"], r["bin"]))[:8]
    lines += ["## Where it fails", ""]
    if worst:
        lines += ["The bins with the highest lower bound on the failure rate:", "",
                  "| dimension | bin | failed / judged | rate | 95 % interval |", "|---|---|---|---|---|"]
        lines += [f"| {r['dimension']} | {r['bin']} | {r['failed']} / {r['judged']} | {_pct(r['rate'])} | "
                  f"{_pct(r['low'])} to {_pct(r['high'])} |" for r in worst]
    else:
        lines += ["No run failed."]
    lines += ["", "## The smallest worlds that show it", ""]
    if not failures:
        lines += ["No failure to show."]
    for k, (f, s) in enumerate(zip(failures, shrunk)):
        kind, generator, level, people, door = f["key"]
        lines.append(f"{k + 1}. **{kind}**: {generator}, level {level}, {people} people, doors {door}; "
                     f"{f['count']} failed run(s); first seen in `{f['record']['folder']}` "
                     f"(point {f['record']['point']['index']})")
        if s.get("shrunk"):
            lines.append(f"   - shrunk to `{s['folder']}` ({s.get('obstacles')} obstacles, {s.get('people')} people left; "
                         f"removed {len(s['removed'])}; {s['calls']} runs of the system)"
                         + (f"; picture: ![]({s['picture']})" if s.get("picture") else ""))
        else:
            lines.append(f"   - {s.get('why') or 'not shrunk'}")
    lines += ["", "## Failure map", "", f"Every bin of every dimension: `{FAILURE_MAP_NAME}`. Per level and per people "
              "count:", ""]
    for dim in ("level", "people", "door_state"):
        mine = [r for r in rows if r["dimension"] == dim]
        if len(mine) < 2:
            continue
        lines += [f"| {dim} | failed / judged | rate | 95 % interval |", "|---|---|---|---|"]
        lines += [f"| {r['bin']} | {r['failed']} / {r['judged']} | {_pct(r['rate'])} | {_pct(r['low'])} to "
                  f"{_pct(r['high'])} |" for r in mine] + [""]
    lines += _crossed(records)
    if plots:
        lines += ["Plots:", ""] + [f"![{p.stem}]({p.relative_to(out).as_posix()})" for p in plots] + [""]
    return "\n".join(lines) + "\n"
