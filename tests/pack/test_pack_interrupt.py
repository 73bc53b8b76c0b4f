"""Ctrl-C during a pack build: it stops within 2 s with one line and status 130, every world
folder left on disk has its record, and the rerun rebuilds at most the jobs that were in flight.

Ctrl-C in a terminal sends SIGINT to the whole foreground process group (the build and its
workers); the tests do the same with killpg on a build started in its own session.
"""

from __future__ import annotations

import json
import os
import signal
import subprocess
import time
from pathlib import Path

import pytest
from support.cli import WORLDGEN

JOBS = 2
SMALL = """\
name: stop
formats: [sdf]
seeds: {seeds}
worlds:
  - generator: cluttered
    params:
      size: {size}
      n_obstacles: {obstacles}
"""


def _sigint_as_in_a_terminal() -> None:
    # A test run started in the background (`pytest &`) inherits SIGINT ignored, and so would the build;
    # a build started from a terminal has it at its default.
    signal.signal(signal.SIGINT, signal.SIG_DFL)


def start(recipe: Path, pack: Path) -> tuple[subprocess.Popen, list[str]]:
    cmd = WORLDGEN + ["pack", "build", str(recipe), "--out", str(pack), "--jobs", str(JOBS)]
    return subprocess.Popen(cmd, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
                            start_new_session=True, preexec_fn=_sigint_as_in_a_terminal), cmd


def ctrl_c_after(proc: subprocess.Popen, pack: Path, records: int, then: float = 0.0) -> tuple[float, str]:
    """SIGINT to the build's process group ``then`` seconds after ``records`` jobs are recorded;
    (seconds from the signal to the exit, stderr)."""
    deadline = time.monotonic() + 60
    while len(list((pack / ".build").glob("*.json"))) < records:
        if time.monotonic() > deadline or proc.poll() is not None:
            proc.kill()
            pytest.fail(f"the build did not record {records} jobs within 60 s: {proc.communicate()[1]}")
        time.sleep(0.01)
    time.sleep(then)
    sent = time.monotonic()
    os.killpg(proc.pid, signal.SIGINT)
    try:
        _, err = proc.communicate(timeout=30)
    except subprocess.TimeoutExpired:
        os.killpg(proc.pid, signal.SIGKILL)
        proc.communicate()
        pytest.fail("the build was still running 30 s after Ctrl-C")
    return time.monotonic() - sent, err


def on_disk(pack: Path) -> tuple[dict[str, int], set[str], list[str]]:
    """(visible world folder -> world.json mtime, folders named by a record, hidden leftovers)."""
    worlds = pack / "worlds"
    visible = {p.name: (p / "world.json").stat().st_mtime_ns for p in worlds.iterdir() if not p.name.startswith(".")}
    recorded = {json.loads(p.read_text()).get("folder") for p in (pack / ".build").glob("*.json")}
    hidden = [p.name for p in worlds.iterdir() if p.name.startswith(".")]
    return visible, recorded, hidden


def resume(cmd: list[str], pack: Path, before: dict[str, int]) -> tuple[int, int]:
    """Rerun the build; (jobs it skipped as done, worlds on disk before it that it wrote again)."""
    run = subprocess.run(cmd, capture_output=True, text=True, timeout=300)
    assert run.returncode == 0, run.stderr
    skipped = int(run.stdout.split("(+", 1)[1].split(" ", 1)[0])
    rewritten = sum((pack / "worlds" / name / "world.json").stat().st_mtime_ns != stamp
                    for name, stamp in before.items())
    return skipped, rewritten


def test_ctrl_c_stops_within_2_s_keeps_every_finished_world_and_the_rerun_redoes_none(tmp_path):
    recipe = tmp_path / "stop.yaml"
    recipe.write_text(SMALL.format(seeds=400, size="[6, 6]", obstacles=3))
    pack = tmp_path / "pack"
    proc, cmd = start(recipe, pack)
    seconds, err = ctrl_c_after(proc, pack, records=20)
    assert proc.returncode == 130
    assert seconds < 2.0, f"the build took {seconds:.2f} s to stop"
    assert not (pack / "manifest.json").exists()
    visible, recorded, hidden = on_disk(pack)
    assert hidden == []  # nothing half-written is left
    assert set(visible) <= recorded, f"{len(set(visible) - recorded)} world folders have no record"
    assert len(visible) < 400  # the cancel kept the jobs not started from running
    skipped, rewritten = resume(cmd, pack, visible)
    assert skipped == len(recorded)
    assert rewritten <= JOBS, f"the rerun wrote {rewritten} finished worlds again"
    assert json.loads((pack / "manifest.json").read_text())["world_count"] == 400
    # One line saying what is kept, not a traceback per worker.
    assert len(err.strip().splitlines()) == 1 and err.startswith("error: interrupted: "), err


def test_ctrl_c_cuts_off_jobs_that_outlast_the_grace_and_leaves_nothing_half_written(tmp_path):
    # Worlds of ~1.5 s each, Ctrl-C 0.2 s after the second job finished: the two jobs then
    # running cannot finish within the grace (1 s), so their workers are stopped mid-job.
    recipe = tmp_path / "slow.yaml"
    recipe.write_text(SMALL.format(seeds=6, size="[100, 100]", obstacles=3000))
    pack = tmp_path / "pack"
    proc, cmd = start(recipe, pack)
    seconds, err = ctrl_c_after(proc, pack, records=2, then=0.2)
    assert proc.returncode == 130 and len(err.strip().splitlines()) == 1, err
    assert seconds < 2.0, f"the build took {seconds:.2f} s to stop"
    visible, recorded, hidden = on_disk(pack)
    assert hidden == [] and set(visible) <= recorded
    assert len(visible) == len(recorded) < 6
    skipped, rewritten = resume(cmd, pack, visible)
    assert skipped == len(recorded) and rewritten == 0
