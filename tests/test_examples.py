"""Every example runs end to end, as a user would run it."""

import subprocess
import sys
from pathlib import Path

import pytest

EXAMPLES = sorted((Path(__file__).resolve().parent.parent / "examples").glob("*.py"))


#: Examples that need an optional extra, and the module that tells whether it is installed.
NEEDS = {"rl_navigation.py": ("gymnasium", "rl"), "diffdrive_mujoco.py": ("rosbags", "ros")}


def _need_extra(script: Path) -> None:
    import importlib.util

    module, extra = NEEDS.get(script.name, (None, None))
    if module and importlib.util.find_spec(module) is None:
        from support import missing_tool
        missing_tool(f"{module} (pip install 'worldgen[{extra}]'), for {script.name}")


@pytest.mark.parametrize("script", EXAMPLES, ids=lambda p: p.name)
def test_example_runs(script, tmp_path):
    _need_extra(script)
    run = subprocess.run([sys.executable, str(script), str(tmp_path)], capture_output=True, text=True, timeout=300)
    assert run.returncode == 0, run.stderr
    assert "Traceback" not in run.stderr


def test_diffdrive_example_report(tmp_path):
    """The MuJoCo differential-drive example records 20 bags and judges them: 20 runs, every criterion met."""
    import json

    script = EXAMPLES[0].parent / "diffdrive_mujoco.py"
    _need_extra(script)
    run = subprocess.run([sys.executable, str(script), str(tmp_path)], capture_output=True, text=True, timeout=300)
    assert run.returncode == 0, run.stdout + run.stderr
    report = json.loads((tmp_path / "report" / "report.json").read_text())
    assert report["passed"] is True and report["summary"]["runs"] == 20 and report["summary"]["collision_count"] == 0
    assert report["summary"]["unjudged"] == 0 and {r["source"] for r in report["runs"]} == {"tf"}
    assert (tmp_path / "report" / "report.csv").read_text().startswith("run,bag,outcome,readable,world_id,task,")
    assert len(list((tmp_path / "bags").iterdir())) == 20
    assert run.stdout.splitlines()[-2] == "20 runs, 20 succeeded: PASS"


def test_rl_navigation_example_reports_both_policies(tmp_path):
    """The Gymnasium example: the path follower meets every criterion with SPL near 1, the random policy does not."""
    import json

    script = EXAMPLES[0].parent / "rl_navigation.py"
    _need_extra(script)
    run = subprocess.run([sys.executable, str(script), str(tmp_path)], capture_output=True, text=True, timeout=300)
    assert run.returncode == 0, run.stdout + run.stderr
    follower = json.loads((tmp_path / "report-follower.json").read_text())
    random = json.loads((tmp_path / "report-random.json").read_text())
    assert follower["passed"] is True and follower["summary"]["runs"] == 10
    assert random["summary"]["success_rate"] < 0.5
    summaries = [line for line in run.stdout.splitlines() if line.startswith("success rate")]
    assert len(summaries) == 2
    assert summaries[0].startswith("success rate 1.00, mean SPL ") and float(summaries[0].split()[5].rstrip(",")) > 0.9
    assert all(line.endswith("agree on success in 10 of 10 runs") for line in summaries)


# -- the shipped recipes ---------------------------------------------------------------------

RECIPES = EXAMPLES[0].parent / "recipes"


def test_the_readme_uses_the_shipped_recipes():
    readme = (RECIPES.parent.parent / "README.md").read_text()
    for name in ("ci_smoke.yaml", "barn_like.yaml", "barn.yaml"):
        assert f"examples/recipes/{name}" in readme
    assert "Not built yet" not in readme


def test_ci_smoke_recipe_builds_and_verifies(tmp_path):
    from support.cli import run

    out = tmp_path / "ci_smoke"
    built = run("pack", "build", RECIPES / "ci_smoke.yaml", "--out", out, "--jobs", "1")
    assert built.returncode == 0, built.stderr
    verified = run("pack", "verify", out)
    assert verified.returncode == 0, verified.stdout + verified.stderr
    import worldgen

    pack = worldgen.Pack.open(out)
    assert len(pack) == 14
    assert {w.generator for w in pack} == {"cluttered", "corridor", "door", "minimal"}


def test_barn_like_recipe_is_a_ladder_of_300_worlds_levels_1_to_10_in_order():
    import worldgen
    from worldgen.pack.recipe import load_recipe

    recipe = load_recipe(RECIPES / "barn_like.yaml")
    assert len(recipe) == 300
    levels = [j.level for j in recipe.jobs]
    assert levels == sorted(levels) and [levels.count(k) for k in range(1, 11)] == [30] * 10
    # One world of each level (a different request seed each) lands in its level, feasible.
    for k in range(10):
        job = recipe.jobs[30 * k + k]
        meta = worldgen.generate(job.generator, job.seed, difficulty=job.level, **job.param_dict).metadata
        assert meta["feasibility"]["feasible"] and meta["metrics"]["difficulty_level"] == job.level


def test_barn_recipe_is_barn_s_300_worlds_and_each_setting_can_be_crossed():
    import worldgen
    from worldgen.pack.recipe import load_recipe

    recipe = load_recipe(RECIPES / "barn.yaml")
    assert len(recipe) == 300 and {j.generator for j in recipe.jobs} == {"barn"}
    settings = {(j.param_dict["fill_fraction"], j.param_dict["smoothing_passes"]) for j in recipe.jobs}
    assert settings == {(f, p) for f in (0.15, 0.2, 0.25, 0.3) for p in (2, 3, 4)}
    for job in recipe.jobs[::25]:  # the first seed of each setting
        world = worldgen.generate(job.generator, job.seed, **job.param_dict)
        assert world.feasibility.feasible and (world.params["grid_cols"], world.params["cell_size"]) == (30, 0.15)


def test_diffdrive_example_among_reacting_people(tmp_path):
    """--people: the robot drives the timed path while four people react to it; no contact with the people
    as they walked, the bags pass the criteria, and the walked trajectories are written beside them."""
    import json

    script = EXAMPLES[0].parent / "diffdrive_mujoco.py"
    _need_extra(script)
    run = subprocess.run([sys.executable, str(script), str(tmp_path), "3", "--people"], capture_output=True,
                         text=True, timeout=300)
    assert run.returncode == 0, run.stdout + run.stderr
    assert run.stdout.splitlines()[-1] == "3 runs among reacting people: 0 contacts; judged: PASS"
    walked = [json.loads(p.read_text()) for p in sorted((tmp_path / "people").iterdir())]
    assert len(walked) == 3 and all(len(w) == 4 and all(len(rows) > 10 for rows in w.values()) for w in walked)
    report = json.loads((tmp_path / "report" / "report.json").read_text())
    assert all(r["social"]["by_behaviour"]["all"]["min_tube_gap"] > 0 for r in report["runs"])
