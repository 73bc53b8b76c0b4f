"""evaluate's honest statistics: path figures over successful runs, the confidence form of success_rate,
the BARN score per run and the per-world breakdown, on runs built from real worlds' reference paths.

lidar_wall (minimal generator): the robot (radius 0.2 m) spawns at the origin, a box wall occupies
x in [2.0, 2.1], y in [-2, 2]; the goal is (2.0, 2.5), tolerance 0.2 m, and the reference path is
the straight segment to it, 3.201562 m.
"""

import json
import math

import numpy as np
import pytest

import worldgen
from worldgen.errors import ParameterError
from worldgen.judge.evaluate import evaluate, load_criteria
from worldgen.judge.figures import barn_score
from worldgen.presets import generate_preset

REF = math.hypot(2.0, 2.5)


@pytest.fixture(scope="module")
def wall():
    return generate_preset("lidar_wall")


@pytest.fixture(scope="module")
def clutter():
    return worldgen.generate("cluttered", seed=2, size=[6, 6], n_obstacles=8)


def along(waypoints, upto, t0, speed, step=0.05):
    """``t, x, y`` samples along a polyline from its start to ``upto`` of its length, at ``speed``, every ``step`` m."""
    pts = np.asarray(waypoints, dtype=float)
    seg = np.hypot(*np.diff(pts, axis=0).T)
    cum = np.r_[0.0, np.cumsum(seg)]
    s = np.r_[np.arange(0.0, upto * cum[-1], step), upto * cum[-1]]
    xy = np.c_[np.interp(s, cum, pts[:, 0]), np.interp(s, cum, pts[:, 1])]
    return np.c_[t0 + s / speed, xy]


def line(a, b, t0, t1, n=20):
    s = np.linspace(0.0, 1.0, n)
    return np.c_[t0 + s * (t1 - t0), a[0] + s * (b[0] - a[0]), a[1] + s * (b[1] - a[1])]


def test_a_crash_at_65_percent_no_longer_flatters_path_efficiency(wall):
    """The issue's story: the crash's short path pulled the mean efficiency under the limit and the criterion passed."""
    path = wall.metadata["tasks"][0]["path"]["waypoints"]
    # 65 % along the reference path, then straight on towards +x into the wall (contact at x = 1.8).
    crash = along(path, 0.65, 0.0, 0.5)
    at = crash[-1]
    crash = np.vstack([crash, line(at[1:], (1.9, at[2]), at[0], at[0] + 1.2)[1:]])
    # The successful run is a detour: up the y axis, then across above the wall, 4.5 m.
    detour = np.vstack([line((0, 0), (0, 2.5), 0, 6), line((0, 2.5), (2.0, 2.5), 6, 10)[1:]])
    report = evaluate([(detour, wall), (crash, wall)], {"navigation": {"path_efficiency": 1.2}})
    crashed, clean = report.runs[1], report.runs[0]
    assert crashed["success"] is False and crashed["reason"].startswith("collision with target at t=")
    assert clean["success"] is True and clean["path_efficiency"] == pytest.approx(4.5 / REF, abs=1e-6)
    assert crashed["path_efficiency"] == pytest.approx((0.65 * REF + (1.9 - at[1])) / REF, abs=1e-6)
    # Over every run the mean was under 1.2 (the old, wrong verdict); over successful runs it is 1.406.
    assert (clean["path_efficiency"] + crashed["path_efficiency"]) / 2 < 1.2
    assert report.summary["mean_path_efficiency"] == pytest.approx(4.5 / REF, abs=1e-6)
    assert not report.passed
    assert report.failures == [f"navigation.path_efficiency: required <= 1.2, measured {4.5 / REF:.6g}, "
                               f"failed by {4.5 / REF - 1.2:.6g}"]
    assert report.summary["averaged_over"]["path_efficiency"] == "successful runs"
    assert "path efficiency and time to goal: means over successful runs only" in str(report).splitlines()


def clean_runs(wall, n):
    return [(line((0, 0), (2.0, 2.5), 0.0, 10.0 + i * 0.1), wall) for i in range(n)]


def test_success_rate_with_confidence_19_of_20(wall):
    crash = line((0, 0), (3, 0), 0.0, 3.0)
    report = evaluate(clean_runs(wall, 19) + [(crash, wall)],
                      "navigation:\n  success_rate: {min: 0.95, confidence: 0.95}\n")
    c = report.criteria[0]
    assert report.summary["success_rate"] == 0.95  # the point estimate meets 0.95; the evidence does not
    assert not c.passed and c.measured == pytest.approx(0.7839, abs=5e-5)
    assert (c.successes, c.runs, c.confidence, c.more_clean_runs) == (19, 20, 0.95, 73)
    assert report.failures == [f"navigation.success_rate: required >= 0.95, measured lower bound {c.measured:.6g} "
                               f"(19/20 at 95% confidence), failed by {0.95 - c.measured:.6g}; "
                               "73 more clean runs would make it pass"]
    row = report.rows()[0]
    assert row["required"] == ">= 0.95 (95% conf.)" and row["measured"] == f"{c.measured:.6g} (19/20)"
    assert ("navigation.success_rate: one-sided 95% Clopper-Pearson lower bound of 19/20 = 0.7839; "
            "73 more clean runs would make it pass") in str(report).splitlines()
    row = report.to_dict()["criteria"][0]  # what report.json carries for a judge or a CI script
    assert {k: row[k] for k in ("confidence", "successes", "runs", "more_clean_runs", "passed")} == \
        {"confidence": 0.95, "successes": 19, "runs": 20, "more_clean_runs": 73, "passed": False}
    # The same runs against the point estimate pass, as before.
    assert evaluate(clean_runs(wall, 19) + [(crash, wall)], {"navigation": {"success_rate": 0.95}}).passed


def test_confidence_form_pass_fail_at_the_edge(wall):
    # (1 - 0.95)^(1/n) >= 0.8 from n = 14 on: 13 clean runs fail by one run, 14 pass.
    criteria = {"navigation": {"success_rate": {"min": 0.8, "confidence": 0.95}}}
    fail = evaluate(clean_runs(wall, 13), criteria).criteria[0]
    assert not fail.passed and fail.more_clean_runs == 1 and fail.measured == pytest.approx(0.05 ** (1 / 13))
    ok = evaluate(clean_runs(wall, 14), criteria).criteria[0]
    assert ok.passed and ok.more_clean_runs == 0 and ok.measured == pytest.approx(0.05 ** (1 / 14))
    # A required rate of 1 is never shown by a lower bound; 0 always is.
    never = evaluate(clean_runs(wall, 3), {"navigation": {"success_rate": {"min": 1.0}}})
    assert never.criteria[0].more_clean_runs == "never" and never.criteria[0].confidence == 0.95
    assert never.failures[0].endswith("; no number of further runs would make it pass")
    assert evaluate(clean_runs(wall, 1), {"navigation": {"success_rate": {"min": 0}}}).passed


def test_barn_score_per_run(wall, tmp_path):
    optimal = 3.201562 / 2.0  # the reference length at BARN's 2 m/s: 1.6 s
    # 20 samples 0.168 m apart: each run is within the goal's 0.2 m tolerance at 18/19 of its duration.
    fast = line((0, 0), (2.0, 2.5), 0.0, 2.0)          # 1.89 s, under 2 optimal times: clipped, 1/2
    mid = line((0, 0), (2.0, 2.5), 0.0, 10.0)          # 9.47 s: optimal / 9.47 s
    slow = line((0, 0), (2.0, 2.5), 0.0, 15.0)         # 14.2 s, over 8 optimal times (12.8 s): 1/8
    crash = line((0, 0), (3, 0), 0.0, 3.0)             # failed: 0
    report = evaluate([(fast, wall), (mid, wall), (slow, wall), (crash, wall)], {"performance": {"barn_score": 0.2}})
    scores = [r["barn_score"] for r in report.runs]
    assert report.runs[1]["time_to_goal"] == pytest.approx(10.0 * 18 / 19)
    assert scores == [pytest.approx(0.5), pytest.approx(optimal / (10.0 * 18 / 19)), pytest.approx(0.125), 0.0]
    assert report.summary["mean_barn_score"] == pytest.approx((0.5 + optimal / (10.0 * 18 / 19) + 0.125) / 4)
    assert report.runs[0]["reference_length"] == pytest.approx(3.201562)
    assert report.summary["barn"] == {"k": 2.0, "reference_speed": 2.0}
    assert report.criteria[0].passed is False  # (0.5 + 0.169 + 0.125 + 0) / 4 = 0.198 < 0.2
    # BARN's 2022 clip (4 optimal times), from the criteria file or the keyword, and another reference speed.
    k4 = evaluate([(fast, wall)], "scoring: {barn_k: 4}\n")
    assert k4.runs[0]["barn_score"] == pytest.approx(0.25) and k4.summary["barn"]["k"] == 4.0
    assert evaluate([(fast, wall)], "scoring: {barn_k: 4}\n", barn_k=2).runs[0]["barn_score"] == pytest.approx(0.5)
    # At 0.5 m/s the optimal time is 6.4 s: 9.47 s is under 2 optimal times, clipped, 1/2.
    slow_robot = evaluate([(mid, wall)], {"scoring": {"reference_speed": 0.5}})
    assert slow_robot.runs[0]["barn_score"] == pytest.approx(0.5)
    slower = evaluate([(mid, wall)], {"scoring": {"reference_speed": 1.0}})  # OT 3.2 s: 3.2 / 9.47
    assert slower.runs[0]["barn_score"] == pytest.approx(3.201562 / (10.0 * 18 / 19))
    data = json.loads(report.write_json(tmp_path / "r.json").read_text())
    assert [r["barn_score"] for r in data["runs"]][-1] == 0.0


def test_barn_score_function_edges():
    assert barn_score(True, 5.0, None) is None  # no proven path, no optimal time
    assert barn_score(False, None, 4.0) == 0.0
    assert barn_score(True, 3.0, 4.0) == pytest.approx(2.0 / 4.0)  # OT = 2 s; 3 s is below 2 OT
    assert barn_score(True, 3.0, 4.0, k=1) == pytest.approx(2.0 / 3.0)
    for bad in ({"k": 0}, {"k": 9}, {"reference_speed": 0}):
        with pytest.raises(ParameterError):
            barn_score(True, 3.0, 4.0, **bad)


def test_per_world_breakdown(wall, clutter):
    path = clutter.metadata["tasks"][0]["path"]
    runs = [(along(path["waypoints"], 1.0, 0.0, 0.5), clutter), (along(path["waypoints"], 1.0, 0.0, 0.4), clutter),
            (along(path["waypoints"], 0.5, 0.0, 0.5), clutter),  # stops half way: goal not reached
            (line((0, 0), (2.0, 2.5), 0.0, 10.0), wall)]
    report = evaluate(runs, {})
    s = report.summary
    assert s["worlds"] == 2 and s["runs"] == 4 and s["successes"] == 3
    c, w = s["per_world"][clutter.metadata["world_id"]], s["per_world"][wall.metadata["world_id"]]
    length = path["length"]
    assert (c["runs"], c["successes"], c["success_rate"]) == (3, 2, pytest.approx(2 / 3))
    # Time to goal: the first sample within the 0.2 m tolerance, 0.05 m apart.
    t5, t4 = report.runs[0]["time_to_goal"], report.runs[1]["time_to_goal"]
    assert (length - 0.25) / 0.5 <= t5 <= length / 0.5 and (length - 0.25) / 0.4 <= t4 <= length / 0.4
    assert c["mean_time_to_goal"] == pytest.approx((t5 + t4) / 2)
    # The failed half-way run (0.5) is not in it; world.json rounds waypoints and length to 1e-6 m.
    assert c["mean_path_efficiency"] == pytest.approx(1.0, abs=1e-5)
    assert c["min_clearance"] == min(r["min_clearance"] for r in report.runs[:3])
    # Both times lie between 2 and 8 optimal times (OT = length / 2 m/s), so neither is clipped; the failure scores 0.
    assert c["mean_barn_score"] == pytest.approx(((length / 2) / t5 + (length / 2) / t4 + 0.0) / 3)
    # 20 samples 0.168 m apart: the 19th is within the 0.2 m tolerance, at 18/19 of the 10 s.
    assert (w["runs"], w["successes"], w["mean_time_to_goal"]) == (1, 1, pytest.approx(10.0 * 18 / 19))
    assert w["mean_path_efficiency"] == pytest.approx(REF / 3.201562, abs=1e-6)
    assert list(s["per_world"]) == sorted(s["per_world"])


def test_new_criteria_forms_and_their_mistakes():
    got = load_criteria("navigation: {success_rate: {min: 0.9, confidence: 0.99}}\nscoring: {barn_k: 4, reference_speed: 1}\n")
    assert got == {"navigation": {"success_rate": {"min": 0.9, "confidence": 0.99}},
                   "scoring": {"barn_k": 4.0, "reference_speed": 1.0}}
    assert load_criteria({"navigation": {"success_rate": {"min": 0.9}}})["navigation"]["success_rate"]["confidence"] == 0.95
    cases = {"navigation: {success_rate: {min: 1.5}}": "navigation.success_rate.min must be in [0, 1]",
             "navigation: {success_rate: {min: 0.9, confidence: 0.3}}": "confidence must be in [0.5, 1)",
             "navigation: {success_rate: {min: 0.9, confidence: 1}}": "confidence must be in [0.5, 1)",
             "navigation: {success_rate: {minimum: 0.9}}": "takes min (required) and confidence, got keys minimum",
             "scoring: {barn_k: 9}": "scoring.barn_k must be in (0, 8]",
             "scoring: {reference_speed: 0}": "scoring.reference_speed must be > 0",
             "scoring: {speed: 1}": "unknown key scoring.speed; allowed in scoring: barn_k, reference_speed",
             "comfort: {x: 1}": "allowed: navigation, safety, performance, social, scoring"}
    for text, words in cases.items():
        with pytest.raises(ParameterError) as exc:
            load_criteria(text)
        assert words in str(exc.value) and "\n" not in str(exc.value)


def test_a_refused_run_is_a_failure_counted_in_the_rates_and_out_of_the_figures(clutter):
    """The judge's bag that started far from its spawn: judged, failed, with its reason and no figures."""
    good = along(clutter.metadata["tasks"][0]["path"]["waypoints"], 1.0, 0.0, 0.5)
    alone = evaluate([(good, clutter)], {"navigation": {"success_rate": 0.5}}).to_dict()
    both = evaluate([(good, clutter), {"world": clutter, "task": None, "refused": "the run starts 6.40 m from the "
                                       "task's spawn"}], {"navigation": {"success_rate": 0.5}}).to_dict()
    s = both["summary"]
    assert (s["runs"], s["successes"], s["success_rate"]) == (2, 1, 0.5) and both["passed"]
    for figure in ("min_clearance", "max_velocity", "mean_time_to_goal", "mean_path_efficiency", "collision_count"):
        assert s[figure] == alone["summary"][figure]  # the refused run has no figure to add
    refused = both["runs"][1]
    assert refused["success"] is False and refused["reason"].startswith("the run starts 6.40 m")
    assert refused["world_id"] == clutter.world_id and refused["barn_score"] == 0.0 and "min_clearance" not in refused
    assert s["per_world"][clutter.world_id]["runs"] == 2 and s["mean_barn_score"] == alone["summary"]["mean_barn_score"] / 2
    only = evaluate([{"world": clutter, "refused": "another world"}], {"navigation": {"success_rate": 1.0}}).to_dict()
    assert only["summary"]["min_clearance"] is None and not only["passed"]
