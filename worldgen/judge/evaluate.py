"""Judge many runs in many worlds against acceptance criteria read from YAML.

Usage (an example that runs is in :mod:`worldgen.testing.oracles`)::

    report = evaluate([(trajectory, world), ...], "criteria.yaml")
    print(report)                 # a table: criterion, required, measured, verdict, by how much
    report.passed, report.failures
    report.write_csv("report.csv"); report.write_json("report.json")

The criteria file's sections and keys are in :mod:`worldgen.judge.criteria`.
What is averaged over what, so that a crash cannot flatter a figure:

- success rate: every run; in its confidence form (``success_rate: {min: 0.95, confidence: 0.95}``)
  the one-sided Clopper-Pearson lower bound must reach ``min``, and the report says how many more
  clean runs would get it there (:mod:`worldgen.judge.stats`);
- path efficiency and time to goal: successful runs only, as BARN and Arena average them (a run
  that crashed at 65 % of the path is short, not efficient);
- BARN score: every run, failures scoring 0; clearance, contacts, speed: every run.

``summary["per_world"]`` breaks every figure down by world: the runs in one world are repeats, the
worlds a sample.

A run succeeds when it meets its world's scenario (scenario.yaml, read from the
folder or built from the World): it reaches the goal waypoint within tolerance,
within ``max_time``, and no failure condition (collision, timeout) occurred.
"""

from __future__ import annotations

import csv
import io
import json
from dataclasses import asdict, dataclass
from pathlib import Path
from typing import Any, Iterable, Mapping, Optional, Union

from worldgen.errors import ParameterError
from worldgen.files import SCENARIO_NAME
from worldgen.groundtruth.ground import load
from worldgen.judge.criteria import CRITERIA, SCORING, load_criteria
from worldgen.judge.figures import Run, barn_score
from worldgen.judge.figures import run as run_figures

__all__ = ["CRITERIA", "AVERAGED_OVER", "Criterion", "Report", "load_criteria", "evaluate", "scenario_of"]

#: Which runs each summary figure is taken over (written into every report's summary).
AVERAGED_OVER = {
    "success_rate": "all runs", "path_efficiency": "successful runs", "time_to_goal": "successful runs",
    "barn_score": "all runs (failed runs score 0; runs without a reference path are left out)",
    "min_clearance": "all runs (smallest)", "collision_count": "all runs (total)",
    "max_velocity": "all runs (largest)", "min_separation": "all runs (smallest)",
    "min_person_distance": "all runs (smallest)", "personal_space_time": "all runs (largest)",
    "min_time_to_collision": "all runs (smallest)",
}


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
    """One criterion's verdict. ``margin`` is how far the measurement is on the good side (negative = failed by).

    For ``success_rate`` in its confidence form, ``measured`` is the one-sided Clopper-Pearson lower
    bound at ``confidence``, ``successes``/``runs`` the counts it comes from, and ``more_clean_runs``
    how many more successful runs would make the bound reach ``required`` (0 when it does; "never"
    when no run count can, a required rate of 1).
    """

    section: str
    key: str
    op: str
    required: float
    measured: Optional[float]
    passed: bool
    margin: Optional[float]
    confidence: Optional[float] = None
    successes: Optional[int] = None
    runs: Optional[int] = None
    more_clean_runs: Union[int, str, None] = None

    @property
    def more_text(self) -> str:
        """What more runs would do, for the confidence form ('' when it passes or is another criterion)."""
        more = self.more_clean_runs
        if self.confidence is None or not more:
            return ""
        if more == "never":
            return "no number of further runs would make it pass"
        return f"{more} more clean run{'s' if more != 1 else ''} would make it pass"

    @property
    def bound_text(self) -> str:
        """How the confidence form reads (empty for every other criterion)."""
        if self.confidence is None:
            return ""
        head = (f"one-sided {self.confidence:.0%} Clopper-Pearson lower bound of {self.successes}/{self.runs} "
                f"= {self.measured:.4f}")
        return f"{head}; {self.more_text}" if self.more_text else head


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
                if c.confidence is not None:
                    got = f"lower bound {got} ({c.successes}/{c.runs} at {c.confidence:.0%} confidence)"
                by = "" if c.margin is None else f", failed by {-c.margin:.6g}"
                more = f"; {c.more_text}" if c.more_text else ""
                out.append(f"{c.section}.{c.key}: required {c.op} {c.required:.6g}, measured {got}{by}{more}")
        return out

    def rows(self) -> list[dict[str, Any]]:
        out = []
        for c in self.criteria:
            measured = "n/a" if c.measured is None else f"{c.measured:.6g}"
            required = f"{c.op} {c.required:.6g}"
            if c.confidence is not None:  # the bound, and the counts it is a bound of
                required += f" ({c.confidence:.0%} conf.)"
                measured += f" ({c.successes}/{c.runs})"
            out.append({"criterion": f"{c.section}.{c.key}", "required": required, "measured": measured,
                        "verdict": "PASS" if c.passed else "FAIL",
                        "margin": "" if c.margin is None else f"{c.margin:+.6g}"})
        return out

    def notes(self) -> list[str]:
        """What the table's figures are taken over, and the confidence bound in words."""
        out = [f"{c.section}.{c.key}: {c.bound_text}" for c in self.criteria if c.confidence is not None]
        out.append("path efficiency and time to goal: means over successful runs only")
        return out

    def __str__(self) -> str:
        rows = self.rows()
        head = ["criterion", "required", "measured", "verdict", "margin"]
        widths = [max([len(h)] + [len(r[h]) for r in rows]) for h in head]

        def line(cells):
            return "  ".join(c.ljust(w) for c, w in zip(cells, widths)).rstrip()

        out = [line(head), line(["-" * w for w in widths])] + [line([r[h] for h in head]) for r in rows]
        out += self.notes()
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


def _runs(runs: Iterable) -> Iterable[tuple[Any, Any, Optional[str], Optional[str]]]:
    """(trajectory, world, task, refused) of each run; ``refused`` is the reason a run failed unmeasured."""
    for i, item in enumerate(runs):
        if isinstance(item, Mapping) and item.get("refused") is not None:
            yield None, item["world"], item.get("task"), str(item["refused"])
        elif isinstance(item, Mapping):
            yield item["trajectory"], item["world"], item.get("task"), None
        elif isinstance(item, (tuple, list)) and len(item) in (2, 3):
            yield item[0], item[1], (item[2] if len(item) == 3 else None), None
        else:
            raise ParameterError(f"parameter 'runs' item {i} must be (trajectory, world[, task]) or a dict with those keys")


def _mean(xs: list[float]) -> Optional[float]:
    return sum(xs) / len(xs) if xs else None


#: One judged run: its figures (None for a run refused unmeasured, a failure), success, BARN score, world id.
_Judged = tuple[Optional[Run], bool, Optional[float], str]


def _figures(judged: list[_Judged]) -> dict[str, Any]:
    """The summary figures of some judged runs, each over the runs AVERAGED_OVER says."""
    good = [r for r, ok, _, _ in judged if ok and r is not None]
    times = [r.time_to_goal for r in good if r.time_to_goal is not None]
    scores = [s for _, _, s, _ in judged if s is not None]
    return {
        "runs": len(judged), "successes": len(good), "success_rate": len(good) / len(judged),
        "mean_time_to_goal": _mean(times), "max_time_to_goal": max(times) if times else None,
        "mean_path_efficiency": _mean([r.path_efficiency for r in good if r.path_efficiency is not None]),
        "mean_barn_score": _mean(scores),
        "min_clearance": min((r.min_clearance for r, *_ in judged if r is not None), default=None),
    }


def _refused_row(ground, task: Optional[str], reason: str, k: float, speed: float) -> tuple[dict, _Judged]:
    """The row of a run that failed before it could be measured (it started far from the spawn, or names
    another world): a failure with its reason and no figures, counted in every rate."""
    t = ground.task(task)
    ref = (t.get("path") or {}).get("length")
    score = barn_score(False, None, float(ref) if ref else None, k, speed)
    world_id = str(ground.meta.get("world_id", ""))
    row = {"world_id": world_id, "task": t["id"], "reference_length": float(ref) if ref else None,
           "success": False, "reason": reason, "barn_score": score}
    return row, (None, False, score, world_id)


# long: each run's figures, then the criteria over all of them, in one place so the rows stay aligned
def evaluate(runs: Iterable, criteria, *, barn_k: Optional[float] = None,
             reference_speed: Optional[float] = None) -> Report:
    """Figures of every run (each a ``(trajectory, world[, task])`` or a dict), judged against ``criteria``.

    A dict ``{"world", "task", "refused": reason}`` (no trajectory) is a run that failed before it
    could be measured: a failure with that reason, counted in the rates, with no figures.

    ``barn_k`` and ``reference_speed`` set the BARN score (the criteria file's ``scoring`` section
    otherwise, else BARN's current 2 optimal times and 2 m/s).
    """
    crit = load_criteria(criteria)
    scoring = {key: default for key, (default, _) in SCORING.items()} | crit.pop("scoring", {})
    k = scoring["barn_k"] if barn_k is None else barn_k
    speed = scoring["reference_speed"] if reference_speed is None else reference_speed
    rows, judged = [], []
    for trajectory, world, task, refused in _runs(runs):
        ground = load(world)
        if refused is not None:
            row, item = _refused_row(ground, task, refused, k, speed)
            rows.append(row)
            judged.append(item)
            continue
        r = run_figures(trajectory, ground, task)
        ok, why = _succeeded(r, _task_spec(scenario_of(world), r.task))
        score = barn_score(ok, r.time_to_goal, r.reference_length, k, speed)
        judged.append((r, ok, score, r.world_id))
        rows.append(r.as_dict() | {"success": ok, "reason": why, "barn_score": score})
    if not judged:
        raise ParameterError("parameter 'runs' must hold at least one run, got none")
    measured_runs = [r for r, *_ in judged if r is not None]
    seps = [r.min_separation for r in measured_runs if r.min_separation is not None]

    def extreme(pick, key):  # over the runs that have the figure (worlds with people); None without any
        values = [getattr(r, key) for r in measured_runs if getattr(r, key) is not None]
        return pick(values) if values else None

    by_world: dict[str, list] = {}
    for item in judged:
        by_world.setdefault(item[3], []).append(item)
    summary = _figures(judged) | {
        "collision_count": sum(len(r.collisions) for r in measured_runs),
        "min_separation": min(seps) if seps else None,
        "max_velocity": max((r.max_velocity for r in measured_runs), default=None),
        "min_person_distance": extreme(min, "min_person_distance"),
        "personal_space_time": extreme(max, "personal_space_time"),
        "min_time_to_collision": extreme(min, "min_time_to_collision"),
        "worlds": len(by_world),
        "per_world": {w: _figures(items) for w, items in sorted(by_world.items())},
        "averaged_over": AVERAGED_OVER, "barn": {"k": k, "reference_speed": speed},
    }
    measured = {"success_rate": summary["success_rate"], "path_efficiency": summary["mean_path_efficiency"],
                "obstacle_clearance": summary["min_clearance"], "min_obstacle_distance": summary["min_separation"],
                "collision_tolerance": float(summary["collision_count"]), "max_velocity": summary["max_velocity"],
                "max_time": summary["max_time_to_goal"], "avg_time_to_goal": summary["mean_time_to_goal"],
                "barn_score": summary["mean_barn_score"], "min_person_distance": summary["min_person_distance"],
                "personal_space_time": summary["personal_space_time"],
                "min_time_to_collision": summary["min_time_to_collision"]}
    verdicts = []
    for section in CRITERIA:  # a fixed order, whatever order the YAML had
        for key, (op, _) in CRITERIA[section].items():
            if key not in crit.get(section, {}):
                continue
            need, got = crit[section][key], measured[key]
            if isinstance(need, dict):  # success_rate: {min, confidence}
                verdicts.append(_bound_verdict(section, key, op, need, summary["successes"], summary["runs"]))
                continue
            if got is None:
                # No movers or people means nothing can come near (nor a collision course): those criteria
                # hold; no success means no time: it fails.
                passed = key in ("min_obstacle_distance", "min_person_distance", "personal_space_time",
                                 "min_time_to_collision")
                verdicts.append(Criterion(section, key, op, need, None, passed, None))
                continue
            margin = got - need if op == ">=" else need - got
            verdicts.append(Criterion(section, key, op, need, got, margin >= 0, margin))
    return Report(verdicts, rows, summary)


def _bound_verdict(section: str, key: str, op: str, need: dict, k: int, n: int) -> Criterion:
    from worldgen.judge.stats import success_bound

    b = success_bound(k, n, need["min"], need["confidence"])
    return Criterion(section, key, op, need["min"], b["lower_bound"], b["passed"], b["lower_bound"] - need["min"],
                     confidence=need["confidence"], successes=k, runs=n, more_clean_runs=b["more_clean_runs"])
