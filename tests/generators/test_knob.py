"""Each generator declares its difficulty knob beside its parameters (worldgen.generators.Knob), a generator from
another package too; the names leveling held before answer with a DeprecationWarning."""

from __future__ import annotations

import dataclasses
import subprocess
import sys
import textwrap

import pytest

from worldgen.errors import ParameterError
from worldgen.generators import LEVELS, GeneratorSpec, Knob, all_specs, get
from worldgen.generators.cluttered import KNOB, PARAMS, build


def test_every_generator_turns_a_parameter_it_has_or_says_why_it_has_no_levels():
    for spec in all_specs():
        if spec.knob is None:
            assert spec.no_levels, spec.name
            continue
        names = {p.name for p in spec.all_params}
        assert set(spec.knob.owned()) <= names and len(spec.knob.start) == LEVELS, spec.name
    assert get("cluttered").knob is KNOB and get("minimal").knob is None
    assert get("door").knob.reachable() == tuple(range(2, 11))


@pytest.mark.parametrize("knob, message", [
    (Knob("n_trees", KNOB.start, 1.0, 10.0), "generator 'mine': its knob sets 'n_trees', which it has no parameter for"),
    (Knob("n_obstacles", KNOB.start, 1.0, 10.0, fixed=((1, 10, {"shape": "U"}),)), "its knob sets 'shape'"),
    (Knob("n_obstacles", KNOB.start, 1.0, 10.0, excludes=("colour",)), "its knob sets 'colour'"),
])
def test_a_knob_that_names_no_parameter_of_its_generator_is_refused_where_the_generator_is_defined(knob, message):
    with pytest.raises(ParameterError) as err:
        GeneratorSpec("mine", "a test generator", PARAMS, build, knob=knob)
    assert message in str(err.value) and "\n" not in str(err.value)


def test_a_malformed_knob_is_one_line():
    with pytest.raises(ParameterError, match=r"one value \(or None\) per level 1\.\.10, got 3 for 'n_obstacles'"):
        Knob("n_obstacles", (0.0, 1.0, 2.0), 1.0, 10.0)
    with pytest.raises(ParameterError, match="low <= high and a positive step"):
        Knob("n_obstacles", KNOB.start, 0.0, 10.0)
    with pytest.raises(ParameterError, match="declares a knob and says it has no levels"):
        GeneratorSpec("mine", "a test generator", PARAMS, build, knob=KNOB, no_levels="none")


def test_a_spec_with_another_calibration_is_requested_through_its_own_knob():
    """The level search reads the knob off the spec it is given: a copy with other starting values starts there
    (the benchmark compares calibrations this way)."""
    from worldgen.leveling import generate_at_level

    spec = get("cluttered")
    moved = dataclasses.replace(spec, knob=dataclasses.replace(KNOB, start=(3.0,) * LEVELS))
    world = generate_at_level(moved, 0, "2/10", {})
    assert world.difficulty_request["draws"][0]["n_obstacles"] == 3 and world.metadata["metrics"]["difficulty_level"] == 2


def test_a_generator_from_another_package_declares_its_knob_and_is_asked_for_a_level(tmp_path):
    (tmp_path / "extra_levels.py").write_text(textwrap.dedent('''
        from worldgen.generators import GeneratorSpec, Knob
        from worldgen.generators.cluttered import build, PARAMS, check
        SPEC = GeneratorSpec("extra", "a plugin generator with levels", PARAMS, build, check,
                             knob=Knob("n_obstacles", (None, None, 17.0, 23.0, 31.0, 36.0, 41.0, 50.0, 70.0, 78.0),
                                       step=4.0, high=120.0, per_area=True, excludes=("density",)))
    '''))
    dist = tmp_path / "extra_levels-1.0.dist-info"
    dist.mkdir()
    (dist / "METADATA").write_text("Metadata-Version: 2.1\nName: extra-levels\nVersion: 1.0\n")
    (dist / "entry_points.txt").write_text("[worldgen.generators]\nextra = extra_levels:SPEC\n")
    code = ("import worldgen\nfrom worldgen.leveling import describe_levels\n"
            "w = worldgen.generate('extra', seed=0, difficulty='4/10')\n"
            "print(w.metadata['metrics']['difficulty_level'], w.difficulty_request['knob'])\n"
            "print(describe_levels('extra'))\n"
            "try:\n    worldgen.generate('extra', seed=0, difficulty='1/10')\n"
            "except worldgen.ParameterError as e:\n    print(e)\n")
    import os

    env = {"PYTHONPATH": os.pathsep.join([str(tmp_path), *sys.path[1:]]), "PATH": "/usr/bin:/bin"}
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, env=env, check=True).stdout
    assert out.splitlines() == [
        "4 n_obstacles",
        "difficulty: levels 3-10 of 10 (--difficulty K/10 turns n_obstacles)",
        "parameter 'difficulty' 1/10 is out of reach of 'extra': it reaches levels 3-10",
    ]


def test_the_names_leveling_held_answer_from_the_specs_with_a_warning():
    import worldgen.leveling as leveling

    with pytest.warns(DeprecationWarning, match=r"worldgen.leveling.KNOBS is deprecated: use each generator's spec"):
        knobs = leveling.KNOBS
    assert knobs == {s.name: s.knob for s in all_specs() if s.knob is not None}
    with pytest.warns(DeprecationWarning):
        assert leveling.NO_LEVELS == {"minimal": get("minimal").no_levels}
    assert leveling.Knob is Knob  # the same class, which leveling uses
    with pytest.warns(DeprecationWarning):
        assert (leveling.START, leveling.STEP, leveling.MAX_KNOB) == (KNOB.start, KNOB.step, KNOB.high)
    with pytest.raises(AttributeError):
        leveling.NOT_A_NAME  # noqa: B018
