"""The failure map: how often the system failed in each bin of each dimension, with exact confidence bounds.

For every dimension of the space (each range parameter cut into :data:`BINS` equal bins over its range, each
list of choices by value) and every descriptor of the worlds (level, people, door state, generator, narrowest
passage in bands of :data:`~worldgen.campaign.space.PASSAGE_BIN`), the judged runs that fell in each bin are
counted: the failure rate ``failed / judged`` with its two-sided Clopper-Pearson interval (the project's
statistics, :mod:`worldgen.judge.stats`). Unjudged runs are in no rate: they are neither a pass nor a failure.
Plots: one PNG per dimension with more than one bin, the rate and its interval per bin (matplotlib).
"""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any, Iterable, Mapping, Sequence

from worldgen.campaign.recipe import Entry
from worldgen.campaign.space import PASSAGE_BIN
from worldgen.errors import require_optional

__all__ = ["failure_map", "map_rows_csv", "plot_map", "BINS", "CONFIDENCE", "MAP_COLUMNS"]

#: Equal bins each range parameter is cut into.
BINS = 5
#: Confidence of every interval of the map.
CONFIDENCE = 0.95
MAP_COLUMNS = ["dimension", "bin", "judged", "failed", "rate", "low", "high"]
_DESCRIPTOR_DIMS = ("level", "people", "door_state", "generator")


def _edges(entries: Sequence[Entry]) -> dict[str, tuple[float, float, bool]]:
    found: dict[str, tuple[float, float, bool]] = {}
    for entry in entries:
        for name, r in entry.ranges:
            lo, hi, integer = found.get(name, (r.low, r.high, r.integer))
            found[name] = (min(lo, r.low), max(hi, r.high), integer and r.integer)
    return found


def _range_bin(value: float, lo: float, hi: float, integer: bool) -> tuple[int, str]:
    if hi <= lo:
        return 0, f"{lo:g}"
    if integer and hi - lo + 1 <= BINS:  # few integers: one bin each
        return int(value - lo), f"{int(value)}"
    width = (hi - lo) / BINS
    k = min(int((value - lo) / width), BINS - 1)
    a, b = lo + k * width, lo + (k + 1) * width
    return k, f"[{a:.3g}, {b:.3g}{']' if k == BINS - 1 else ')'}"


def _order(value: Any) -> tuple:
    return (0, value, "") if isinstance(value, (int, float)) and not isinstance(value, bool) else (1, 0, str(value))


def failure_map(records: Iterable[Mapping[str, Any]], entries: Sequence[Entry]) -> list[dict[str, Any]]:
    """Rows (dimension, bin, judged, failed, rate, low, high) over the judged runs of ``records``."""
    from worldgen.judge.stats import clopper_pearson_interval

    edges = _edges(entries)
    choice_names = sorted({name for e in entries for name, _ in e.choices})
    counts: dict[tuple[str, tuple, str], list[int]] = {}
    for rec in records:
        desc, params = rec["descriptors"], rec["point"]["params"]
        places: list[tuple[str, tuple, str]] = [(d, _order(desc.get(d)), str(desc.get(d))) for d in _DESCRIPTOR_DIMS]
        passage = desc.get("narrowest_passage")
        if passage is not None:
            k = int(passage // PASSAGE_BIN)
            places.append(("narrowest_passage", (0, k, ""), f"[{k * PASSAGE_BIN:.2f}, {(k + 1) * PASSAGE_BIN:.2f})"))
        for name, (lo, hi, integer) in sorted(edges.items()):
            if name in params and name != "n_people":  # the people descriptor counts them
                k, label = _range_bin(params[name], lo, hi, integer)
                places.append((name, (0, k, ""), label))
        for name in choice_names:
            if name in params and name != "n_people":
                value = params[name]
                label = json.dumps(value) if isinstance(value, list) else str(value)
                places.append((name, _order(label), label))
        for r in rec.get("runs", ()):
            if r["verdict"] not in ("passed", "failed"):
                continue
            for place in places:
                c = counts.setdefault(place, [0, 0])
                c[0] += 1
                c[1] += r["verdict"] == "failed"
    rows = []
    for (dim, _, label), (judged, failed) in sorted(counts.items(), key=lambda kv: (kv[0][0], kv[0][1])):
        low, high = clopper_pearson_interval(failed, judged, CONFIDENCE)
        rows.append({"dimension": dim, "bin": label, "judged": judged, "failed": failed, "rate": failed / judged,
                     "low": low, "high": high})
    return rows


def map_rows_csv(rows: Sequence[Mapping[str, Any]]) -> bytes:
    import csv
    import io

    buf = io.StringIO()
    w = csv.writer(buf, lineterminator="\n")
    w.writerow(MAP_COLUMNS)
    for r in rows:
        w.writerow([f"{r[k]:.4f}" if isinstance(r[k], float) else r[k] for k in MAP_COLUMNS])
    return buf.getvalue().encode()


def plot_map(rows: Sequence[Mapping[str, Any]], folder: Path, title: str) -> list[Path]:
    """One PNG per dimension with more than one bin in ``folder``; returns their paths."""
    require_optional("matplotlib", "campaign", "the campaign's failure-map plots need matplotlib")
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    from worldgen.files import write_atomically

    folder.mkdir(parents=True, exist_ok=True)
    written = []
    for dim in sorted({r["dimension"] for r in rows}):
        mine = [r for r in rows if r["dimension"] == dim]
        if len(mine) < 2:
            continue
        fig, ax = plt.subplots(figsize=(max(5.6, 0.7 * len(mine) + 2), 3.2), dpi=100)
        xs = range(len(mine))
        rates = [r["rate"] for r in mine]
        err = [[r["rate"] - r["low"] for r in mine], [r["high"] - r["rate"] for r in mine]]
        ax.errorbar(xs, rates, yerr=err, fmt="o", color="#c0392b", ecolor="#7f8c8d", capsize=4)
        for x, r in zip(xs, mine):
            ax.annotate(f"{r['failed']}/{r['judged']}", (x, r["high"]), textcoords="offset points", xytext=(0, 4),
                        ha="center", fontsize=7)
        ax.set_xticks(list(xs), [r["bin"] for r in mine], rotation=30 if len(mine) > 6 else 0, fontsize=8)
        ax.set_ylim(0, 1.14)
        ax.set_ylabel("failure rate")
        ax.set_xlabel(dim)
        ax.set_title(f"{title}: failures by {dim} ({int(CONFIDENCE * 100)} % Clopper-Pearson)", fontsize=9)
        fig.tight_layout()
        path = folder / f"{dim}.png"
        buf = _png(fig)
        plt.close(fig)
        write_atomically(path, buf)
        written.append(path)
    return written


def _png(fig) -> bytes:
    import io

    buf = io.BytesIO()
    fig.savefig(buf, format="png", metadata={"Software": None})
    return buf.getvalue()

