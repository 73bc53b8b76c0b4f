"""pytest plugin: generated worlds as fixtures (registered through the ``pytest11`` entry point).

    def test_reaches_goal(worldgen_world):
        world = worldgen_world("corridor", seed=3, width=1.2)   # written into the test's tmp folder
        world.file("sdf"), world.metadata["tasks"][0]

    @pytest.mark.worldgen("cluttered", seeds=range(20), n_obstacles=30)
    def test_nav(world):                                       # ids: cluttered-s0 ... cluttered-s19
        ...

    @pytest.mark.worldgen(pack="packs/nav-v1")                 # every world of a built pack; a relative
    def test_pack(world):                                      # path is read from this file's folder
        ...                                                    # a worldgen.pack PackWorld; ids = world_id

A mistake in a marker's arguments (a typo in a parameter's name, a value out of range, a
pack that is missing or unfinished) fails that test with one line naming what is wrong
and what is allowed; the rest of the run goes on.

Options (group ``worldgen``): ``--worldgen-seed N`` keeps only seed N of every
marked test (replay one failing world; for a pack, its worlds of seed N), ``--worldgen-out DIR`` writes worlds
there instead of the tmp folder, ``--worldgen-formats`` picks the formats.

This module only wires things up; it imports nothing but pytest at start-up,
because every pytest run in an environment with worldgen installed loads it.
worldgen itself (numpy, FCL, MuJoCo) is imported when a fixture is first used.
"""

from __future__ import annotations

import pytest

from worldgen.errors import ParameterError

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


#: The marker's own keyword arguments; every other keyword is a parameter of the generator.
MARKER_ARGS = ("seeds", "allow_infeasible", "difficulty")


class _MarkerError(ParameterError):
    """A mistake in a marker's arguments: the test fails with this one line, the run goes on. A ParameterError,
    as the same mistake in a call of ``generate`` would be; importing worldgen.errors loads nothing else."""


def pytest_generate_tests(metafunc):
    mark = metafunc.definition.get_closest_marker(MARKER)
    if mark is None:
        return
    if "world" not in metafunc.fixturenames:
        raise pytest.UsageError(f"{metafunc.definition.nodeid}: @pytest.mark.worldgen needs the test to take a `world` argument")
    replay = metafunc.config.getoption("worldgen_seed")
    try:
        if "pack" in mark.kwargs:
            cases, ids = _pack_cases(metafunc, mark, replay)
        else:
            cases, ids = _generated_cases(mark, replay)
    except _MarkerError as exc:
        # One failing test saying what is wrong, instead of a traceback for every seed.
        cases, ids = [("error", f"@pytest.mark.worldgen{_call_text(mark)}: {exc}")], ["marker-error"]
    metafunc.parametrize("world", cases, ids=ids, indirect=True)


def _generated_cases(mark, replay):
    from worldgen import WorldgenError
    from worldgen.errors import InfeasibleError, did_you_mean
    from worldgen.generators import get

    if len(mark.args) != 1 or not isinstance(mark.args[0], str):
        raise _MarkerError("it takes one generator name or pack=PATH, e.g. "
                           "@pytest.mark.worldgen('cluttered', seeds=range(20), n_obstacles=30)")
    try:
        spec = get(mark.args[0])
    except WorldgenError as exc:
        raise _MarkerError(str(exc)) from None
    params = {k: v for k, v in mark.kwargs.items() if k not in MARKER_ARGS}
    known = [p.name for p in spec.all_params]
    unknown = sorted(set(params) - set(known))
    if unknown:
        raise _MarkerError(f"unknown argument '{unknown[0]}'{did_you_mean(unknown[0], (*MARKER_ARGS, *known))}; "
                           f"allowed: {', '.join(MARKER_ARGS)}, pack, or a parameter of '{spec.name}': "
                           f"{', '.join(sorted(known))}")
    allow_infeasible = mark.kwargs.get("allow_infeasible", False)
    if not isinstance(allow_infeasible, bool):
        raise _MarkerError(f"allow_infeasible must be True or False, got {allow_infeasible!r}")
    difficulty = mark.kwargs.get("difficulty")
    try:
        if difficulty is not None:  # a level request (as generate's difficulty=): checked here, drawn per seed
            from worldgen.leveling import check_request

            if allow_infeasible:
                raise _MarkerError("difficulty asks for a drivable world; it excludes allow_infeasible")
            check_request(spec.name, difficulty, params)
        else:
            spec.resolve(params)  # every value checked once here, not once per seed
    except InfeasibleError as exc:
        if not allow_infeasible:
            raise _MarkerError(f"{exc} (allow_infeasible=True writes such worlds for negative tests)") from None
    except WorldgenError as exc:
        raise _MarkerError(str(exc)) from None
    seeds = mark.kwargs.get("seeds", (0,))
    seeds = [seeds] if isinstance(seeds, int) and not isinstance(seeds, bool) else seeds
    try:
        seeds = list(seeds)
    except TypeError:
        raise _MarkerError(f"seeds must be an integer or integers, e.g. seeds=range(20), got {seeds!r}") from None
    if not seeds or any(isinstance(s, bool) or not isinstance(s, int) for s in seeds):
        raise _MarkerError(f"seeds must be an integer or integers, e.g. seeds=range(20), got {seeds!r}")
    if replay is not None:
        # Replaying one world must not silently run nothing: a seed outside the list still runs.
        seeds = [replay]
    if difficulty is not None:
        params = {**params, "difficulty": difficulty}
    cases = [("generate", spec.name, seed, params, allow_infeasible) for seed in seeds]
    return cases, [f"{spec.name}-s{seed}" for seed in seeds]


def _pack_cases(metafunc, mark, replay):
    """Every world of the pack (of seed ``replay`` only, when given). A relative path is read
    from the folder of the test file that carries the marker, wherever pytest was started."""
    from pathlib import Path

    from worldgen import Pack, WorldgenError

    extra = [f"{k}=" for k in mark.kwargs if k != "pack"]
    if mark.args or extra:
        raise _MarkerError(f"pack=PATH takes no generator, seeds or parameters, got "
                           f"{', '.join([repr(a) for a in mark.args] + extra)}")
    where = mark.kwargs["pack"]
    if not isinstance(where, (str, Path)):
        raise _MarkerError(f"pack must be a path, got {where!r}")
    path = Path(where)
    if not path.is_absolute():
        path = Path(metafunc.definition.path).parent / path
    if not path.exists():
        raise _MarkerError(f"no pack at '{path}' (a relative pack path is read from the test file's folder)")
    try:
        pack = Pack.open(path)
    except WorldgenError as exc:
        raise _MarkerError(str(exc)) from None
    worlds = [w for w in pack if replay is None or w.seed == replay]
    return [("pack", w) for w in worlds], [w.world_id for w in worlds]


def _call_text(mark) -> str:
    """The marker's arguments as written, for a message: ``('cluttered', seeds=range(0, 2))``."""
    parts = [repr(a) for a in mark.args] + [f"{k}={v!r}" for k, v in mark.kwargs.items()]
    text = f"({', '.join(parts)})"
    return text if len(text) <= 120 else text[:117] + "...)"


def _write(request, generator, seed, params, tmp, allow_infeasible=False):
    from pathlib import Path

    import worldgen

    try:
        world = worldgen.generate(generator, seed, allow_infeasible=allow_infeasible, **params)
    except worldgen.WorldgenError as exc:  # e.g. no feasible draw for this seed: the test's answer, not a bug
        pytest.fail(f"worldgen: {generator} seed {seed}: {exc}", pytrace=False)
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
    kind, *args = request.param
    if kind == "error":  # a mistake in the marker's arguments, found at collection
        pytest.fail(args[0], pytrace=False)
    if kind == "pack":
        return args[0]  # a PackWorld: its files are already on disk (or in the archive)
    generator, seed, params, allow_infeasible = args
    return _write(request, generator, seed, params, tmp_path / "worlds", allow_infeasible)
