"""``worldgen compare A B`` end to end on two report folders written by evaluate (the report.json format
the judge writes), and every bad input as one line with exit status 2."""

import json

import numpy as np
import pytest
import scipy.stats
from support.cli import run

import worldgen
from worldgen.judge.evaluate import evaluate
from worldgen.presets import generate_preset

NOTE = ("A large p-value means these runs cannot tell A and B apart, not that A and B are the same; "
        "a small one means a difference this large would be rare if they were.")


def along(waypoints, upto, speed, step=0.05):
    pts = np.asarray(waypoints, dtype=float)
    cum = np.r_[0.0, np.cumsum(np.hypot(*np.diff(pts, axis=0).T))]
    s = np.r_[np.arange(0.0, upto * cum[-1], step), upto * cum[-1]]
    return np.c_[s / speed, np.interp(s, cum, pts[:, 0]), np.interp(s, cum, pts[:, 1])]


@pytest.fixture(scope="module")
def reports(tmp_path_factory):
    """A: 'simulation', 6 clean runs at 0.5-0.55 m/s in two worlds; B: 'real', 7 runs at 0.38-0.44 m/s, one stopping short."""
    wall = generate_preset("lidar_wall")
    clutter = worldgen.generate("cluttered", seed=2, size=[6, 6], n_obstacles=8)
    paths = {w: w.metadata["tasks"][0]["path"]["waypoints"] for w in (wall, clutter)}
    sim = [(along(paths[w], 1.0, v), w) for w in (wall, clutter) for v in (0.5, 0.52, 0.55)]
    real = [(along(paths[w], 1.0, v), w) for w in (wall, clutter) for v in (0.38, 0.41, 0.44)]
    real.append((along(paths[clutter], 0.6, 0.4), clutter))  # stopped at 60 %: goal not reached
    root = tmp_path_factory.mktemp("reports")
    out = {}
    for name, runs in (("sim", sim), ("real", real)):
        (root / name).mkdir()
        evaluate(runs, {"navigation": {"success_rate": 0.8}}).write_json(root / name / "report.json")
        out[name] = root / name
    return out


def test_compare_table(reports):
    done = run("compare", reports["sim"], reports["real"])
    assert done.returncode == 0, done.stderr
    assert done.stderr == ""
    lines = done.stdout.splitlines()
    assert lines[0] == (f"A: {reports['sim']} (6 judged runs, 0 unjudged)    "
                        f"B: {reports['real']} (7 judged runs, 0 unjudged)")
    assert any(line.startswith("success  A 6/6 = 1.000 (95% CI 0.541-1.000)   B 6/7 = 0.857") for line in lines)
    assert any("Fisher's exact p = 1.0000" in line and "odds ratio inf" in line for line in lines)
    head = next(line for line in lines if line.startswith("figure"))
    assert head.split()[:4] == ["figure", "over", "n", "A"]
    rows = {line.split()[0]: line.split() for line in lines if line.split() and line.split()[0] in
            ("time_to_goal", "path_length", "path_efficiency", "min_clearance", "max_velocity", "barn_score")}
    assert len(rows) == 6
    assert rows["time_to_goal"][1:4] == ["successful", "6", "6"] and rows["min_clearance"][1:4] == ["all", "6", "7"]
    assert lines[-1] == NOTE


def test_compare_json_matches_scipy_on_the_same_runs(reports):
    done = run("compare", reports["sim"], reports["real"], "--json")
    assert done.returncode == 0, done.stderr
    got = json.loads(done.stdout)
    a = json.loads((reports["sim"] / "report.json").read_text())["runs"]
    b = json.loads((reports["real"] / "report.json").read_text())["runs"]
    ta = [r["time_to_goal"] for r in a if r["success"]]
    tb = [r["time_to_goal"] for r in b if r["success"]]
    time = got["figures"]["time_to_goal"]
    assert time["n_a"] == 6 and time["n_b"] == 6 and time["over"] == "successful runs"
    ref = scipy.stats.ttest_ind(ta, tb, equal_var=False)
    assert time["welch"]["p"] == pytest.approx(ref.pvalue, rel=1e-9)
    assert time["welch"]["difference"] == pytest.approx(np.mean(ta) - np.mean(tb), rel=1e-9)
    assert time["welch"]["difference"] < 0 and time["welch"]["ci_high"] < 0  # the real robot is slower
    assert time["mann_whitney"]["p"] == pytest.approx(scipy.stats.mannwhitneyu(ta, tb).pvalue, rel=1e-9)
    clearance = got["figures"]["min_clearance"]
    assert clearance["n_b"] == 7  # every run, the failed one too
    assert got["success"]["p"] == pytest.approx(scipy.stats.fisher_exact([[6, 0], [6, 1]]).pvalue)
    assert got["success"]["odds_ratio"] == "inf" and got["success"]["risk_difference"] == pytest.approx(1 / 7)
    assert got["runs"] == {"a": 6, "b": 7} and got["note"] == NOTE and got["confidence"] == 0.95
    assert got["a"] == str(reports["sim"])


def test_a_figure_without_enough_runs_is_a_row(reports, tmp_path):
    one = json.loads((reports["real"] / "report.json").read_text())
    one["runs"] = [r for r in one["runs"] if not r["success"]] + [r for r in one["runs"] if r["success"]][:1]
    (tmp_path / "one").mkdir()
    (tmp_path / "one" / "report.json").write_text(json.dumps(one))
    done = run("compare", reports["sim"], tmp_path / "one")
    assert done.returncode == 0, done.stderr
    row = next(line for line in done.stdout.splitlines() if line.startswith("time_to_goal"))
    assert row.endswith("too few runs (A 6, B 1; need 2 on each side)")
    clearance = next(line for line in done.stdout.splitlines() if line.startswith("min_clearance"))
    assert "too few" not in clearance  # two runs on B's side count for the figures over all runs


def test_bad_input_is_one_line_exit_2(reports, tmp_path):
    (tmp_path / "empty").mkdir()
    (tmp_path / "broken").mkdir()
    (tmp_path / "broken" / "report.json").write_text("{not json")
    (tmp_path / "norows").mkdir()
    (tmp_path / "norows" / "report.json").write_text(json.dumps({"passed": True, "summary": {}}))
    (tmp_path / "unjudged").mkdir()
    (tmp_path / "unjudged" / "report.json").write_text(json.dumps({"runs": [{"success": None, "reason": "truncated bag"}]}))
    cases = {tmp_path / "missing": "does not exist",
             tmp_path / "empty": "has no report.json; give a report folder written by 'worldgen judge'",
             tmp_path / "broken": "is not valid JSON",
             tmp_path / "norows": "has no list of runs ('runs')",
             tmp_path / "unjudged": "holds no judged run"}
    for folder, words in cases.items():
        done = run("compare", reports["sim"], folder)
        assert done.returncode == 2, (folder, done.stdout, done.stderr)
        assert done.stdout == "" and len(done.stderr.splitlines()) == 1
        assert done.stderr.startswith("error: ") and words in done.stderr and "Traceback" not in done.stderr
    done = run("compare", reports["sim"], reports["real"], "--confidence", "1.5")
    assert done.returncode == 2 and len(done.stderr.splitlines()) == 1


def test_unjudged_bags_are_left_out_counted_and_a_side_of_only_them_is_bad_input(reports, tmp_path):
    """The issue's case: a report whose one bag could not be read is no evidence of failure (was Fisher p = 0.0476)."""
    pytest.importorskip("rosbags")
    world = worldgen.generate("cluttered", seed=2, size=[6, 6], n_obstacles=8).write(tmp_path / "worlds", preview=False)
    judged = run("judge", tmp_path / "missing_bag", "--world", world, "--out", tmp_path / "r1")
    assert judged.returncode == 1 and json.loads((tmp_path / "r1" / "report.json").read_text())["summary"]["unjudged"] == 1
    for a, b in ((reports["sim"], tmp_path / "r1"), (tmp_path / "r1", reports["sim"])):
        done = run("compare", a, b)
        assert done.returncode == 2 and done.stdout == "", done.stdout
        assert done.stderr.startswith("error: report ") and "holds no judged run" in done.stderr
    # A report of an older version: unreadable rows carried success false beside readable false.
    rows = json.loads((reports["real"] / "report.json").read_text())["runs"]
    old = rows + [{"bag": "b", "run": "b", "readable": False, "success": False, "reason": "truncated"}] * 3
    (tmp_path / "old").mkdir()
    (tmp_path / "old" / "report.json").write_text(json.dumps({"runs": old}))
    done = run("compare", reports["sim"], tmp_path / "old", "--json")
    assert done.returncode == 0, done.stderr
    out = json.loads(done.stdout)
    assert out["runs"] == {"a": 6, "b": 7} and out["unjudged"] == {"a": 0, "b": 3}
    assert out["success"]["b"]["runs"] == 7 and out["success"]["b"]["successes"] == 6
    table = run("compare", reports["sim"], tmp_path / "old").stdout.splitlines()
    assert table[0].endswith("(7 judged runs, 3 unjudged)") and "left out of every test" in table[1]
