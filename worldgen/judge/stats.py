"""The statistics behind honest verdicts: a success rate's confidence bound, and two sets of runs compared.

Pure functions over counts and samples, returning plain dicts, on :mod:`scipy.stats`
(the optional ``stats`` extra, imported on first use):

    >>> round(success_bound(19, 20, minimum=0.95, confidence=0.95)["lower_bound"], 4)
    0.7839
    >>> runs_needed(19, 20, minimum=0.95, confidence=0.95)                    # clean runs to add
    73
    >>> compare_runs(runs_a, runs_b)  # doctest: +SKIP
    ... # Welch, Mann-Whitney U, Fisher, with effect sizes and counts (docs/statistics.md)

A success rate over n runs is a binomial proportion; its one-sided Clopper-Pearson lower
bound at confidence c is the (1 - c) quantile of Beta(k, n - k + 1) (0 when k = 0): the
smallest rate that would still give k or more successes with probability 1 - c. See
docs/statistics.md for how to read every figure here.
"""

from __future__ import annotations

import math
import warnings
from numbers import Integral
from typing import Any, Optional, Sequence, Union

from worldgen.errors import ParameterError, require_optional
from worldgen.floats import finite_or_none  # None where scipy gives NaN or an infinity: JSON has neither

__all__ = [
    "INSTALL_HINT", "FIGURES", "NOTE", "require_scipy",
    "judged_runs", "clopper_pearson_lower", "clopper_pearson_interval", "wilson_interval", "runs_needed", "success_bound",
    "welch", "mann_whitney", "fisher", "compare_samples", "compare_runs",
]

#: What to install for the statistics (the ``stats`` extra of worldgen's pyproject.toml).
INSTALL_HINT = "pip install 'worldgen[stats]'"

#: The continuous figures of a judged run and which runs each is taken over: time and path figures
#: mean something only for runs that arrived (as BARN and Arena average them); the rest over all runs.
FIGURES: dict[str, str] = {
    "time_to_goal": "successful", "path_length": "successful", "path_efficiency": "successful",
    "min_clearance": "all", "max_velocity": "all", "barn_score": "all",
}

#: Said with every comparison, because a large p-value is so often read the wrong way.
NOTE = ("A large p-value means these runs cannot tell A and B apart, not that A and B are the same; "
        "a small one means a difference this large would be rare if they were.")

#: The fewest values per side a continuous test is run on (a sample variance needs two).
MIN_SAMPLE = 2


def require_scipy():
    """The ``scipy.stats`` module, or :class:`MissingDependencyError` naming the ``stats`` extra."""
    return require_optional("scipy.stats", "stats", "worldgen's statistics need scipy")


def _check_counts(k: int, n: int) -> None:
    integers = all(isinstance(x, Integral) and not isinstance(x, bool) for x in (k, n))
    if not integers or not 0 <= k <= n:
        raise ParameterError(f"counts must be integers with 0 <= successes <= runs, got {k!r} of {n!r}")


def _check_confidence(confidence: float) -> None:
    if isinstance(confidence, bool) or not isinstance(confidence, (int, float)) or not 0 < confidence < 1:
        raise ParameterError(f"confidence must be a number in (0, 1), e.g. 0.95, got {confidence!r}")


def clopper_pearson_lower(k: int, n: int, confidence: float = 0.95) -> float:
    """One-sided exact (Clopper-Pearson) lower bound on a success rate from k successes in n runs."""
    _check_counts(k, n)
    _check_confidence(confidence)
    if k == 0:
        return 0.0
    return float(require_scipy().beta.ppf(1.0 - confidence, k, n - k + 1))


def clopper_pearson_interval(k: int, n: int, confidence: float = 0.95) -> tuple[float, float]:
    """Two-sided exact (Clopper-Pearson) interval on a success rate; (0, 1) when there are no runs."""
    _check_counts(k, n)
    _check_confidence(confidence)
    if n == 0:
        return 0.0, 1.0
    ci = require_scipy().binomtest(k, n).proportion_ci(confidence_level=confidence, method="exact")
    return float(ci.low), float(ci.high)


def wilson_interval(k: int, n: int, confidence: float = 0.95) -> tuple[float, float]:
    """Two-sided Wilson score interval on a success rate (the one BARN-style tables use; narrower than
    Clopper-Pearson, never outside [0, 1]); (0, 1) when there are no runs."""
    _check_counts(k, n)
    _check_confidence(confidence)
    if n == 0:
        return 0.0, 1.0
    z = float(require_scipy().norm.ppf(0.5 + confidence / 2.0))
    p, zz = k / n, z * z
    centre = (p + zz / (2 * n)) / (1 + zz / n)
    half = z * math.sqrt(p * (1 - p) / n + zz / (4 * n * n)) / (1 + zz / n)
    return max(0.0, centre - half), min(1.0, centre + half)


def runs_needed(k: int, n: int, minimum: float, confidence: float = 0.95) -> Optional[int]:
    """The fewest clean runs m such that k + m successes of n + m runs have a lower bound >= ``minimum``.

    0 when the bound already holds; None when no number of runs can do it (``minimum`` 1: the bound
    of any finite run count stays below 1). The bound grows with every added success, so the
    smallest m is found by doubling, then halving.
    """
    _check_counts(k, n)
    if not 0 <= minimum <= 1:
        raise ParameterError(f"minimum must be in [0, 1], got {minimum!r}")

    def holds(m: int) -> bool:
        return clopper_pearson_lower(k + m, n + m, confidence) >= minimum

    if holds(0):
        return 0
    if minimum >= 1:
        return None
    low, high = 0, 1  # holds(low) is False
    while not holds(high):
        low, high = high, high * 2
    while high - low > 1:
        mid = (low + high) // 2
        low, high = (low, mid) if holds(mid) else (mid, high)
    return high


def success_bound(k: int, n: int, minimum: float, confidence: float = 0.95) -> dict[str, Any]:
    """The confidence form of a success-rate criterion: the bound, the verdict, and the runs still needed."""
    bound = clopper_pearson_lower(k, n, confidence)
    more = runs_needed(k, n, minimum, confidence)
    return {"successes": k, "runs": n, "rate": k / n if n else None, "confidence": confidence,
            "minimum": minimum, "lower_bound": bound, "passed": bound >= minimum,
            "more_clean_runs": "never" if more is None else more}


# -- comparing two sets of runs ---------------------------------------------------------------

def _mean(xs: Sequence[float]) -> float:
    # Equal values have that value as their mean exactly (a sum divided back can be off by an ulp).
    return xs[0] if len(set(xs)) == 1 else math.fsum(xs) / len(xs)


def _var(xs: Sequence[float]) -> float:
    if len(set(xs)) == 1:
        return 0.0
    m = _mean(xs)
    return math.fsum((x - m) ** 2 for x in xs) / (len(xs) - 1)


def welch(a: Sequence[float], b: Sequence[float], confidence: float = 0.95) -> dict[str, Any]:
    """Welch's t-test (unequal variances) of mean(A) - mean(B), its confidence interval, and Hedges' g.

    g is the difference over the pooled standard deviation (Cohen's d) times the exact small-sample
    correction J = Gamma(df/2) / (sqrt(df/2) Gamma((df-1)/2)), df = nA + nB - 2.
    """
    _check_confidence(confidence)
    st = require_scipy()
    na, nb = len(a), len(b)
    diff = _mean(a) - _mean(b)
    va, vb = _var(a), _var(b)
    out: dict[str, Any] = {"difference": diff, "ci_low": None, "ci_high": None, "t": None, "df": None, "p": None,
                           "cohens_d": None, "hedges_g": None}
    if va == 0 and vb == 0:  # no spread: t is undefined, the difference is exact
        out["ci_low"] = out["ci_high"] = diff
        out["p"] = 1.0 if diff == 0 else 0.0
        return out
    with warnings.catch_warnings():
        # scipy warns of precision loss when one side's values are all equal; its variance is then 0
        # (the other side carries the spread) and the test is well defined.
        warnings.filterwarnings("ignore", "Precision loss occurred", RuntimeWarning)
        res = st.ttest_ind(a, b, equal_var=False)
    ci = res.confidence_interval(confidence_level=confidence)
    out.update(t=finite_or_none(res.statistic), df=finite_or_none(res.df), p=finite_or_none(res.pvalue),
               ci_low=finite_or_none(ci.low), ci_high=finite_or_none(ci.high))
    pooled = math.sqrt(((na - 1) * va + (nb - 1) * vb) / (na + nb - 2))
    d = diff / pooled
    df = na + nb - 2
    j = math.exp(math.lgamma(df / 2) - math.lgamma((df - 1) / 2)) / math.sqrt(df / 2) if df > 1 else None
    out.update(cohens_d=d, hedges_g=None if j is None else d * j)
    return out


def mann_whitney(a: Sequence[float], b: Sequence[float]) -> dict[str, Any]:
    """Mann-Whitney U (two-sided) and the rank-biserial correlation r = P(A > B) - P(A < B), in [-1, 1]."""
    st = require_scipy()
    if len(set(a) | set(b)) == 1:  # every value the same: no ranks to compare
        return {"u": len(a) * len(b) / 2, "p": 1.0, "rank_biserial": 0.0}
    res = st.mannwhitneyu(a, b, alternative="two-sided")
    u = float(res.statistic)  # U of A: pairs where A is larger, ties counted half
    return {"u": u, "p": finite_or_none(res.pvalue), "rank_biserial": 2.0 * u / (len(a) * len(b)) - 1.0}


def fisher(ka: int, na: int, kb: int, nb: int, confidence: float = 0.95) -> dict[str, Any]:
    """Fisher's exact test on successes of A against B, the odds ratio, the risk difference and each side's rate.

    The odds ratio is the sample one, (kA (nB - kB)) / ((nA - kA) kB): "inf" when only the
    denominator is 0, None when both are. Each rate carries its two-sided Clopper-Pearson interval.
    """
    _check_counts(ka, na)
    _check_counts(kb, nb)
    st = require_scipy()
    res = st.fisher_exact([[ka, na - ka], [kb, nb - kb]])
    num, den = ka * (nb - kb), (na - ka) * kb
    odds: Union[float, str, None] = num / den if den else ("inf" if num else None)
    return {"p": float(res.pvalue), "odds_ratio": odds, "risk_difference": ka / na - kb / nb,
            "a": {"successes": ka, "runs": na, "rate": ka / na, "ci": list(clopper_pearson_interval(ka, na, confidence))},
            "b": {"successes": kb, "runs": nb, "rate": kb / nb, "ci": list(clopper_pearson_interval(kb, nb, confidence))}}


def compare_samples(a: Sequence[float], b: Sequence[float], confidence: float = 0.95) -> dict[str, Any]:
    """Both tests of one continuous figure with counts, means and medians; ``too_few`` where a side lacks data."""
    out: dict[str, Any] = {"n_a": len(a), "n_b": len(b)}
    for side, xs in (("a", a), ("b", b)):
        s = sorted(xs)
        out[f"mean_{side}"] = _mean(s) if s else None
        out[f"median_{side}"] = (s[(len(s) - 1) // 2] + s[len(s) // 2]) / 2 if s else None
    if len(a) < MIN_SAMPLE or len(b) < MIN_SAMPLE:
        out["too_few"] = f"too few runs (A {len(a)}, B {len(b)}; need {MIN_SAMPLE} on each side)"
        return out
    out["welch"] = welch(a, b, confidence)
    out["mann_whitney"] = mann_whitney(a, b)
    return out


def judged_runs(runs: Sequence[dict]) -> list[dict]:
    """Runs with a verdict (success True or False); an unjudged row (a bag that could not be read, or whose
    world was not found: ``outcome`` "unjudged", or ``readable`` False in reports of older versions) is left out."""
    return [r for r in runs if isinstance(r.get("success"), bool) and r.get("outcome") != "unjudged"
            and r.get("readable") is not False]


#: Significant digits a figure is compared at. Figures computed two ways (a path length summed in
#: another order) differ in the last bits; at full precision the t-test reads that noise as a
#: difference (p = 0.12 on differences of 1e-16 m).
SIGNIFICANT_DIGITS = 12


def _values(runs: Sequence[dict], figure: str) -> list[float]:
    out = []
    for r in runs:
        v = r.get(figure)
        if isinstance(v, (int, float)) and not isinstance(v, bool) and math.isfinite(v):
            out.append(float(f"{v:.{SIGNIFICANT_DIGITS}g}"))
    return out


def compare_runs(runs_a: Sequence[dict], runs_b: Sequence[dict], confidence: float = 0.95) -> dict[str, Any]:
    """Two sets of judged runs (report.json ``runs`` rows) compared figure by figure.

    Fisher's exact test on success counts; Welch's t-test and Mann-Whitney U on each figure of
    :data:`FIGURES`, over the runs it names (successful ones for time and path figures). A row
    missing a figure (None: not measured) is left out of that figure only.
    """
    _check_confidence(confidence)
    a, b = judged_runs(runs_a), judged_runs(runs_b)
    if not a or not b:
        raise ParameterError(f"each side needs at least one judged run, got A {len(a)}, B {len(b)}")
    ka, kb = sum(r["success"] for r in a), sum(r["success"] for r in b)
    figures = {}
    for name, over in FIGURES.items():
        pick_a = [r for r in a if r["success"]] if over == "successful" else a
        pick_b = [r for r in b if r["success"]] if over == "successful" else b
        figures[name] = {"over": f"{over} runs", **compare_samples(_values(pick_a, name), _values(pick_b, name), confidence)}
    return {"confidence": confidence,
            "runs": {"a": len(a), "b": len(b)},
            "unjudged": {"a": len(runs_a) - len(a), "b": len(runs_b) - len(b)},
            "success": fisher(ka, len(a), kb, len(b), confidence),
            "figures": figures, "note": NOTE}
