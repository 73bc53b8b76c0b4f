"""The pytest plugin, run through pytester as a user's suite would run it (entry point loaded)."""

import subprocess
import sys

from support.cli import run

# In a subprocess each: in-process runs restore sys.modules afterwards, and numpy cannot be imported twice.
pytest_plugins = ["pytester"]

QUICK = "size=[6, 6], n_obstacles=3"
TINY = "name: tiny\nseeds: 2\nworlds:\n  - generator: cluttered\n    params:\n      size: [6, 6]\n      n_obstacles: 3\n"


def build_tiny(out):
    """A two-world pack, built by the command (in-process, the generators would be imported inside
    a pytester test, whose end unloads them while the registry keeps their specs)."""
    recipe = out.parent / "tiny.yaml"
    out.parent.mkdir(parents=True, exist_ok=True)
    recipe.write_text(TINY)
    done = run("pack", "build", recipe, "--out", out)
    assert done.returncode == 0, done.stderr


def test_registered_through_the_entry_point_and_light():
    from importlib.metadata import entry_points

    assert [e.value for e in entry_points(group="pytest11") if e.name == "worldgen"] == ["worldgen.testing.plugin"]
    code = ("import sys, worldgen.testing.plugin; "
            "print(sorted(m for m in ('numpy', 'fcl', 'mujoco', 'scipy', 'shapely', 'trimesh', 'lxml') if m in sys.modules))")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True).stdout
    assert out.strip() == "[]"


def test_options_in_one_group(pytester):
    result = pytester.runpytest_subprocess("--help")
    result.stdout.fnmatch_lines(["worldgen: generated test worlds:", "*--worldgen-seed=N*", "*--worldgen-out=DIR*"])


def test_marker_parametrises_with_readable_ids(pytester):
    pytester.makepyfile(f"""
        import pytest

        @pytest.mark.worldgen("cluttered", seeds=range(3), {QUICK})
        def test_nav(world):
            assert world.path.is_dir() and (world.path / "world.sdf").is_file()
            assert world.metadata["params"]["n_obstacles"] == 3
            assert world.seed != 1, "seed 1 fails on purpose"
    """)
    result = pytester.runpytest_subprocess("-v")
    result.stdout.fnmatch_lines(["*test_nav?cluttered-s0? PASSED*", "*test_nav?cluttered-s1? FAILED*",
                                 "*test_nav?cluttered-s2? PASSED*"])
    result.assert_outcomes(passed=2, failed=1)


def test_seed_option_replays_one_world(pytester):
    pytester.makepyfile(f"""
        import pytest

        @pytest.mark.worldgen("cluttered", seeds=range(20), {QUICK})
        def test_nav(world):
            assert world.seed == 7
    """)
    result = pytester.runpytest_subprocess("-v", "--worldgen-seed", "7")
    result.stdout.fnmatch_lines(["*test_nav?cluttered-s7? PASSED*"])
    result.assert_outcomes(passed=1)


def test_the_marker_asks_for_a_level_as_generate_and_the_cli_do(pytester):
    pytester.makepyfile("""
        import pytest

        @pytest.mark.worldgen("cluttered", seeds=[0], difficulty="2/10", size=[5, 5])
        def test_level(world):
            assert world.metadata["metrics"]["difficulty_level"] == 2
            assert world.metadata["difficulty_request"]["level"] == "2/10"

        @pytest.mark.worldgen("cluttered", seeds=[0], difficulty="12/10")
        def test_no_such_level(world):
            pass

        @pytest.mark.worldgen("cluttered", seeds=[0], difficulty=3, n_obstacles=4)
        def test_level_and_its_knob(world):
            pass
    """)
    result = pytester.runpytest_subprocess()
    result.assert_outcomes(passed=1, errors=2)
    one = {name.split("[")[0]: lines[0] for name, lines in error_sections(result).items()}
    assert "parameter 'difficulty' must be a level 'k/10'" in one["test_no_such_level"]
    assert "leave out 'n_obstacles'" in one["test_level_and_its_knob"]


def test_factory_fixture_writes_into_tmp(pytester):
    pytester.makepyfile("""
        def test_corridor(worldgen_world, tmp_path):
            world = worldgen_world("corridor", seed=3, width=1.2)
            assert world.path.parent == tmp_path / "worlds"
            assert world.file("json").is_file() and world.params["width"] == 1.2
    """)
    pytester.runpytest_subprocess().assert_outcomes(passed=1)


def error_sections(result) -> dict[str, list[str]]:
    """The lines of each ``ERROR at setup of TEST`` section of a pytest report, by TEST."""
    sections: dict[str, list[str]] = {}
    current = None
    for line in result.stdout.lines:
        if line.startswith("_") and " ERROR at setup of " in line:
            current = line.split(" ERROR at setup of ", 1)[1].strip(" _")
            sections[current] = []
        elif line.startswith("=") or (line.startswith("_") and line.endswith("_")):
            current = None
        elif current is not None and line.strip():
            sections[current].append(line)
    return sections


def test_a_mistake_in_a_marker_fails_that_test_with_one_line_and_the_run_goes_on(pytester):
    pytester.makepyfile(f"""
        import pytest

        @pytest.mark.worldgen("cluttered", seeds=range(2), size=[6, 6], n_obstacle=3)
        def test_typo_in_a_parameter(world):
            pass

        @pytest.mark.worldgen("clutterd", seeds=range(2))
        def test_typo_in_the_generator(world):
            pass

        @pytest.mark.worldgen("cluttered", seed=4, {QUICK})
        def test_seed_for_seeds(world):
            pass

        @pytest.mark.worldgen("cluttered", seeds=range(2), size=[6, 6], n_obstacles=-3)
        def test_value_out_of_range(world):
            pass

        @pytest.mark.worldgen(seeds=range(2))
        def test_no_generator(world):
            pass

        @pytest.mark.worldgen("cluttered", seeds=[0], {QUICK})
        def test_fine(world):
            pass
    """)
    result = pytester.runpytest_subprocess()
    result.assert_outcomes(passed=1, errors=5)  # one per marked test, not one per seed
    sections = error_sections(result)
    assert sorted(sections) == sorted(f"{t}[marker-error]" for t in (
        "test_typo_in_a_parameter", "test_typo_in_the_generator", "test_seed_for_seeds", "test_value_out_of_range",
        "test_no_generator"))
    assert all(len(lines) == 1 for lines in sections.values()), sections  # no traceback
    one = {name.split("[")[0]: lines[0] for name, lines in sections.items()}
    assert "unknown argument 'n_obstacle' (did you mean 'n_obstacles'?); allowed: seeds, allow_infeasible, difficulty, " \
           "pack, " \
           "or a parameter of 'cluttered': box_size" in one["test_typo_in_a_parameter"]
    assert "unknown generator 'clutterd' (did you mean 'cluttered'?); available: barn, cluttered, corridor" \
           in one["test_typo_in_the_generator"]
    assert "unknown argument 'seed' (did you mean 'seeds'?)" in one["test_seed_for_seeds"]
    assert "parameter 'n_obstacles' must be" in one["test_value_out_of_range"]
    assert "takes one generator name or pack=PATH" in one["test_no_generator"]
    assert all(line.startswith("@pytest.mark.worldgen(") for line in one.values())


def test_a_relative_pack_path_is_read_from_the_test_files_folder(pytester):
    suite = pytester.mkdir("suite")
    build_tiny(suite / "packs" / "tiny")
    (suite / "test_over_pack.py").write_text(
        "import pytest\n\n"
        "@pytest.mark.worldgen(pack='packs/tiny')\n"
        "def test_pack(world):\n"
        "    assert world.metadata['world_id'] == world.world_id\n")
    # Started from the folder above the suite and from a folder beside it: the same two worlds.
    pytester.runpytest_subprocess("suite").assert_outcomes(passed=2)
    elsewhere = pytester.mkdir("elsewhere")
    result = pytester.run(sys.executable, "-m", "pytest", "-p", "no:cacheprovider", "--rootdir", str(elsewhere),
                          str(suite / "test_over_pack.py"))
    result.assert_outcomes(passed=2)


def test_a_missing_or_unfinished_pack_is_said_plainly(pytester):
    pytester.mkdir("not_a_pack")
    (pytester.mkdir("stopped") / ".build").mkdir()  # a build stopped before its manifest
    pytester.makepyfile("""
        import pytest

        @pytest.mark.worldgen(pack="packs/nowhere")
        def test_missing(world):
            pass

        @pytest.mark.worldgen(pack="not_a_pack")
        def test_not_a_pack(world):
            pass

        @pytest.mark.worldgen(pack="stopped")
        def test_unfinished(world):
            pass
    """)
    result = pytester.runpytest_subprocess()
    result.assert_outcomes(errors=3)
    one = {name.split("[")[0]: lines for name, lines in error_sections(result).items()}
    assert all(len(lines) == 1 for lines in one.values()), one
    here = pytester.path
    assert one["test_missing"][0].endswith(f"no pack at '{here / 'packs/nowhere'}' "
                                           "(a relative pack path is read from the test file's folder)")
    assert one["test_not_a_pack"][0].endswith(f"'{here / 'not_a_pack'}' is not a pack: it has no manifest.json "
                                              f"(build one with 'worldgen pack build RECIPE --out {here / 'not_a_pack'}')")
    assert f"'{here / 'stopped'}' is a pack whose build has not finished" in one["test_unfinished"][0]
    assert not any("has not finished" in line for line in one["test_missing"] + one["test_not_a_pack"])


def test_pack_parametrisation(pytester, tmp_path):
    build_tiny(tmp_path / "pack")
    pytester.makepyfile(f"""
        import pytest

        @pytest.mark.worldgen(pack={str(tmp_path / "pack")!r})
        def test_pack(world):
            assert world.metadata["world_id"] == world.world_id
    """)
    result = pytester.runpytest_subprocess("-v")
    result.stdout.fnmatch_lines(["*test_pack?cluttered-s0-*? PASSED*", "*test_pack?cluttered-s1-*? PASSED*"])
    result.assert_outcomes(passed=2)
    pytester.runpytest_subprocess("-v", "--worldgen-seed", "1").assert_outcomes(passed=1)


def test_out_option_keeps_the_worlds(pytester, tmp_path):
    pytester.makepyfile(f"""
        import pytest

        @pytest.mark.worldgen("cluttered", seeds=[4], {QUICK})
        def test_nav(world):
            assert world.path.parent == __import__("pathlib").Path({str(tmp_path / "kept")!r})
    """)
    pytester.runpytest_subprocess("--worldgen-out", str(tmp_path / "kept"), "--worldgen-formats", "mjcf").assert_outcomes(passed=1)
    [folder] = (tmp_path / "kept").iterdir()
    assert folder.name.startswith("cluttered-s4-") and (folder / "world.mjcf.xml").is_file()
    assert not (folder / "world.sdf").exists()
