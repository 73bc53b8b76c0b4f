"""Judge many runs in many worlds against acceptance criteria read from YAML.

    >>> report = evaluate([(trajectory, world), ...], "criteria.yaml")
    >>> print(report)                 # a table: criterion, required, measured, verdict, by how much
    >>> report.passed, report.failures
    >>> report.write_csv("report.csv"); report.write_json("report.json")

Criteria come in three sections; every key is optional, an unknown section or
key is a one-line :class:`~worldgen.errors.ParameterError`:

    navigation:  success_rate (>=, 0..1), path_efficiency (<=, mean recorded/reference length)
    safety:      obstacle_clearance (>=, m, smallest over all runs), min_obstacle_distance (>=, m,
                 from movers), collision_tolerance (<=, total contacts), max_velocity (<=, m/s)
    performance: max_time (<=, s, slowest successful run), avg_time_to_goal (<=, s, mean over successes)

A run succeeds when it meets its world's scenario (scenario.yaml, read from the
folder or built from the World): it reaches the goal waypoint within tolerance,
within ``max_time``, and no failure condition (collision, timeout) occurred.
"""

from __future__ import annotations

import csv
import io
import json
import math
from dataclasses import asdict, dataclass
from pathlib import Path
from typing import Any, Iterable, Mapping, Optional

from worldgen.errors import ParameterError
from worldgen.files import SCENARIO_NAME
from worldgen.testing.figures import Run, load
from worldgen.testing.figures import run as run_figures

__all__ = ["CRITERIA", "Criterion", "Report", "load_criteria", "evaluate", "scenario_of"]

#: section -> key -> (comparison, what is measured)
CRITERIA: dict[str, dict[str, tuple[str, str]]] = {
    "navigation": {"success_rate": (">=", "share of runs meeting their scenario"),
                   "path_efficiency": ("<=", "mean recorded length / reference length")},
    "safety": {"obstacle_clearance": (">=", "smallest footprint-to-collider distance (m)"),
               "min_obstacle_distance": (">=", "smallest footprint-to-mover gap (m)"),
               "collision_tolerance": ("<=", "total contacts"),
               "max_velocity": ("<=", "highest speed between samples (m/s)")},
    "performance": {"max_time": ("<=", "slowest time to goal of a successful run (s)"),
                    "avg_time_to_goal": ("<=", "mean time to goal of successful runs (s)")},
}


def load_criteria(criteria) -> dict[str, dict[str, float]]:
    """Criteria from a YAML file path, a YAML text or a mapping, checked key by key."""
    import yaml

    where = "criteria"
    is_file_name = isinstance(criteria, str) and "\n" not in criteria and criteria.endswith((".yaml", ".yml"))
    if isinstance(criteria, Path) or is_file_name:
        where = str(criteria)
        try:
            criteria = Path(criteria).read_text()
        except OSError as exc:
            raise ParameterError(f"parameter 'criteria': cannot read '{where}': {exc.strerror}") from None
    if isinstance(criteria, str):
        try:
            criteria = yaml.safe_load(criteria) or {}
        except yaml.YAMLError as exc:
            raise ParameterError(f"parameter 'criteria': {where} is not valid YAML ({str(exc).splitlines()[0]})") from None
    if not isinstance(criteria, Mapping):
        raise ParameterError(f"parameter 'criteria' must be a mapping of sections {', '.join(CRITERIA)}, "
                             f"got {type(criteria).__name__}")
    out: dict[str, dict[str, float]] = {}
    for section, keys in criteria.items():
        if section not in CRITERIA:
            raise ParameterError(f"{where}: unknown section {section!r}; allowed: {', '.join(CRITERIA)}")
        if not isinstance(keys, Mapping):
            raise ParameterError(f"{where}: section {section!r} must be a mapping of criteria, got {type(keys).__name__}")
        out[section] = {}
        for key, value in keys.items():
            if key not in CRITERIA[section]:
                raise ParameterError(f"{where}: unknown key {section}.{key}; "
                                     f"allowed in {section}: {', '.join(CRITERIA[section])}")
            if isinstance(value, bool) or not isinstance(value, (int, float)) or not math.isfinite(value) or value < 0:
                raise ParameterError(f"{where}: {section}.{key} must be a finite number >= 0, got {value!r}")
            if key == "success_rate" and value > 1:
                raise ParameterError(f"{where}: navigation.success_rate must be in [0, 1], got {value!r}")
            out[section][key] = float(value)
    return out


def scenario_of(world) -> dict:
    """The scenario spec of a world: scenario.yaml of a folder or written World, else built in memory."""
    from worldgen.export import scenario

    if isinstance(world, (str, Path)):
        return scenario.read(world)
    if getattr(world, "path", None) is not None and (Path(world.path) / SCENARIO_NAME).is_file():
        return scenario.read(world.path)
    return scenario.scenario(world)


def _task_spec(spec: dict, task_id: str) -> dict:
    for t in spec.get("tasks", []):
        if t.get("id") == task_id:
            return t
    return {"success_criteria": spec.get("success_criteria", []), "failure_conditions": spec.get("failure_conditions", [])}


def _succeeded(r: Run, task_spec: dict) -> tuple[bool, str]:
    """Does the run meet its scenario? (ok, the first reason it does not)."""
    limit = None
    for c in task_spec.get("success_criteria", []):
        if c.get("type") == "max_time":
            limit = float(c["seconds"])
    for c in task_spec.get("failure_conditions", []):
        if c.get("type") == "collision" and r.collisions:
            return False, f"collision with {r.collisions[0].entity} at t={r.collisions[0].time:.2f} s"
        if c.get("type") == "timeout" and limit is None:
            limit = float(c["seconds"])
    if not r.reached_goal:
        return False, "goal not reached"
    if limit is not None and r.time_to_goal is not None and r.time_to_goal > limit:
        return False, f"timeout: {r.time_to_goal:.2f} s > {limit:.2f} s"
    return True, ""


@dataclass(frozen=True)
class Criterion:
    """One criterion's verdict. ``margin`` is how far the measurement is on the good side (negative = failed by)."""

    section: str
    key: str
    op: str
    required: float
    measured: Optional[float]
    passed: bool
    margin: Optional[float]


class Report:
    """The verdict of :func:`evaluate`: per-criterion rows, per-run rows and the summary figures."""

    def __init__(self, criteria: list[Criterion], runs: list[dict], summary: dict):
        self.criteria = criteria
        self.runs = runs
        self.summary = summary

    @property
    def passed(self) -> bool:
        return all(c.passed for c in self.criteria)

    @property
    def failures(self) -> list[str]:
        """One line per failed criterion: which, what was required, what was measured, by how much."""
        out = []
        for c in self.criteria:
            if not c.passed:
                got = "nothing to measure" if c.measured is None else f"{c.measured:.6g}"
                by = "" if c.margin is None else f", failed by {-c.margin:.6g}"
                out.append(f"{c.section}.{c.key}: required {c.op} {c.required:.6g}, measured {got}{by}")
        return out

    def rows(self) -> list[dict[str, Any]]:
        return [{"criterion": f"{c.section}.{c.key}", "required": f"{c.op} {c.required:.6g}",
                 "measured": "n/a" if c.measured is None else f"{c.measured:.6g}",
                 "verdict": "PASS" if c.passed else "FAIL",
                 "margin": "" if c.margin is None else f"{c.margin:+.6g}"} for c in self.criteria]

    def __str__(self) -> str:
        rows = self.rows()
        head = ["criterion", "required", "measured", "verdict", "margin"]
        widths = [max([len(h)] + [len(r[h]) for r in rows]) for h in head]

        def line(cells):
            return "  ".join(c.ljust(w) for c, w in zip(cells, widths)).rstrip()

        out = [line(head), line(["-" * w for w in widths])] + [line([r[h] for h in head]) for r in rows]
        s = self.summary
        out.append(f"{s['runs']} runs, {s['successes']} succeeded: {'PASS' if self.passed else 'FAIL'}")
        return "\n".join(out)

    def to_dict(self) -> dict:
        return {"passed": self.passed, "failures": self.failures, "summary": self.summary,
                "criteria": [asdict(c) for c in self.criteria], "runs": self.runs}

    def write_json(self, path) -> Path:
        path = Path(path)
        path.write_text(json.dumps(self.to_dict(), indent=2, sort_keys=True) + "\n")
        return path

    def write_csv(self, path) -> Path:
        path = Path(path)
        buf = io.StringIO()
        w = csv.DictWriter(buf, fieldnames=["criterion", "required", "measured", "verdict", "margin"], lineterminator="\n")
        w.writeheader()
        w.writerows(self.rows())
        path.write_text(buf.getvalue())
        return path


def _runs(runs: Iterable) -> Iterable[tuple[Any, Any, Optional[str]]]:
    for i, item in enumerate(runs):
        if isinstance(item, Mapping):
            yield item["trajectory"], item["world"], item.get("task")
        elif isinstance(item, (tuple, list)) and len(item) in (2, 3):
            yield item[0], item[1], (item[2] if len(item) == 3 else None)
        else:
            raise ParameterError(f"parameter 'runs' item {i} must be (trajectory, world[, task]) or a dict with those keys")


def evaluate(runs: Iterable, criteria) -> Report:
    """Figures of every run (each a ``(trajectory, world[, task])`` or a dict), judged against ``criteria``."""
    crit = load_criteria(criteria)
    rows, figures = [], []
    for trajectory, world, task in _runs(runs):
        ground = load(world)
        r = run_figures(trajectory, ground, task)
        ok, why = _succeeded(r, _task_spec(scenario_of(world), r.task))
        figures.append((r, ok))
        rows.append(r.as_dict() | {"success": ok, "reason": why})
    if not figures:
        raise ParameterError("parameter 'runs' must hold at least one run, got none")
    good = [r for r, ok in figures if ok]
    times = [r.time_to_goal for r in good if r.time_to_goal is not None]
    eff = [r.path_efficiency for r, _ in figures if r.path_efficiency is not None]
    seps = [r.min_separation for r, _ in figures if r.min_separation is not None]
    summary = {
        "runs": len(figures), "successes": len(good),
        "success_rate": len(good) / len(figures),
        "mean_time_to_goal": sum(times) / len(times) if times else None,
        "max_time_to_goal": max(times) if times else None,
        "min_clearance": min(r.min_clearance for r, _ in figures),
        "mean_path_efficiency": sum(eff) / len(eff) if eff else None,
        "collision_count": sum(len(r.collisions) for r, _ in figures),
        "min_separation": min(seps) if seps else None,
        "max_velocity": max(r.max_velocity for r, _ in figures),
    }
    measured = {"success_rate": summary["success_rate"], "path_efficiency": summary["mean_path_efficiency"],
                "obstacle_clearance": summary["min_clearance"], "min_obstacle_distance": summary["min_separation"],
                "collision_tolerance": float(summary["collision_count"]), "max_velocity": summary["max_velocity"],
                "max_time": summary["max_time_to_goal"], "avg_time_to_goal": summary["mean_time_to_goal"]}
    verdicts = []
    for section in CRITERIA:  # a fixed order, whatever order the YAML had
        for key, (op, _) in CRITERIA[section].items():
            if key not in crit.get(section, {}):
                continue
            need, got = crit[section][key], measured[key]
            if got is None:
                # No movers means nothing can come near: that criterion holds; no success means no time: it fails.
                passed = key == "min_obstacle_distance"
                verdicts.append(Criterion(section, key, op, need, None, passed, None))
                continue
            margin = got - need if op == ">=" else need - got
            verdicts.append(Criterion(section, key, op, need, got, margin >= 0, margin))
    return Report(verdicts, rows, summary)
