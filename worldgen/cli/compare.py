"""``worldgen compare A B``: two report folders of ``worldgen judge`` (say simulation and real runs) compared.

The statistics are :func:`worldgen.judge.stats.compare_runs`; this module reads the two
report.json files, prints the table (or ``--json``), and turns every bad input into one line
(:class:`~worldgen.errors.ParameterError`, exit status 2).
"""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any, Optional

import click

from worldgen.cli.context import CONTEXT as _CONTEXT
from worldgen.errors import ParameterError, read_user_text
from worldgen.files import REPORT_JSON_NAME

__all__ = ["compare_command", "read_runs", "format_comparison"]



def read_runs(path) -> list[dict]:
    """The ``runs`` rows of a report folder's report.json (or of a report.json named directly)."""
    path = Path(path)
    if not path.exists():
        raise ParameterError(f"report folder '{path}' does not exist")
    file = path / REPORT_JSON_NAME if path.is_dir() else path
    if path.is_dir() and not file.is_file():
        raise ParameterError(f"'{path}' has no report.json; give a report folder written by 'worldgen judge'")
    text = read_user_text(file, "report")
    try:
        data = json.loads(text)
    except ValueError as exc:
        raise ParameterError(f"report '{file}' is not valid JSON ({exc})") from None
    runs = data.get("runs") if isinstance(data, dict) else None
    if not isinstance(runs, list) or not all(isinstance(r, dict) for r in runs):
        raise ParameterError(f"report '{file}' has no list of runs ('runs'); is it a report of 'worldgen judge'?")
    from worldgen.judge.stats import judged_runs

    if not judged_runs(runs):
        rows = f"{len(runs)} row{'' if len(runs) == 1 else 's'}"
        raise ParameterError(f"report '{file}' holds no judged run ({rows}, none with a verdict: every bag was "
                             "unjudged); nothing to compare")
    return runs


def _num(x: Any, spec: str = ".4g") -> str:
    if x is None:
        return "n/a"
    return x if isinstance(x, str) else format(x, spec)


def _p(x: Optional[float]) -> str:
    return "n/a" if x is None else ("<0.0001" if x < 1e-4 else f"{x:.4f}")


def format_comparison(result: dict, name_a: str, name_b: str) -> str:
    """The readable table of a :func:`~worldgen.judge.stats.compare_runs` result."""
    s = result["success"]
    conf = f"{result['confidence']:.0%}"
    unjudged = result["unjudged"]
    out = [f"A: {name_a} ({result['runs']['a']} judged runs, {unjudged['a']} unjudged)    "
           f"B: {name_b} ({result['runs']['b']} judged runs, {unjudged['b']} unjudged)"]
    if unjudged["a"] or unjudged["b"]:
        out.append("unjudged bags (no verdict: unreadable, or their world not found) are left out of every test below")
    out.append("")

    def side(x: dict) -> str:
        return f"{x['successes']}/{x['runs']} = {x['rate']:.3f} ({conf} CI {x['ci'][0]:.3f}-{x['ci'][1]:.3f})"

    out.append(f"success  A {side(s['a'])}   B {side(s['b'])}")
    out.append(f"         risk difference A - B {s['risk_difference']:+.3f}, odds ratio {_num(s['odds_ratio'])}, "
               f"Fisher's exact p = {_p(s['p'])}")
    out.append("")
    head = ["figure", "over", "n A", "n B", "mean A", "mean B", f"A - B ({conf} CI)", "Welch p", "Hedges g",
            "MWU p", "rank-biserial"]
    rows = []
    for name, f in result["figures"].items():
        cells = [name, f["over"].split()[0], str(f["n_a"]), str(f["n_b"]), _num(f["mean_a"]), _num(f["mean_b"])]
        if "too_few" in f:
            rows.append(cells + [f["too_few"]])
            continue
        w, m = f["welch"], f["mann_whitney"]
        ci = f"{w['difference']:+.4g} ({_num(w['ci_low'])}, {_num(w['ci_high'])})"
        rows.append(cells + [ci, _p(w["p"]), _num(w["hedges_g"], "+.3f"), _p(m["p"]), f"{m['rank_biserial']:+.3f}"])
    full = [r for r in rows if len(r) == len(head)]  # a "too few runs" row's note may run past its column
    widths = [max([len(h)] + [len(r[i]) for r in full + [r[:6] for r in rows]]) if i < 6 else
              max([len(h)] + [len(r[i]) for r in full]) for i, h in enumerate(head)]

    def line(cells: list[str]) -> str:
        return "  ".join(c.ljust(w) for c, w in zip(cells, widths)).rstrip()

    out += [line(head), line(["-" * w for w in widths])] + [line(r) for r in rows]
    out += ["", "time and path figures are over successful runs only; a run without a figure is left out of it.",
            result["note"]]
    return "\n".join(out)


@click.command("compare", context_settings=_CONTEXT)
@click.argument("a", type=click.Path(path_type=Path))
@click.argument("b", type=click.Path(path_type=Path))
@click.option("--json", "as_json", is_flag=True, help="Print the comparison as JSON (stable key order).")
@click.option("--confidence", type=click.FloatRange(0.5, 1.0, max_open=True), default=0.95, show_default=True,
              help="Confidence of the intervals (difference of means, success rates).")
def compare_command(a: Path, b: Path, as_json: bool, confidence: float) -> None:
    """Compare two report folders of 'worldgen judge' (A, B: e.g. simulation and real runs).

    Fisher's exact test on success counts; Welch's t-test and Mann-Whitney U on time to goal, path
    length and path efficiency (successful runs), minimum clearance, maximum speed and BARN score
    (all runs); with effect sizes and counts. A large p-value means the runs cannot tell A and B
    apart, not that they are the same.

    \b
    Examples:
      worldgen compare reports/sim reports/real
      worldgen compare reports/sim reports/real --json > comparison.json
    """
    from worldgen.judge.stats import compare_runs

    runs_a, runs_b = read_runs(a), read_runs(b)
    result = compare_runs(runs_a, runs_b, confidence=confidence)
    if as_json:
        click.echo(json.dumps({"a": str(a), "b": str(b)} | result, indent=2, sort_keys=True))
        return
    click.echo(format_comparison(result, str(a), str(b)))
