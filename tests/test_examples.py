"""Every example runs end to end, as a user would run it."""

import subprocess
import sys
from pathlib import Path

import pytest

EXAMPLES = sorted((Path(__file__).resolve().parent.parent / "examples").glob("*.py"))


@pytest.mark.parametrize("script", EXAMPLES, ids=lambda p: p.name)
def test_example_runs(script, tmp_path):
    run = subprocess.run([sys.executable, str(script), str(tmp_path)], capture_output=True, text=True, timeout=300)
    assert run.returncode == 0, run.stderr
    assert "Traceback" not in run.stderr


def test_diffdrive_example_report(tmp_path):
    """The MuJoCo differential-drive example writes its evaluate() report: 20 runs, every criterion met."""
    import json

    script = EXAMPLES[0].parent / "diffdrive_mujoco.py"
    run = subprocess.run([sys.executable, str(script), str(tmp_path)], capture_output=True, text=True, timeout=300)
    assert run.returncode == 0, run.stdout + run.stderr
    report = json.loads((tmp_path / "report.json").read_text())
    assert report["passed"] is True and report["summary"]["runs"] == 20 and report["summary"]["collision_count"] == 0
    assert (tmp_path / "report.csv").read_text().startswith("criterion,required,measured,verdict,margin\n")
    assert run.stdout.splitlines()[-2] == "20 runs, 20 succeeded: PASS"
