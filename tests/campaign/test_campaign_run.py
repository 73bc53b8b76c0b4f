"""Running campaigns against System test doubles (tests/support/campaign.py): the same campaign twice is the same
bytes, a planted corner lands in the right bins, refusals and unjudged runs are never failures, bad output
folders are refused with nothing written, a killed campaign resumes to the same results, Dask runs it too,
and each distinct failure is shrunk to a world that still fails and passes `worldgen check`."""

from __future__ import annotations

import csv
import json
import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest
from support.campaign import PlantedWeakness

from worldgen.campaign import expect_no_failures, parse_campaign, run, write_report
from worldgen.errors import ParameterError
from worldgen.files import (
    CAMPAIGN_STATE_DIR,
    FAILURE_MAP_NAME,
    FAILURES_NAME,
    MANIFEST_NAME,
    REPORT_MD_NAME,
    SHRUNK_DIR,
    STRATEGY_NAME,
    VERDICTS_NAME,
)
from worldgen.verify import check_folder

CORNER = """\
name: corner
space:
  - generator: cluttered
    params:
      size: [8, 8]
      max_attempts: 10
      n_obstacles: {min: 0, max: 30}
      n_people: {min: 0, max: 2}
      people_duration: 3
      robot_radius: {min: 0.15, max: 0.3}
budget: {runs: 24}
strategy: {name: adaptive, seed: 0}
"""
WEAK = PlantedWeakness(min_obstacles=24, min_people=1, min_radius=0.26)
OUTPUTS = (VERDICTS_NAME, FAILURES_NAME, STRATEGY_NAME, FAILURE_MAP_NAME, REPORT_MD_NAME)


def _rows(path: Path) -> list[dict]:
    with open(path, newline="") as fh:
        return list(csv.DictReader(fh))


def test_a_sequential_campaign_is_the_same_bytes_and_puts_the_corner_in_its_bins(tmp_path):
    recipe = parse_campaign(CORNER)
    first = run(recipe, tmp_path / "a", system=WEAK, shrink=False)
    run(recipe, tmp_path / "b", system=WEAK, shrink=False)
    for name in OUTPUTS:
        assert (tmp_path / "a" / name).read_bytes() == (tmp_path / "b" / name).read_bytes(), name
    assert first.runs == 24 and first.failed >= 4, first.lines()
    rows = _rows(tmp_path / "a" / VERDICTS_NAME)
    assert len(rows) == 24 and {r["verdict"] for r in rows} == {"passed", "failed"}
    for r in rows:  # every failure is in the corner, and the corner always fails
        params = json.loads(r["params"])
        corner = int(r["obstacles"]) >= 24 and int(r["people"]) >= 1 and params["robot_radius"] >= 0.26
        assert (r["verdict"] == "failed") == corner, r
    assert len(_rows(tmp_path / "a" / FAILURES_NAME)) == first.failed
    bins = {(r["dimension"], r["bin"]): r for r in _rows(tmp_path / "a" / FAILURE_MAP_NAME)}
    assert int(bins[("people", "0")]["failed"]) == 0
    obstacle_bins = {b: r for (d, b), r in bins.items() if d == "n_obstacles"}
    assert set(obstacle_bins) <= {"[0, 6)", "[6, 12)", "[12, 18)", "[18, 24)", "[24, 30]"}
    assert int(obstacle_bins["[24, 30]"]["failed"]) == first.failed
    assert all(int(r["failed"]) == 0 for b, r in obstacle_bins.items() if b != "[24, 30]")
    top = obstacle_bins["[24, 30]"]
    assert 0 <= float(top["low"]) <= float(top["rate"]) <= float(top["high"]) <= 1
    report = (tmp_path / "a" / REPORT_MD_NAME).read_text()
    assert "## Where it fails" in report and "collision with person_# at # s" in report
    assert (tmp_path / "a" / "plots" / "people.png").is_file()
    manifest = json.loads((tmp_path / "a" / MANIFEST_NAME).read_text())
    assert manifest["complete"] and manifest["runs"] == 24 and manifest["failed"] == first.failed
    # Uniform sampling with the same budget and seed finds far fewer.
    uniform = run(parse_campaign(CORNER.replace("adaptive", "random")), tmp_path / "u", system=WEAK, report=False)
    assert uniform.runs == 24 and 2 * uniform.failed < first.failed, (uniform.lines(), first.lines())


MIXED = """\
space:
  - generator: cluttered
    params:
      size: [4, 4]
      max_attempts: 2
      n_obstacles: [2, 300]
      n_people: {min: 0, max: 2}
      people_duration: 5
budget: {runs: 10}
"""


def test_worlds_that_do_not_exist_are_no_runs_and_unjudged_runs_are_no_failures(tmp_path):
    system = PlantedWeakness(min_obstacles=0, min_people=1, crash_people=2)
    s = run(parse_campaign(MIXED), tmp_path / "c", system=system, report=False)
    assert s.runs == 10 and s.no_world >= 1 and s.points == s.runs + s.no_world
    rows = _rows(tmp_path / "c" / VERDICTS_NAME)
    assert len(rows) == 10 and all(r["obstacles"] == "2" for r in rows)
    for r in rows:
        assert r["verdict"] == {"0": "passed", "1": "failed", "2": "unjudged"}[r["people"]], r
    assert {r["verdict"] for r in _rows(tmp_path / "c" / FAILURES_NAME)} <= {"failed"}
    records = [json.loads(p.read_text()) for p in sorted((tmp_path / "c" / CAMPAIGN_STATE_DIR).glob("[0-9]*[0-9].json"))]
    refused = [r for r in records if r["world_id"] is None]
    assert len(refused) == s.no_world and all(r["runs"] == [] and r["reason"] for r in refused)
    assert s.unjudged == sum(r["verdict"] == "unjudged" for r in rows)


def test_an_output_folder_holding_something_else_is_refused_with_nothing_written(tmp_path):
    recipe = parse_campaign(CORNER.replace("runs: 24", "runs: 2"))
    run(recipe, tmp_path / "mine", system=WEAK, report=False)
    before = sorted(p.relative_to(tmp_path) for p in tmp_path.rglob("*"))
    other = parse_campaign(CORNER.replace("seed: 0", "seed: 1"))
    with pytest.raises(ParameterError, match="holds another campaign"):
        run(other, tmp_path / "mine", system=WEAK)
    (tmp_path / "stuff").mkdir()
    (tmp_path / "stuff" / "notes.txt").write_text("mine")
    with pytest.raises(ParameterError, match="is not a campaign folder"):
        run(recipe, tmp_path / "stuff", system=WEAK)
    with pytest.raises(ParameterError, match="no 'system:' block"):
        run(recipe, tmp_path / "new")
    with pytest.raises(ParameterError, match="parameter 'jobs'"):
        run(recipe, tmp_path / "new", jobs=0, system=WEAK)
    before.append(Path("stuff")), before.append(Path("stuff/notes.txt"))
    assert sorted(p.relative_to(tmp_path) for p in tmp_path.rglob("*")) == sorted(before)
    # The same recipe with a bigger budget goes on where it stopped.
    s = run(parse_campaign(CORNER.replace("runs: 24", "runs: 4")), tmp_path / "mine", system=WEAK, report=False)
    assert s.runs == 4 and s.points == 4


_KILLED = """\
import sys
sys.path.insert(0, {tests!r})
from support.campaign import PlantedWeakness
from worldgen.campaign import parse_campaign, run
run(parse_campaign({recipe!r}), {out!r}, system=PlantedWeakness(min_obstacles=24, min_people=1, min_radius=0.26, slow=0.5),
    report=False)
"""


def test_a_killed_campaign_resumes_to_the_same_results(tmp_path):
    recipe = CORNER.replace("runs: 24", "runs: 12")
    tests = str(Path(__file__).resolve().parent.parent)
    out = tmp_path / "killed"
    env = dict(os.environ, PYTHONPATH=os.pathsep.join([str(Path(tests).parent), os.environ.get("PYTHONPATH", "")]))
    proc = subprocess.Popen([sys.executable, "-c", _KILLED.format(tests=tests, recipe=recipe, out=str(out))], env=env)
    state = out / CAMPAIGN_STATE_DIR
    deadline = time.monotonic() + 60
    while time.monotonic() < deadline and len(list(state.glob("[0-9]*[0-9].json"))) < 4 and proc.poll() is None:
        time.sleep(0.05)
    proc.send_signal(signal.SIGKILL)
    proc.wait()
    done = len(list(state.glob("[0-9]*[0-9].json")))
    assert 4 <= done < 12 and not (out / MANIFEST_NAME).exists()
    slow = PlantedWeakness(min_obstacles=24, min_people=1, min_radius=0.26, slow=0.5)  # the same system, as in the killed one
    resumed = run(parse_campaign(recipe), out, system=slow, report=False)
    whole = run(parse_campaign(recipe), tmp_path / "whole", system=slow, report=False)
    assert resumed.runs == whole.runs == 12
    for name in (VERDICTS_NAME, FAILURES_NAME, STRATEGY_NAME):
        assert (out / name).read_bytes() == (tmp_path / "whole" / name).read_bytes(), name


def test_dask_runs_a_campaign_and_tells_results_as_they_arrive(tmp_path):
    pytest.importorskip("distributed")
    s = run(parse_campaign(CORNER.replace("runs: 24", "runs: 6").replace("adaptive", "random")), tmp_path / "d",
            jobs=2, system=WEAK, report=False)
    assert s.runs == 6
    rows = _rows(tmp_path / "d" / VERDICTS_NAME)
    assert sorted(int(r["point"]) for r in rows) == list(range(6))
    # The points (and so worlds and verdicts) are the sequential campaign's: the first batch is asked before any
    # result comes back in both, and random sampling never reads results.
    run(parse_campaign(CORNER.replace("runs: 24", "runs: 6").replace("adaptive", "random")), tmp_path / "s",
        system=WEAK, report=False)
    assert (tmp_path / "d" / VERDICTS_NAME).read_bytes() == (tmp_path / "s" / VERDICTS_NAME).read_bytes()


SHRINKABLE = """\
space:
  - generator: cluttered
    params:
      size: [6, 6]
      n_obstacles: {min: 10, max: 12}
budget: {runs: 3}
"""


def test_each_distinct_failure_is_shrunk_to_a_world_that_still_fails_and_passes_check(tmp_path):
    system = PlantedWeakness(min_obstacles=8, min_people=0)
    run(parse_campaign(SHRINKABLE), tmp_path / "s", system=system)
    notes = sorted((tmp_path / "s" / SHRUNK_DIR).glob("*.json"))
    assert notes  # one per kind of failure and cell (generator, level, people, doors)
    report = (tmp_path / "s" / REPORT_MD_NAME).read_text()
    for note in notes:
        info = json.loads(note.read_text())
        assert info["shrunk"] and info["obstacles"] == 8, info
        folder = tmp_path / "s" / info["folder"]
        assert check_folder(folder).ok, check_folder(folder).line()
        assert system.run(folder, info["task"], "again", tmp_path).verdict == "failed"
        assert (tmp_path / "s" / info["picture"]).is_file()
        assert info["folder"] in report
    # A redraw without the system keeps what shrinking found.
    (tmp_path / "s" / REPORT_MD_NAME).unlink()
    write_report(tmp_path / "s")
    assert info["folder"] in (tmp_path / "s" / REPORT_MD_NAME).read_text()
    # The pytest helper fails a test naming each shrunk world.
    with pytest.raises(pytest.fail.Exception) as failed:
        expect_no_failures(tmp_path / "s")
    message = str(failed.value)
    assert f"found {len(notes)} distinct failure(s)" in message
    for note in notes:
        assert str(tmp_path / "s" / json.loads(note.read_text())["folder"]) in message and "shrunk to" in message


def test_a_relative_verdict_path_is_read_beside_the_recipe_and_the_report_redraws_without_it(tmp_path):
    (tmp_path / "recipes").mkdir()
    (tmp_path / "recipes" / "criteria.yaml").write_text("navigation:\n  success_rate: 1.0\n")
    (tmp_path / "recipes" / "c.yaml").write_text(SHRINKABLE.replace("budget:", "verdict: criteria.yaml\nbudget:"))
    from worldgen.campaign import load_campaign

    recipe = load_campaign(tmp_path / "recipes" / "c.yaml")
    assert recipe.verdict == str(tmp_path / "recipes" / "criteria.yaml")
    run(recipe, tmp_path / "out", system=PlantedWeakness(min_obstacles=99), report=False)
    assert write_report(tmp_path / "out").is_file()


def test_the_pytest_helper_passes_a_campaign_without_failures(tmp_path):
    run(parse_campaign(SHRINKABLE), tmp_path / "ok", system=PlantedWeakness(min_obstacles=99), report=False)
    expect_no_failures(tmp_path / "ok")
    with pytest.raises(ParameterError, match="is not a campaign folder"):
        expect_no_failures(tmp_path)


_INTERRUPTED = """\
import sys
sys.path.insert(0, {tests!r})
from support.campaign import PlantedWeakness
from worldgen.campaign import CampaignInterrupted, parse_campaign, run
try:
    run(parse_campaign({recipe!r}), {out!r}, system=PlantedWeakness(min_obstacles=24, min_people=1, slow=0.3))
except CampaignInterrupted as exc:
    print(exc.line())
    sys.exit(130)
"""


def test_ctrl_c_keeps_every_finished_run_and_the_rerun_goes_on(tmp_path):
    recipe = CORNER.replace("runs: 24", "runs: 40")
    tests = str(Path(__file__).resolve().parent.parent)
    out = tmp_path / "int"
    proc = subprocess.Popen([sys.executable, "-c", _INTERRUPTED.format(tests=tests, recipe=recipe, out=str(out))],
                            stdout=subprocess.PIPE, text=True)
    state = out / CAMPAIGN_STATE_DIR
    deadline = time.monotonic() + 60
    while time.monotonic() < deadline and len(list(state.glob("[0-9]*[0-9].json"))) < 3 and proc.poll() is None:
        time.sleep(0.05)
    proc.send_signal(signal.SIGINT)
    stdout, _ = proc.communicate(timeout=60)
    assert proc.returncode == 130 and "rerun the same command" in stdout, stdout
    done = len(list(state.glob("[0-9]*[0-9].json")))
    rows = _rows(out / VERDICTS_NAME)
    assert done >= 3 and len(rows) == done  # every finished run is in the tables
    manifest = json.loads((out / MANIFEST_NAME).read_text())
    assert manifest["complete"] is False and manifest["runs"] == done
    s = run(parse_campaign(recipe.replace("runs: 40", f"runs: {done + 2}")), out, system=WEAK, report=False)
    assert s.runs == done + 2 and json.loads((out / MANIFEST_NAME).read_text())["complete"]


def test_a_budget_of_seconds_stops_asking_when_it_is_spent(tmp_path):
    recipe = parse_campaign(CORNER.replace("budget: {runs: 24}", "budget: {seconds: 1}"))
    s = run(recipe, tmp_path / "t", system=PlantedWeakness(slow=0.4), report=False)
    assert 1 <= s.runs <= 4 and s.stopped == "the budget's 1 s", s.lines()


def test_a_scheduler_out_of_reach_is_one_line_and_leaves_nothing_written(tmp_path, monkeypatch):
    pytest.importorskip("distributed")
    monkeypatch.setattr("worldgen.campaign.runner.CONNECT_TIMEOUT", "1s")  # nothing listens: no need to wait 10 s
    with pytest.raises(ParameterError, match="cannot reach the dask scheduler"):
        run(parse_campaign(SHRINKABLE), tmp_path / "new" / "out", scheduler="tcp://127.0.0.1:9", system=WEAK)
    assert not (tmp_path / "new").exists()
