"""pytest plugin: generated worlds as fixtures (registered through the ``pytest11`` entry point).

    def test_reaches_goal(worldgen_world):
        world = worldgen_world("corridor", seed=3, width=1.2)   # written into the test's tmp folder
        world.file("sdf"), world.metadata["tasks"][0]

    @pytest.mark.worldgen("cluttered", seeds=range(20), n_obstacles=30)
    def test_nav(world):                                       # ids: cluttered-s0 ... cluttered-s19
        ...

    @pytest.mark.worldgen(pack="packs/nav-v1")                 # every world of a built pack
    def test_pack(world):                                      # a worldgen.pack PackWorld; ids = world_id
        ...

Options (group ``worldgen``): ``--worldgen-seed N`` keeps only seed N of every
marked test (replay one failing world; for a pack, its worlds of seed N), ``--worldgen-out DIR`` writes worlds
there instead of the tmp folder, ``--worldgen-formats`` picks the formats.

This module only wires things up; it imports nothing but pytest at start-up,
because every pytest run in an environment with worldgen installed loads it.
worldgen itself (numpy, FCL, MuJoCo) is imported when a fixture is first used.
"""

from __future__ import annotations

import pytest

__all__ = ["pytest_addoption", "pytest_configure", "pytest_generate_tests", "worldgen_world", "world"]

MARKER = "worldgen"


def pytest_addoption(parser):
    group = parser.getgroup("worldgen", "worldgen: generated test worlds")
    group.addoption("--worldgen-seed", type=int, default=None, metavar="N",
                    help="run @pytest.mark.worldgen tests on seed N only (replay one failing world)")
    group.addoption("--worldgen-out", default=None, metavar="DIR",
                    help="write worlds into DIR (kept after the run) instead of each test's tmp folder")
    group.addoption("--worldgen-formats", default="sdf,mjcf,urdf", metavar="LIST",
                    help="formats written for each world (default: sdf,mjcf,urdf)")


def pytest_configure(config):
    config.addinivalue_line(
        "markers",
        "worldgen(generator, seeds=range(n), **params): run the test once per generated world, "
        "given as the `world` fixture (ids like cluttered-s7)",
    )


def _marker_args(mark):
    if "pack" in mark.kwargs:
        if mark.args or set(mark.kwargs) != {"pack"}:
            raise pytest.UsageError("@pytest.mark.worldgen(pack=PATH) takes the pack only, no generator, seeds or params")
        return None, [], {"pack": mark.kwargs["pack"]}
    if len(mark.args) != 1 or not isinstance(mark.args[0], str):
        raise pytest.UsageError("@pytest.mark.worldgen takes one generator name, e.g. "
                                "@pytest.mark.worldgen('cluttered', seeds=range(20), n_obstacles=30)")
    params = dict(mark.kwargs)
    seeds = params.pop("seeds", (0,))
    if isinstance(seeds, int):
        seeds = (seeds,)
    seeds = list(seeds)
    if not seeds or any(isinstance(s, bool) or not isinstance(s, int) for s in seeds):
        raise pytest.UsageError(f"@pytest.mark.worldgen: seeds must be integers, got {seeds!r}")
    return mark.args[0], seeds, params


def pytest_generate_tests(metafunc):
    mark = metafunc.definition.get_closest_marker(MARKER)
    if mark is None:
        return
    if "world" not in metafunc.fixturenames:
        raise pytest.UsageError(f"{metafunc.definition.nodeid}: @pytest.mark.worldgen needs the test to take a `world` argument")
    generator, seeds, params = _marker_args(mark)
    replay = metafunc.config.getoption("worldgen_seed")
    if generator is None:
        _parametrize_pack(metafunc, params["pack"], replay)
        return
    if replay is not None:
        # Replaying one world must not silently run nothing: a seed outside the list still runs.
        seeds = [replay]
    cases = [(generator, seed, params) for seed in seeds]
    metafunc.parametrize("world", cases, ids=[f"{generator}-s{seed}" for seed in seeds], indirect=True)


def _parametrize_pack(metafunc, where, replay):
    from pathlib import Path

    from worldgen import Pack, WorldgenError

    path = Path(where)
    if not path.is_absolute():
        path = Path(metafunc.config.rootpath) / path
    try:
        pack = Pack.open(path)
    except WorldgenError as exc:
        raise pytest.UsageError(f"@pytest.mark.worldgen(pack=...): {exc}") from None
    worlds = [w for w in pack if replay is None or w.seed == replay]
    metafunc.parametrize("world", [("pack", w) for w in worlds], ids=[w.world_id for w in worlds], indirect=True)


def _write(request, generator, seed, params, tmp):
    from pathlib import Path

    import worldgen

    world = worldgen.generate(generator, seed, **params)
    out = request.config.getoption("worldgen_out")
    world.write(Path(out) if out else tmp, formats=request.config.getoption("worldgen_formats"))
    return world


@pytest.fixture
def worldgen_world(request, tmp_path):
    """Factory: ``worldgen_world(generator, seed=0, **params)`` -> a written World (``world.path`` set)."""

    def make(generator: str, seed: int = 0, **params):
        return _write(request, generator, seed, params, tmp_path / "worlds")

    return make


@pytest.fixture
def world(request, tmp_path):
    """The world of a ``@pytest.mark.worldgen`` test, written into its tmp folder."""
    if not hasattr(request, "param"):
        raise pytest.UsageError("the `world` fixture comes from @pytest.mark.worldgen(generator, seeds=..., **params)")
    if len(request.param) == 2:  # ("pack", PackWorld)
        return request.param[1]  # a PackWorld: its files are already on disk (or in the archive)
    generator, seed, params = request.param
    return _write(request, generator, seed, params, tmp_path / "worlds")
