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


# -- the shipped recipes ---------------------------------------------------------------------

RECIPES = EXAMPLES[0].parent / "recipes"


def test_the_readme_uses_the_shipped_recipes():
    readme = (RECIPES.parent.parent / "README.md").read_text()
    for name in ("ci_smoke.yaml", "barn_like.yaml"):
        assert f"examples/recipes/{name}" in readme
    assert "Not built yet" not in readme


def test_ci_smoke_recipe_builds_and_verifies(tmp_path):
    from test_cli import run

    out = tmp_path / "ci_smoke"
    built = run("pack", "build", RECIPES / "ci_smoke.yaml", "--out", out, "--jobs", "1")
    assert built.returncode == 0, built.stderr
    verified = run("pack", "verify", out)
    assert verified.returncode == 0, verified.stdout + verified.stderr
    import worldgen

    pack = worldgen.Pack.open(out)
    assert len(pack) == 14
    assert {w.generator for w in pack} == {"cluttered", "corridor", "door", "minimal"}


def test_barn_like_recipe_is_300_worlds_spanning_difficulty():
    import worldgen
    from worldgen.pack.recipe import load_recipe

    recipe = load_recipe(RECIPES / "barn_like.yaml")
    assert len(recipe) == 300
    assert sum(j.generator == "cluttered" for j in recipe.jobs) == sum(j.generator == "corridor" for j in recipe.jobs) == 150
    # A spread sample (every 10th job: each clutter level and corridor width, several seeds) is feasible,
    # and the BARN figures span easy to hard.
    passage, visibility = [], []
    for job in recipe.jobs[::10]:
        meta = worldgen.generate(job.generator, job.seed, **job.param_dict).metadata
        assert meta["feasibility"]["feasible"]
        passage.append(meta["metrics"]["narrowest_passage"])
        visibility.append(meta["metrics"]["average_visibility"])
    assert min(passage) < 0.7 and max(passage) > 1.2
    assert max(visibility) / min(visibility) > 1.5
