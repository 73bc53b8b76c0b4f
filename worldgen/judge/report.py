"""The report folder of ``worldgen judge``: report.json, report.csv, report.md and a picture per run.

    report/
      report.json     evaluate's report (verdict, failures, summary, criteria) with one row per bag
      report.csv      one row per bag, the columns of RUN_COLUMNS first
      report.md       the verdict, the criteria, the per-world summary where the report has one, every run
      runs/RUN.png    the run over the world as preview.png draws it: trajectory, contacts, who was where at each

The folder is written beside its destination under a temporary name and renamed into place,
so a reader never sees half a report; an earlier report in the same place is replaced, any
other existing folder is refused.
"""

from __future__ import annotations

import csv
import io
import json
import os
import re
import shutil
from pathlib import Path
from typing import Any, Optional

import numpy as np

from worldgen.errors import OutputError
from worldgen.export.topdown import COLOURS as TOPDOWN_COLOURS
from worldgen.files import REPORT_NAME

__all__ = ["write_report", "RUN_COLUMNS", "draw_run", "COLOURS"]

#: Columns of report.csv, in order; any other key of a row follows, sorted.
RUN_COLUMNS = ["run", "bag", "outcome", "readable", "world_id", "task", "source", "start", "start_time", "success", "reason",
               "reached_goal", "time_to_goal", "duration", "path_length", "path_efficiency", "min_clearance",
               "collisions", "min_separation", "max_velocity", "drift_bounded", "source_detail", "picture"]
#: The one colour table of every top-down picture (worldgen.export.topdown), the run's layers among it.
COLOURS = TOPDOWN_COLOURS
_WIDTH = 640


def _safe(name: str) -> str:
    return re.sub(r"[^A-Za-z0-9._-]", "_", name)[:120] or "run"


def _cell(value: Any) -> str:
    if value is None:
        return ""
    if isinstance(value, float):
        return f"{value:.6g}"
    if isinstance(value, list):  # the contacts: entity@time
        return ";".join(f"{c['entity']}@{c['time']:.3f}" if isinstance(c, dict) and "entity" in c else str(c) for c in value)
    if isinstance(value, dict):
        return json.dumps(value, sort_keys=True)
    return str(value)


def _csv(report: dict) -> str:
    rows = report["runs"]
    others = sorted({k for r in rows for k in r} - set(RUN_COLUMNS))
    buf = io.StringIO()
    w = csv.writer(buf, lineterminator="\n")
    w.writerow(RUN_COLUMNS + others)
    for r in rows:
        w.writerow([_cell(r.get(k)) for k in RUN_COLUMNS + others])
    return buf.getvalue()


def _table(head: list[str], rows: list[list[str]]) -> list[str]:
    esc = [[c.replace("|", "\\|").replace("\n", " ") for c in row] for row in rows]
    return ["| " + " | ".join(head) + " |", "|" + "---|" * len(head)] + ["| " + " | ".join(r) + " |" for r in esc]


def _markdown(report: dict) -> str:
    s = report["summary"]
    out = [f"# Run report: {'PASS' if report['passed'] else 'FAIL'}", ""]
    out.append(f"{s.get('bags', s.get('runs'))} bags, {s.get('runs', 0)} runs judged, {s.get('successes', 0)} succeeded, "
               f"{s.get('unjudged', 0)} unjudged (no verdict: left out of every rate).")
    out.append("")
    if report["failures"]:
        out += ["## Failures", ""] + [f"- {f}" for f in report["failures"]] + [""]
    if report.get("criteria"):
        rows = [[f"{c['section']}.{c['key']}", f"{c['op']} {_cell(c['required'])}",
                 "n/a" if c.get("measured") is None else _cell(c["measured"]), "PASS" if c["passed"] else "FAIL",
                 f"{c['margin']:+.6g}" if isinstance(c.get("margin"), (int, float)) else _cell(c.get("margin"))]
                for c in report["criteria"]]
        out += ["## Criteria", ""] + _table(["criterion", "required", "measured", "verdict", "margin"], rows) + [""]
    out += ["## Summary", ""] + _table(["figure", "value"], [[k, _cell(v)] for k, v in sorted(s.items())
                                                             if not isinstance(v, (dict, list))]) + [""]
    per_world = report.get("per_world") or s.get("per_world")
    if isinstance(per_world, dict) and per_world:
        keys = sorted({k for v in per_world.values() if isinstance(v, dict) for k in v})
        rows = [[w] + [_cell(v.get(k)) if isinstance(v, dict) else "" for k in keys] for w, v in sorted(per_world.items())]
        out += ["## Per world", ""] + _table(["world"] + keys, rows) + [""]
    elif isinstance(per_world, list) and per_world:
        keys = sorted({k for v in per_world for k in v})
        out += ["## Per world", ""] + _table(keys, [[_cell(v.get(k)) for k in keys] for v in per_world]) + [""]
    head = ["run", "world", "task", "source", "outcome", "reason", "time to goal (s)", "path eff.", "min clearance (m)",
            "contacts", "picture"]
    rows = []
    for r in report["runs"]:
        pic = f"[png]({r['picture']})" if r.get("picture") else ""
        rows.append([str(r.get("run")), _cell(r.get("world_id")), _cell(r.get("task")), _cell(r.get("source")),
                     _cell(r.get("outcome")), _cell(r.get("reason")), _cell(r.get("time_to_goal")),
                     _cell(r.get("path_efficiency")), _cell(r.get("min_clearance")), str(len(r.get("collisions") or [])), pic])
    out += ["## Runs", ""] + _table(head, rows) + [""]
    return "\n".join(out)


#: px above the world's picture for the run's name, verdict and legend.
_HEADER = 54


#: Worlds whose picture is kept while a report is drawn (runs usually come grouped by world).
_WORLDS_KEPT = 4


def draw_run(world: Path, task: Optional[str], trajectory: np.ndarray, row: dict, worlds: Optional[dict] = None):
    """The run's picture (a Pillow image): the world as preview.png draws it from world.json (walls, obstacles,
    no-go zone, reference path, spawn and goal, movers' and people's tracks), the run over it, and at each
    contact who was where, all with :mod:`worldgen.export.topdown`; a header with the run and its verdict.
    ``worlds`` keeps each world's picture between runs (it costs tens of ms to draw)."""
    from PIL import Image, ImageDraw

    from worldgen.export.preview import draw, layout
    from worldgen.export.topdown import Pen, text_font
    from worldgen.export.topdown import draw_run as draw_trajectory
    from worldgen.groundtruth.ground import load

    worlds = {} if worlds is None else worlds
    key = str(Path(world).resolve())
    if key not in worlds:
        ground = load(world)
        worlds[key] = (ground, layout(ground.meta, _WIDTH), draw(ground.meta, _WIDTH))
        while len(worlds) > _WORLDS_KEPT:
            worlds.pop(next(iter(worlds)))
    ground, lay, background = worlds[key]
    meta = ground.meta
    picture = background.copy()
    draw_trajectory(Pen(picture, lay), meta, trajectory, bool(row.get("success")), row.get("collisions") or [])
    canvas = Image.new("RGB", (picture.width, picture.height + _HEADER), COLOURS["background"])
    canvas.paste(picture, (0, _HEADER))
    pen = ImageDraw.Draw(canvas)
    t = ground.task(task)
    colour = COLOURS["run_ok"] if row.get("success") else COLOURS["run"]
    verdict = "success" if row.get("success") else f"FAIL: {row.get('reason') or ''}"
    pen.text((6, 3), f"{row.get('run')}   task {t['id']}   source: {row.get('source')}", fill=COLOURS["text"],
             font=text_font(13))
    pen.text((6, 19), verdict[:90], fill=colour, font=text_font(13))
    pen.text((6, 35), "blue/red line: the run (success/failure)   red x: a contact, with every mover and person "
             "where they were then", fill=COLOURS["text"], font=text_font(11))
    return canvas


def write_report(result, out) -> Path:
    """Write the report folder of a :class:`~worldgen.judge.runs.JudgeResult` at ``out``; returns ``out``."""
    out = Path(out)
    if out.exists() and not (out.is_dir() and ((out / "report.json").is_file() or not any(out.iterdir()))):
        raise OutputError(f"--out '{out}' exists and is not a report folder; give a new folder or an earlier report's")
    tmp = out.with_name(f".{out.name}.tmp-{os.getpid()}")
    old = out.with_name(f".{out.name}.old-{os.getpid()}")
    try:
        shutil.rmtree(tmp, ignore_errors=True)
        (tmp / "runs").mkdir(parents=True)
        report = result.report
        worlds: dict = {}
        for k, (row, plot) in enumerate(zip(report["runs"], result.plots)):
            row["picture"] = None
            if plot is None:
                continue
            image = draw_run(plot["world"], plot["task"], result.trajectory(k), row, worlds)
            if image is not None:
                name = f"runs/{_safe(str(row['run']))}.png"
                image.save(tmp / name, format="PNG")
                row["picture"] = name
        (tmp / "report.json").write_text(json.dumps(report, indent=2, sort_keys=True, default=str) + "\n")
        (tmp / "report.csv").write_text(_csv(report))
        (tmp / REPORT_NAME).write_text(_markdown(report))
        if out.exists():
            out.rename(old)
        tmp.rename(out)
    except OSError as exc:
        shutil.rmtree(tmp, ignore_errors=True)
        if old.exists() and not out.exists():
            old.rename(out)
        raise OutputError(f"cannot write the report to '{out}': {exc.strerror or exc}") from None
    shutil.rmtree(old, ignore_errors=True)
    return out
