"""worldgen.judge.stats against reference values: known binomial bounds, scipy on fixed samples, and an
independent computation from first principles (binomial and hypergeometric sums with math.comb) where cheap."""

import math
import sys
import warnings

import pytest
import scipy.stats
from hypothesis import given, settings
from hypothesis import strategies as st

from worldgen.errors import MissingDependencyError, ParameterError
from worldgen.judge import stats


def binomial_tail_at_least(k, n, p):
    """P(X >= k) for X ~ Binomial(n, p), summed exactly."""
    return math.fsum(math.comb(n, i) * p ** i * (1 - p) ** (n - i) for i in range(k, n + 1))


def lower_bound_by_bisection(k, n, confidence):
    """The Clopper-Pearson lower bound from its definition: the p at which P(X >= k) = 1 - confidence."""
    if k == 0:
        return 0.0
    lo, hi = 0.0, 1.0
    for _ in range(100):
        mid = (lo + hi) / 2
        lo, hi = (mid, hi) if binomial_tail_at_least(k, n, mid) < 1 - confidence else (lo, mid)
    return (lo + hi) / 2


@pytest.mark.parametrize("k, n, confidence", [(19, 20, 0.95), (59, 59, 0.95), (58, 58, 0.95), (7, 10, 0.9),
                                               (1, 3, 0.99), (45, 50, 0.8), (0, 5, 0.95)])
def test_lower_bound_three_ways(k, n, confidence):
    got = stats.clopper_pearson_lower(k, n, confidence)
    assert got == pytest.approx(lower_bound_by_bisection(k, n, confidence), abs=1e-12)
    # A one-sided bound at confidence c is the lower end of the two-sided exact interval at 1 - 2 (1 - c).
    two_sided = scipy.stats.binomtest(k, n).proportion_ci(confidence_level=1 - 2 * (1 - confidence), method="exact")
    assert got == pytest.approx(two_sided.low, abs=1e-12)


def test_the_issues_reference_values():
    assert stats.clopper_pearson_lower(19, 20, 0.95) == pytest.approx(0.7839, abs=5e-5)
    # All n of n: the bound is (1 - c)^(1/n) exactly; 59 is the fewest clean runs for 95 % at 95 %.
    assert stats.clopper_pearson_lower(59, 59, 0.95) == pytest.approx(0.05 ** (1 / 59), abs=1e-14)
    assert stats.clopper_pearson_lower(59, 59, 0.95) >= 0.95 > stats.clopper_pearson_lower(58, 58, 0.95)
    assert stats.runs_needed(0, 0, 0.95, 0.95) == 59
    assert stats.runs_needed(58, 58, 0.95, 0.95) == 1
    assert stats.runs_needed(59, 59, 0.95, 0.95) == 0


@pytest.mark.parametrize("k, n, minimum, confidence", [(19, 20, 0.95, 0.95), (17, 20, 0.9, 0.9), (3, 10, 0.5, 0.95),
                                                        (0, 0, 0.8, 0.99), (99, 100, 0.97, 0.95)])
def test_runs_needed_is_the_smallest(k, n, minimum, confidence):
    m = stats.runs_needed(k, n, minimum, confidence)
    assert m > 0
    assert lower_bound_by_bisection(k + m, n + m, confidence) >= minimum - 1e-12
    assert lower_bound_by_bisection(k + m - 1, n + m - 1, confidence) < minimum


@settings(max_examples=60, deadline=None)
@given(n=st.integers(0, 300), data=st.data(), minimum=st.floats(0.01, 0.99), confidence=st.floats(0.5, 0.995))
def test_runs_needed_is_minimal_everywhere(n, data, minimum, confidence):
    k = data.draw(st.integers(0, n))
    m = stats.runs_needed(k, n, minimum, confidence)

    def bound(k, n):  # straight from scipy's beta quantile, not through the function under test
        return 0.0 if k == 0 else scipy.stats.beta.ppf(1 - confidence, k, n - k + 1)

    assert bound(k + m, n + m) >= minimum
    assert m == 0 or bound(k + m - 1, n + m - 1) < minimum


def test_runs_needed_for_19_of_20():
    m = stats.runs_needed(19, 20, 0.95, 0.95)
    assert m == 73  # 92/93 clean: bound 0.9503; 91/92: 0.9497
    assert stats.clopper_pearson_lower(92, 93) >= 0.95 > stats.clopper_pearson_lower(91, 92)


def test_runs_needed_edges():
    assert stats.runs_needed(20, 20, 1.0, 0.95) is None  # no finite run count has a lower bound of 1
    assert stats.runs_needed(0, 20, 0.0, 0.95) == 0  # a bound is never below 0
    assert stats.runs_needed(0, 0, 0.0, 0.95) == 0
    b = stats.success_bound(20, 20, 1.0, 0.95)
    assert b["more_clean_runs"] == "never" and not b["passed"] and b["lower_bound"] == pytest.approx(0.05 ** (1 / 20))
    b = stats.success_bound(19, 20, 0.95, 0.95)
    assert b == {"successes": 19, "runs": 20, "rate": 0.95, "confidence": 0.95, "minimum": 0.95,
                 "lower_bound": pytest.approx(0.78389, abs=1e-5), "passed": False, "more_clean_runs": 73}


def test_two_sided_interval_matches_scipy():
    lo, hi = stats.clopper_pearson_interval(7, 12, 0.95)
    ref = scipy.stats.binomtest(7, 12).proportion_ci(confidence_level=0.95, method="exact")
    assert (lo, hi) == (pytest.approx(ref.low, abs=1e-15), pytest.approx(ref.high, abs=1e-15))
    # Each end from the definition: P(X >= 7 | lo) = P(X <= 7 | hi) = 0.025.
    assert binomial_tail_at_least(7, 12, lo) == pytest.approx(0.025, abs=1e-9)
    assert 1 - binomial_tail_at_least(8, 12, hi) == pytest.approx(0.025, abs=1e-9)


A = [11.2, 12.5, 10.9, 13.1, 12.0, 11.7, 12.8]
B = [13.4, 12.9, 14.8, 13.7, 15.2, 12.6]


def test_welch_against_scipy_and_by_hand():
    w = stats.welch(A, B, 0.95)
    ref = scipy.stats.ttest_ind(A, B, equal_var=False)
    assert w["t"] == pytest.approx(ref.statistic, rel=1e-12) and w["p"] == pytest.approx(ref.pvalue, rel=1e-12)
    ci = ref.confidence_interval(0.95)
    assert (w["ci_low"], w["ci_high"]) == (pytest.approx(ci.low, rel=1e-12), pytest.approx(ci.high, rel=1e-12))
    # By hand: Welch's t and the Welch-Satterthwaite degrees of freedom.
    ma, mb = sum(A) / len(A), sum(B) / len(B)
    va = sum((x - ma) ** 2 for x in A) / (len(A) - 1)
    vb = sum((x - mb) ** 2 for x in B) / (len(B) - 1)
    sa, sb = va / len(A), vb / len(B)
    assert w["difference"] == pytest.approx(ma - mb, abs=1e-12)
    assert w["t"] == pytest.approx((ma - mb) / math.sqrt(sa + sb), rel=1e-12)
    assert w["df"] == pytest.approx((sa + sb) ** 2 / (sa ** 2 / (len(A) - 1) + sb ** 2 / (len(B) - 1)), rel=1e-12)
    half = scipy.stats.t.ppf(0.975, w["df"]) * math.sqrt(sa + sb)
    assert w["ci_low"] == pytest.approx(ma - mb - half, rel=1e-12)
    # Cohen's d over the pooled SD; Hedges' g with J = Gamma(df/2) / (sqrt(df/2) Gamma((df-1)/2)), df = 11.
    pooled = math.sqrt(((len(A) - 1) * va + (len(B) - 1) * vb) / (len(A) + len(B) - 2))
    assert w["cohens_d"] == pytest.approx((ma - mb) / pooled, rel=1e-12)
    j = math.gamma(5.5) / (math.sqrt(5.5) * math.gamma(5.0))
    assert w["hedges_g"] == pytest.approx(w["cohens_d"] * j, rel=1e-12)
    assert j == pytest.approx(1 - 3 / (4 * 11 - 1), abs=1e-3)  # Hedges' own approximation


def test_welch_without_spread():
    w = stats.welch([2.0, 2.0, 2.0], [2.0, 2.0])
    assert w["p"] == 1.0 and w["difference"] == 0.0 and w["t"] is None and w["hedges_g"] is None
    w = stats.welch([2.0, 2.0], [3.0, 3.0])
    assert w["p"] == 0.0 and w["ci_low"] == w["ci_high"] == -1.0
    # One side without spread: t = (2 - 5) / sqrt(1/3), df = 2 (all of the variance is A's), no warning.
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        w = stats.welch([1.0, 2.0, 3.0], [5.0, 5.0, 5.0])
    assert w["t"] == pytest.approx(-3 / math.sqrt(1 / 3), rel=1e-12) and w["df"] == pytest.approx(2.0, rel=1e-12)
    assert w["p"] == pytest.approx(2 * scipy.stats.t.cdf(-3 / math.sqrt(1 / 3), 2), rel=1e-12)


def test_mann_whitney_against_scipy_and_pairwise_counts():
    m = stats.mann_whitney(A, B)
    ref = scipy.stats.mannwhitneyu(A, B, alternative="two-sided")
    assert m["u"] == ref.statistic and m["p"] == pytest.approx(ref.pvalue, rel=1e-12)
    greater = sum(a > b for a in A for b in B)
    less = sum(a < b for a in A for b in B)
    ties = sum(a == b for a in A for b in B)
    assert m["u"] == greater + ties / 2
    assert m["rank_biserial"] == pytest.approx((greater - less) / (len(A) * len(B)), abs=1e-15)
    assert stats.mann_whitney([1.0, 1.0], [1.0, 1.0]) == {"u": 2.0, "p": 1.0, "rank_biserial": 0.0}


def hypergeometric_two_sided_p(ka, na, kb, nb):
    """Fisher's exact p from the hypergeometric distribution: every table at most as likely as the observed one."""
    total, succ = na + nb, ka + kb

    def prob(x):
        return math.comb(na, x) * math.comb(nb, succ - x) / math.comb(total, succ)

    observed = prob(ka)
    xs = range(max(0, succ - nb), min(na, succ) + 1)
    return math.fsum(prob(x) for x in xs if prob(x) <= observed * (1 + 1e-7))


@pytest.mark.parametrize("ka, na, kb, nb", [(19, 20, 10, 20), (18, 20, 12, 15), (5, 5, 0, 4), (3, 9, 3, 9)])
def test_fisher_against_scipy_and_the_hypergeometric(ka, na, kb, nb):
    f = stats.fisher(ka, na, kb, nb)
    ref = scipy.stats.fisher_exact([[ka, na - ka], [kb, nb - kb]])
    assert f["p"] == pytest.approx(ref.pvalue, rel=1e-12)
    assert f["p"] == pytest.approx(min(1.0, hypergeometric_two_sided_p(ka, na, kb, nb)), rel=1e-9)
    assert f["risk_difference"] == pytest.approx(ka / na - kb / nb)
    assert f["a"]["successes"] == ka and f["b"]["runs"] == nb


def test_fisher_odds_ratio_edges():
    assert stats.fisher(19, 20, 10, 20)["odds_ratio"] == pytest.approx(19 * 10 / (1 * 10))
    assert stats.fisher(5, 5, 0, 4)["odds_ratio"] == "inf"
    assert stats.fisher(5, 5, 4, 4)["odds_ratio"] is None  # 0/0: every run of both succeeded


def test_compare_runs_takes_each_figure_over_its_runs():
    def row(success, t, eff, clearance):
        return {"success": success, "time_to_goal": t, "path_length": eff and eff * 4, "path_efficiency": eff,
                "min_clearance": clearance, "max_velocity": 0.5, "barn_score": 0.2 if success else 0.0}

    a = [row(True, 10.0, 1.1, 0.2), row(True, 11.0, 1.2, 0.3), row(False, None, 0.6, -0.1), {"success": None}]
    b = [row(True, 12.0, 1.3, 0.1), row(True, 14.0, 1.5, 0.2), row(True, 13.0, 1.4, 0.2)]
    out = stats.compare_runs(a, b)
    assert out["runs"] == {"a": 3, "b": 3} and out["unjudged"] == {"a": 1, "b": 0}  # runs: judged ones
    assert out["success"]["a"]["successes"] == 2 and out["success"]["a"]["runs"] == 3
    eff = out["figures"]["path_efficiency"]
    assert eff["over"] == "successful runs" and eff["n_a"] == 2 and eff["mean_a"] == pytest.approx(1.15)
    assert eff["welch"]["p"] == pytest.approx(scipy.stats.ttest_ind([1.1, 1.2], [1.3, 1.5, 1.4], equal_var=False).pvalue)
    clearance = out["figures"]["min_clearance"]
    assert clearance["over"] == "all runs" and clearance["n_a"] == 3
    assert out["figures"]["max_velocity"]["welch"]["p"] == 1.0
    few = stats.compare_runs(a[:1] + a[2:3], b)["figures"]["time_to_goal"]
    assert few["too_few"] == "too few runs (A 1, B 3; need 2 on each side)" and "welch" not in few
    assert out["note"].startswith("A large p-value means these runs cannot tell A and B apart, not that A and B are the same")
    with pytest.raises(ParameterError, match="at least one judged run"):
        stats.compare_runs([{"success": None}], b)


def test_bad_counts_and_confidence_are_one_line():
    for call in (lambda: stats.clopper_pearson_lower(5, 3), lambda: stats.clopper_pearson_lower(-1, 3),
                 lambda: stats.clopper_pearson_lower(1.5, 3), lambda: stats.clopper_pearson_lower(1, 3, 1.0),
                 lambda: stats.runs_needed(1, 3, 1.5)):
        with pytest.raises(ParameterError) as exc:
            call()
        assert "\n" not in str(exc.value)


def test_without_scipy_the_message_says_what_to_install(monkeypatch):
    monkeypatch.setitem(sys.modules, "scipy", None)
    monkeypatch.setitem(sys.modules, "scipy.stats", None)
    with pytest.raises(MissingDependencyError) as exc:
        stats.clopper_pearson_lower(3, 4)
    assert str(exc.value) == "worldgen's statistics need scipy, which is not installed: pip install 'worldgen[stats]'"
    assert stats.clopper_pearson_lower(0, 4) == 0.0  # needs no quantile, so no scipy


def test_wilson_interval_matches_its_closed_forms():
    # With no successes the upper end is z^2 / (n + z^2); with all, the lower end is n / (n + z^2) (z = 1.959964).
    zz = 1.959963984540054 ** 2
    assert stats.wilson_interval(0, 20) == (0.0, pytest.approx(zz / (20 + zz), abs=1e-12))
    assert stats.wilson_interval(20, 20) == (pytest.approx(20 / (20 + zz), abs=1e-12), 1.0)
    lo, hi = stats.wilson_interval(7, 12)
    lo2, hi2 = stats.wilson_interval(5, 12)
    assert (lo, hi) == (pytest.approx(1 - hi2, abs=1e-12), pytest.approx(1 - lo2, abs=1e-12)) and lo < 7 / 12 < hi
    assert stats.wilson_interval(0, 0) == (0.0, 1.0)
