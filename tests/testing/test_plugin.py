"""The pytest plugin, run through pytester as a user's suite would run it (entry point loaded)."""

import subprocess
import sys

# In a subprocess each: in-process runs restore sys.modules afterwards, and numpy cannot be imported twice.
pytest_plugins = ["pytester"]

QUICK = "size=[6, 6], n_obstacles=3"


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


def test_factory_fixture_writes_into_tmp(pytester):
    pytester.makepyfile("""
        def test_corridor(worldgen_world, tmp_path):
            world = worldgen_world("corridor", seed=3, width=1.2)
            assert world.path.parent == tmp_path / "worlds"
            assert world.file("json").is_file() and world.params["width"] == 1.2
    """)
    pytester.runpytest_subprocess().assert_outcomes(passed=1)


def test_marker_mistakes_are_usage_errors(pytester):
    pytester.makepyfile("""
        import pytest

        @pytest.mark.worldgen(seeds=range(2))
        def test_nav(world):
            pass
    """)
    result = pytester.runpytest_subprocess()
    assert result.ret != 0
    result.stdout.fnmatch_lines(["*UsageError: @pytest.mark.worldgen takes one generator name*"])


def test_pack_parametrisation(pytester, tmp_path):
    from worldgen.pack import build_pack, parse_recipe

    recipe = "name: tiny\nseeds: 2\nworlds:\n  - generator: cluttered\n    params:\n      size: [6, 6]\n      n_obstacles: 3\n"
    build_pack(parse_recipe(recipe, "tiny.yaml", "tiny"), tmp_path / "pack", jobs=1)
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
