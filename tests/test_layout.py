"""The package's shape: imports run one way (no cycles, counting imports inside functions too),
no module grows past about 400 lines, and every module says what it exports."""

import ast
from pathlib import Path

import pytest

PACKAGE = Path(__file__).resolve().parent.parent / "worldgen"
MAX_LINES = 400


def modules() -> dict[str, Path]:
    out = {}
    for path in sorted(PACKAGE.rglob("*.py")):
        if "templates" in path.relative_to(PACKAGE).parts:
            continue
        parts = ("worldgen",) + path.relative_to(PACKAGE).with_suffix("").parts
        name = ".".join(parts[:-1] if parts[-1] == "__init__" else parts)
        out[name] = path
    return out


def imports_of(name: str, path: Path, known: set[str]) -> set[str]:
    """Every worldgen module ``name`` imports, wherever the import statement stands."""
    is_package = path.name == "__init__.py"
    found = set()
    for node in ast.walk(ast.parse(path.read_text(), str(path))):
        if isinstance(node, ast.Import):
            targets = [alias.name for alias in node.names]
        elif isinstance(node, ast.ImportFrom):
            if node.level:
                base = name.split(".") if is_package else name.split(".")[:-1]
                base = base[: len(base) - node.level + 1]
                module = ".".join(base + ([node.module] if node.module else []))
            else:
                module = node.module or ""
            # ``from package import submodule`` imports the submodule as well as the package.
            targets = [module] + [f"{module}.{alias.name}" for alias in node.names]
        else:
            continue
        for target in targets:
            while target and target not in known:
                target = target.rpartition(".")[0]
            if target and target != name:
                found.add(target)
    return found


def import_graph() -> dict[str, set[str]]:
    """Module -> the worldgen modules it imports. A submodule importing its own package is an edge to the
    package's __init__, a cycle only when that __init__ imports the submodule back."""
    mods = modules()
    return {name: imports_of(name, path, set(mods)) for name, path in mods.items()}


def cycles(graph: dict[str, set[str]]) -> list[list[str]]:
    """Strongly connected components with more than one module (Tarjan)."""
    index, low, stack, on, out = {}, {}, [], set(), []
    counter = [0]

    def visit(v):
        index[v] = low[v] = counter[0]
        counter[0] += 1
        stack.append(v)
        on.add(v)
        for w in graph.get(v, ()):
            if w not in index:
                visit(w)
                low[v] = min(low[v], low[w])
            elif w in on:
                low[v] = min(low[v], index[w])
        if low[v] == index[v]:
            component = []
            while True:
                w = stack.pop()
                on.discard(w)
                component.append(w)
                if w == v:
                    break
            if len(component) > 1:
                out.append(sorted(component))

    for v in sorted(graph):
        if v not in index:
            visit(v)
    return out


def test_the_import_graph_has_no_cycles():
    found = cycles(import_graph())
    assert not found, "import cycles:\n" + "\n".join(" <-> ".join(c) for c in found)


def test_the_cycle_finder_finds_a_cycle():
    assert cycles({"a": {"b"}, "b": {"c"}, "c": {"a"}, "d": {"a"}}) == [["a", "b", "c"]]
    assert cycles({"a": {"b"}, "b": set()}) == []


@pytest.mark.parametrize("name", sorted(modules()))
def test_modules_stay_small_and_declare_their_exports(name):
    path = modules()[name]
    text = path.read_text()
    lines = len(text.splitlines())
    if lines > MAX_LINES:
        pytest.fail(f"{path.relative_to(PACKAGE.parent)} has {lines} lines (at most {MAX_LINES})")
    tree = ast.parse(text)
    declared = any(isinstance(n, (ast.Assign, ast.AnnAssign)) and any(
        isinstance(t, ast.Name) and t.id == "__all__" for t in (n.targets if isinstance(n, ast.Assign) else [n.target]))
        for n in tree.body)
    if not (declared or name.endswith("__main__")):
        pytest.fail(f"{name} has no __all__")


TESTS = Path(__file__).resolve().parent


def test_tests_mirror_the_package_and_share_helpers_only_through_support():
    """A folder of tests/ is named for the worldgen subpackage it tests; helpers come from tests/support,
    never from another test file (a test module imported twice runs its module-level code twice)."""
    subpackages = {p.name for p in PACKAGE.iterdir() if (p / "__init__.py").exists()}
    for folder in TESTS.iterdir():
        if folder.is_dir() and folder.name not in {"support", "tools", ".cache", "__pycache__"}:
            assert folder.name in subpackages, f"tests/{folder.name}/ names no worldgen subpackage"
    for path in TESTS.rglob("*.py"):
        for node in ast.walk(ast.parse(path.read_text(), str(path))):
            names = [a.name for a in node.names] if isinstance(node, ast.Import) else \
                [node.module or ""] if isinstance(node, ast.ImportFrom) else []
            for name in names:
                assert not name.split(".")[0].startswith(("test_", "conftest")), \
                    f"{path.relative_to(TESTS)} imports {name}: shared helpers belong in tests/support"


# -- rooms and the flow between them ------------------------------------------------------------------

#: The rooms in the order the data flows: a room may import the rooms before it, never one after it.
#: Top-level modules are rooms of their own. Rooms on one rank may not import each other.
FLOW = [
    {"errors"}, {"floats", "files", "seeding", "schema"}, {"params"}, {"scene"}, {"generators"}, {"feasibility"},
    {"groundtruth"}, {"people"}, {"export"}, {"ros"}, {"world"}, {"pipeline"}, {"leveling"}, {"api"}, {"presets"},
    {"verify"}, {"pack"}, {"judge"}, {"testing"}, {"envs"}, {"sim"}, {"campaign"}, {"cli"}, {"__main__"},
]
MAX_TOP_LEVEL = 10


def room_of(module: str) -> str:
    parts = module.split(".")
    return parts[1] if len(parts) > 1 else "worldgen"


def rank(room: str) -> int:
    for i, rooms in enumerate(FLOW):
        if room in rooms:
            return i
    raise KeyError(room)


def against_the_flow(graph: dict[str, set[str]]) -> list[str]:
    out = []
    for a, targets in sorted(graph.items()):
        for b in sorted(targets):
            ra, rb = room_of(a), room_of(b)
            if "worldgen" in (ra, rb) or ra == rb:
                continue  # the package's own __init__ imports nothing but errors; a room within itself is free
            if rank(rb) >= rank(ra):
                out.append(f"{a} -> {b}")
    return out


def test_every_room_has_its_place_in_the_flow():
    rooms = {room_of(m) for m in modules()} - {"worldgen"}
    placed = set().union(*FLOW)
    assert rooms <= placed, f"rooms missing from FLOW: {sorted(rooms - placed)}"


def test_no_import_runs_against_the_flow():
    found = against_the_flow(import_graph())
    assert not found, "imports against the flow (FLOW in this file):\n" + "\n".join(found)


def test_the_flow_check_finds_an_import_back_up():
    assert against_the_flow({"worldgen.feasibility.planner": {"worldgen.people.crowd"}}) == \
        ["worldgen.feasibility.planner -> worldgen.people.crowd"]
    assert against_the_flow({"worldgen.people.crowd": {"worldgen.feasibility.planner"}}) == []


def test_the_top_level_holds_at_most_ten_modules():
    top = sorted(p.name for p in PACKAGE.glob("*.py") if p.name != "__init__.py")
    assert len(top) <= MAX_TOP_LEVEL, f"{len(top)} modules at the top level (at most {MAX_TOP_LEVEL}): {top}"


#: How a long function says why it is long: a comment on the line above its ``def`` (or its decorators).
LONG_REASON = "# long:"
MAX_FUNCTION_LINES = 60


def long_functions_without_reason() -> list[str]:
    out = []
    for name, path in sorted(modules().items()):
        lines = path.read_text().splitlines()
        for node in ast.walk(ast.parse("\n".join(lines))):
            if not isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef)):
                continue
            length = node.end_lineno - node.lineno + 1
            first = min([node.lineno] + [d.lineno for d in node.decorator_list])
            above = lines[first - 2].strip() if first >= 2 else ""
            if length > MAX_FUNCTION_LINES and not above.startswith(LONG_REASON):
                out.append(f"{path.relative_to(PACKAGE.parent)}:{node.lineno} {node.name} ({length} lines)")
    return out


def test_functions_over_60_lines_say_why():
    found = long_functions_without_reason()
    assert not found, f"functions over {MAX_FUNCTION_LINES} lines with no '{LONG_REASON} ...' comment above:\n" + \
        "\n".join(found)


def test_file_names_are_spelled_only_in_files_py():
    """A world's and a pack's file names come from worldgen/files.py: a literal elsewhere is a second spelling
    that a rename would miss."""
    files_py = PACKAGE / "files.py"
    names = {node.value.value for node in ast.parse(files_py.read_text()).body
             if isinstance(node, ast.Assign) and isinstance(node.value, ast.Constant) and isinstance(node.value.value, str)
             and "." in node.value.value}
    assert "world.json" in names
    found = []
    for name, path in sorted(modules().items()):
        if path == files_py:
            continue
        for node in ast.walk(ast.parse(path.read_text())):
            if isinstance(node, ast.Constant) and node.value in names:
                found.append(f"{path.relative_to(PACKAGE.parent)}:{node.lineno} {node.value!r}")
    assert not found, "file names spelled outside files.py:\n" + "\n".join(found)


#: Builtin exceptions the package still raises itself, each with the reason it is not a WorldgenError.
BUILTIN_RAISES_ALLOWED = {
    ("export/metadata.py", "TypeError"): "the JSON encoder's protocol: a value world.json cannot hold is a bug in the caller",
    ("params.py", "ValueError"): "raised and caught a line later, inside parsing; never leaves the function",
    ("ros/cdr.py", "ValueError"): "the fast decoder's own signal; the reader catches it and falls back to rosbags",
    ("export/ros2.py", "AssertionError"): "an invariant of the shipped templates, not of anything a user gives",
    ("pack/archive.py", "FileNotFoundError"): "the archive's file reader answers as open() does",
    ("feasibility/report.py", "KeyError"): "the report's mapping protocol (report['check_name'])",
    ("pack/pack.py", "KeyError"): "the pack's mapping protocol (pack['world_id'])",
    ("__init__.py", "AttributeError"): "a module's __getattr__ protocol (names loaded on first use)",
    ("envs/__init__.py", "AttributeError"): "a module's __getattr__ protocol (names loaded on first use)",
    ("judge/__init__.py", "AttributeError"): "a module's __getattr__ protocol (names loaded on first use)",
}


def test_every_error_the_package_raises_is_a_worldgen_error():
    """Callers catch WorldgenError (the command line maps it to one line): a builtin exception raised by the
    package itself escapes that, so each one left is listed above with its reason."""
    import builtins

    builtin_errors = {n for n, v in vars(builtins).items() if isinstance(v, type) and issubclass(v, BaseException)}
    found = []
    for name, path in sorted(modules().items()):
        rel = path.relative_to(PACKAGE).as_posix()
        for node in ast.walk(ast.parse(path.read_text())):
            if not isinstance(node, ast.Raise) or node.exc is None:
                continue
            target = node.exc.func if isinstance(node.exc, ast.Call) else node.exc
            raised = target.id if isinstance(target, ast.Name) else None
            if raised in builtin_errors and raised not in {"StopIteration", "KeyboardInterrupt", "SystemExit"} \
                    and (rel, raised) not in BUILTIN_RAISES_ALLOWED:
                found.append(f"worldgen/{rel}:{node.lineno} raises {raised}")
    assert not found, "raise a WorldgenError subclass (worldgen/errors.py) instead:\n" + "\n".join(found)
    from worldgen import errors

    for cls in vars(errors).values():
        if isinstance(cls, type) and issubclass(cls, Exception) and cls.__module__ == errors.__name__:
            assert issubclass(cls, errors.WorldgenError), cls


def test_random_streams_are_made_only_in_seeding_py():
    """Every random stream comes from a seed through worldgen/seeding.py (its table names what each is for)."""
    import re

    made = re.compile(r"default_rng|SeedSequence|np\.random\.(seed|rand|randn|random|uniform|normal|choice)\(|\bimport random\b")
    found = [f"{path.relative_to(PACKAGE.parent)}:{i}" for name, path in sorted(modules().items())
             if path.name != "seeding.py"
             for i, line in enumerate(path.read_text().splitlines(), 1) if made.search(line)]
    assert not found, "random streams made outside seeding.py:\n" + "\n".join(found)


# -- judging in the judge's room --------------------------------------------------------------------------

#: The judging: one run's figures, the criteria, many runs evaluated, the statistics. They live in judge/;
#: testing/ (the test author's face) only imports them.
JUDGING = ("criteria", "evaluate", "figures", "proxemics", "social", "stats")


def test_the_judging_lives_in_the_judges_room():
    for name in JUDGING:
        assert (PACKAGE / "judge" / f"{name}.py").is_file(), f"worldgen/judge/{name}.py is missing"
        assert not (PACKAGE / "testing" / f"{name}.py").exists(), \
            f"worldgen/testing/{name}.py: the judging lives in judge/ (the old name imports through testing/__init__)"


def test_judging_is_taken_from_the_judge_never_from_testing():
    """testing/ comes after judge/ and imports it; the rooms that use a run's figures, the criteria or the
    statistics to do their own work (the judge itself, the environment, the simulators) take them from judge/."""
    found = [f"{a} -> {b}" for a, targets in sorted(import_graph().items()) for b in sorted(targets)
             if room_of(a) in {"judge", "envs", "sim"} and room_of(b) == "testing"]
    assert not found, "take the judging from worldgen.judge, not worldgen.testing:\n" + "\n".join(found)
    assert rank("judge") < rank("testing")


def test_the_package_never_imports_the_judgings_old_names():
    """worldgen.testing.stats and its kind still import for users, with a DeprecationWarning; the package itself
    uses the new names, or every run would warn."""
    old = {f"worldgen.testing.{name}" for name in JUDGING}
    found = []
    for name, path in sorted(modules().items()):
        for node in ast.walk(ast.parse(path.read_text(), str(path))):
            if isinstance(node, ast.Import):
                named = {alias.name for alias in node.names}
            elif isinstance(node, ast.ImportFrom) and not node.level:
                named = {node.module or ""} | {f"{node.module}.{alias.name}" for alias in node.names}
            else:
                continue
            found += [f"{path.relative_to(PACKAGE.parent)}:{node.lineno} {n}" for n in sorted(named & old)]
    assert not found, "import these from worldgen.judge:\n" + "\n".join(found)


# -- the level request as a visible call (issue 35, item 4) --------------------------------------------

#: leveling answers the names it held before the knobs moved into the generators' specs through a module
#: ``__getattr__`` (with a DeprecationWarning), whose protocol is an AttributeError for any other name.
BUILTIN_RAISES_ALLOWED[("leveling.py", "AttributeError")] = "a module's __getattr__ protocol (moved names, deprecated)"


def _functions_passed_as_arguments(text: str, where: str) -> list[str]:
    """Calls in module source ``text`` that hand over one of the module's own functions as an argument."""
    tree = ast.parse(text)
    own = {n.name for n in tree.body if isinstance(n, (ast.FunctionDef, ast.AsyncFunctionDef))}
    return [f"{where}:{node.lineno} passes {arg.id}"
            for node in ast.walk(tree) if isinstance(node, ast.Call)
            for arg in [*node.args, *(k.value for k in node.keywords)] if isinstance(arg, ast.Name) and arg.id in own]


def _callable_parameters(text: str, where: str) -> list[str]:
    """Parameters of the functions in module source ``text`` annotated as callables (a callback coming in)."""
    out = []
    for node in ast.walk(ast.parse(text)):
        if isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef)):
            for arg in [*node.args.posonlyargs, *node.args.args, *node.args.kwonlyargs]:
                if arg.annotation is not None and "Callable" in ast.unparse(arg.annotation):
                    out.append(f"{where}:{node.lineno} {node.name}({arg.arg})")
    return out


def test_a_level_request_calls_the_pipeline_itself():
    """A level request draws each world through worldgen.pipeline, which it imports: the edge is in the import
    graph. generate hands nothing to it to be called back, and it takes no callable."""
    graph = import_graph()
    assert any(t == "worldgen.pipeline" or t.startswith("worldgen.pipeline.") for t in graph["worldgen.leveling"])
    assert "worldgen.leveling" in graph["worldgen.api"]
    found = _functions_passed_as_arguments((PACKAGE / "api.py").read_text(), "worldgen/api.py") + \
        _callable_parameters((PACKAGE / "leveling.py").read_text(), "worldgen/leveling.py")
    assert not found, "a callback between api and leveling (call the pipeline instead):\n" + "\n".join(found)


def test_the_callback_finders_find_a_callback():
    text = "from typing import Callable\ndef f(x): pass\ndef g(cb: Callable, n: int):\n    g(f, 1)\n    g(cb=f, n=2)\n"
    assert _functions_passed_as_arguments(text, "m.py") == ["m.py:4 passes f", "m.py:5 passes f"]
    assert _callable_parameters(text, "m.py") == ["m.py:3 g(cb)"]
    assert _functions_passed_as_arguments("def f(): pass\nprint(len([]))\n", "m.py") == []


def test_every_generator_declares_its_difficulty_knob_beside_its_parameters():
    """Each built-in generator's spec says how a level request turns it (``knob=``) or why it cannot
    (``no_levels=``), in its own module; no other module makes a Knob, so there is no table to keep in step."""
    from worldgen.generators import all_specs

    undeclared, elsewhere = [], []
    for name, path in sorted(modules().items()):
        tree = ast.parse(path.read_text())
        in_generators = name.startswith("worldgen.generators.")
        for node in ast.walk(tree):
            if not isinstance(node, ast.Call):
                continue
            called = node.func.id if isinstance(node.func, ast.Name) else getattr(node.func, "attr", None)
            if called == "Knob" and not in_generators:
                elsewhere.append(f"{path.relative_to(PACKAGE.parent)}:{node.lineno}")
            if called == "GeneratorSpec" and in_generators and \
                    not {k.arg for k in node.keywords} & {"knob", "no_levels"}:
                undeclared.append(f"{path.relative_to(PACKAGE.parent)}:{node.lineno}")
    assert not undeclared, "generator specs without knob= or no_levels=:\n" + "\n".join(undeclared)
    assert not elsewhere, "knobs made outside the generators they turn:\n" + "\n".join(elsewhere)
    for spec in all_specs():
        assert (spec.knob is None) == bool(spec.no_levels), spec.name


# -- one reader of a world folder --

#: Modules that may name world.json (``METADATA_NAME``, or a path ending in it), each with its reason; everything
#: else reads a world through worldgen.groundtruth.folder (``open_world``, ``WorldFolder``, ``is_world_folder``).
WORLD_JSON_NAMED = {
    "groundtruth/folder.py": "the reader",
    "files.py": "defines the name; refuse_other_world reads the content_hash a folder records before a write "
                "replaces it (the writer's guard, in a room below every room the reader could live in)",
    "world.py": "the writer: world.json among a folder's files, and read()/file('json') of the in-memory World",
    "pack/render.py": "a pack build, the writer: the figures its manifest copies come from the world.json just rendered",
    "pack/manifest.py": "finds a world's folder by the path its world.json is listed under in a manifest; opens nothing",
    "pack/verify.py": "checks that a pack's manifest lists world.json with its sha256; parses it through the reader",
    "verify/folder.py": "checks a received folder's raw bytes: a missing or broken world.json is the verdict of its "
                        "`metadata` check, not a usage error, and a fresh export's world.json is compared with it",
    "campaign/judging.py": "a writer: the per-run copy of a world folder whose world.json holds the people as they "
                           "walked in the episode, which the judge then reads through the reader",
}


def world_json_named(sources: dict[str, str]) -> list[str]:
    """``rel:line`` of every naming of world.json in ``sources`` (relative path -> text) outside WORLD_JSON_NAMED:
    the name ``METADATA_NAME``, or a string that is, or ends in, ``/world.json`` (docstrings aside)."""
    import re

    path_like = re.compile(r"(.*[/*])?world\.json")
    found = []
    for rel, text in sorted(sources.items()):
        if rel in WORLD_JSON_NAMED:
            continue
        tree = ast.parse(text)
        docstrings = {id(n.body[0].value) for n in ast.walk(tree)
                      if isinstance(n, (ast.Module, ast.ClassDef, ast.FunctionDef, ast.AsyncFunctionDef))
                      and n.body and isinstance(n.body[0], ast.Expr) and isinstance(n.body[0].value, ast.Constant)}
        for node in ast.walk(tree):
            named = (isinstance(node, ast.Name) and node.id == "METADATA_NAME") or \
                (isinstance(node, ast.Attribute) and node.attr == "METADATA_NAME") or \
                (isinstance(node, ast.alias) and node.name == "METADATA_NAME") or \
                (isinstance(node, ast.Constant) and isinstance(node.value, str) and id(node) not in docstrings
                 and path_like.fullmatch(node.value) is not None)
            if named:
                found.append(f"worldgen/{rel}:{getattr(node, 'lineno', '?')}")
    return found


def test_world_json_is_read_only_through_the_reader():
    sources = {path.relative_to(PACKAGE).as_posix(): path.read_text() for path in modules().values()}
    found = world_json_named(sources)
    assert not found, ("world.json named outside its reader (read the world with worldgen.groundtruth.folder."
                       "open_world, or add the module to WORLD_JSON_NAMED with its reason):\n" + "\n".join(found))
    assert set(WORLD_JSON_NAMED) <= set(sources), sorted(set(WORLD_JSON_NAMED) - set(sources))


def test_the_world_json_rule_finds_a_hand_rolled_read():
    hand_rolled = [
        "from worldgen.files import METADATA_NAME\nmeta = json.loads((folder / METADATA_NAME).read_text())\n",
        "import worldgen.files as f\nmeta = json.loads((folder / f.METADATA_NAME).read_text())\n",
        "metas = sorted(root.glob('*/world.json'))\n",
        "meta = src.read(f'{folder}/world.json')\n",
    ]
    for k, text in enumerate(hand_rolled):
        assert world_json_named({f"sim/m{k}.py": text}), text
    clean = '"""Reads world.json through the reader."""\nraise ParameterError("x is not a world folder (no world.json)")\n'
    assert world_json_named({"sim/ok.py": clean}) == []
    assert world_json_named({"world.py": hand_rolled[0]}) == []


# -- the ROS/Gazebo contract --------------------------------------------------------------------------

CONTRACT = PACKAGE / "export" / "contract.py"


def contract_spellings() -> dict[str, str]:
    """Each string the contract owns -> what it is: every Gazebo release's name, every topic's ROS name and
    its Gazebo topic (read from the module itself, so a row added there is held here too)."""
    from worldgen.export import contract

    out = {name: "a Gazebo release" for name in contract.GZ_RELEASES}
    out.update({t.gz_topic: "a Gazebo topic" for t in contract.TOPICS if t.gz_topic is not None})
    out.update({t.name: "a topic" for t in contract.TOPICS})
    return out


def spelled_outside_the_contract(package: Path, spellings: dict[str, str]) -> list[str]:
    found = []
    for path in sorted(package.rglob("*.py")):
        if path == package / "export" / "contract.py" or "templates" in path.relative_to(package).parts:
            continue
        for node in ast.walk(ast.parse(path.read_text(), str(path))):
            if isinstance(node, ast.Constant) and isinstance(node.value, str) and node.value in spellings:
                found.append(f"{path.relative_to(package.parent)}:{node.lineno} {node.value!r} ({spellings[node.value]})")
    return found


def test_gazebo_releases_and_topics_are_spelled_only_in_the_contract():
    """The robot, the bundle, the bag writer and reader, sim/ and the CLI read releases and topics from
    worldgen/export/contract.py: a literal elsewhere is a second home that a rename would miss (issue 35
    found /ground_truth with two types and two default releases that way)."""
    spellings = contract_spellings()
    assert {"fortress", "harmonic", "/ground_truth", "/cmd_vel"} <= set(spellings)
    found = spelled_outside_the_contract(PACKAGE, spellings)
    assert not found, "spell these through worldgen.export.contract:\n" + "\n".join(found)


def test_the_contract_check_finds_a_planted_spelling_and_not_prose(tmp_path):
    (tmp_path / "export").mkdir()
    (tmp_path / "sim").mkdir()
    (tmp_path / "export" / "contract.py").write_text('RELEASE = "fortress"\n')
    (tmp_path / "sim" / "drive.py").write_text('"""Drives in fortress, reads /ground_truth."""\n'
                                               'robot = robot_sdf(meta, gz_release="fortress")\n'
                                               'topic = f"{ns}/ground_truth"\n')  # a piece of an f-string counts
    assert sorted(spelled_outside_the_contract(tmp_path, contract_spellings())) == \
        [f"{tmp_path.name}/sim/drive.py:2 'fortress' (a Gazebo release)", f"{tmp_path.name}/sim/drive.py:3 '/ground_truth' (a topic)"]


def is_deprecation_shim(tree: ast.Module) -> bool:
    """A module kept only so an old import path works: no function or class of its own, and it warns."""
    warns = any(isinstance(n, ast.Expr) and isinstance(n.value, ast.Call) and "DeprecationWarning" in ast.dump(n.value)
                for n in tree.body)
    return warns and not any(isinstance(n, (ast.FunctionDef, ast.AsyncFunctionDef, ast.ClassDef)) for n in ast.walk(tree))


def ros_room_writers(graph: dict[str, set[str]], paths: dict[str, Path]) -> list[str]:
    """Modules of ros/ that reach for a world folder's files: worldgen.files (names, atomic writes) or an
    exporter other than the contract's tables (the package export/ itself holds nothing)."""
    out = []
    for name in sorted(m for m in graph if room_of(m) == "ros"):
        reached = sorted(t for t in graph[name] if t == "worldgen.files" or
                         (room_of(t) == "export" and t not in ("worldgen.export", "worldgen.export.contract")))
        if reached and not is_deprecation_shim(ast.parse(paths[name].read_text())):
            out.append(f"{name} -> {', '.join(reached)}")
    return out


def test_the_ros_room_keeps_bags_only():
    """ros/ reads and writes bags; what a world folder holds (the ROS 2 bundle among it) is export/'s."""
    found = ros_room_writers(import_graph(), modules())
    assert not found, "ros/ writes no world-folder file; move this to export/:\n" + "\n".join(found)


def test_the_ros_room_check_finds_a_bundle_and_lets_a_shim_be():
    graph = {"worldgen.ros.bundle": {"worldgen.files", "worldgen.export.robot", "worldgen.export.contract"},
             "worldgen.ros.writer": {"worldgen.export.contract"}}
    writer = Path(__file__)  # any module with functions of its own
    assert ros_room_writers(graph, {"worldgen.ros.bundle": writer, "worldgen.ros.writer": writer}) == \
        ["worldgen.ros.bundle -> worldgen.export.robot, worldgen.files"]
    shim = ast.parse('"""Moved."""\nimport warnings\nfrom worldgen.export.ros2 import bundle\n__all__ = ["bundle"]\n'
                     'warnings.warn("moved", DeprecationWarning, stacklevel=2)\n')
    assert is_deprecation_shim(shim)
    assert not is_deprecation_shim(ast.parse("def bundle():\n    warnings.warn('x', DeprecationWarning)\n"))


# -- house rules without blind spots ------------------------------------------------------------------

def exception_classes(sources: dict[str, str]) -> dict[str, tuple[str, bool]]:
    """Every class of ``sources`` (module name -> source text) that is an ``Exception``, wherever it is defined
    (module level, inside a class or a function), mapped to (where, whether it descends from WorldgenError).

    Read from the source, not imported: a module behind an optional extra is read like any other. A base is
    known by its last name (``errors.WorldgenError`` is ``WorldgenError``); a base the package does not define
    is a builtin exception when ``builtins`` has it, or, from a third party, when its name says it is one."""
    import builtins

    builtin = {n: v for n, v in vars(builtins).items() if isinstance(v, type) and issubclass(v, BaseException)}
    bases, where = {}, {}
    for module, text in sources.items():
        for node in ast.walk(ast.parse(text)):
            if isinstance(node, ast.ClassDef):
                names = [b.attr if isinstance(b, ast.Attribute) else b.id if isinstance(b, ast.Name) else ""
                         for b in node.bases]
                key = f"{module}.{node.name}"
                bases[key], where[key] = names, f"{module}:{node.lineno} {node.name}"
    by_name: dict[str, list[str]] = {}
    for key in bases:
        by_name.setdefault(key.rpartition(".")[2], []).append(key)

    def kind(name: str, seen: frozenset = frozenset()) -> set[str]:
        """What a base called ``name`` makes a class: "error" for an Exception, with "root" when WorldgenError is
        among its ancestors; "interrupt" for a BaseException that is no Exception (KeyboardInterrupt)."""
        if name == "WorldgenError":
            return {"root", "error"}
        if name in builtin:
            return {"error"} if issubclass(builtin[name], Exception) else {"interrupt"}
        found: set[str] = set()
        for key in by_name.get(name, ()):
            if key not in seen:
                for base in bases[key]:
                    found |= kind(base, seen | {key})
        if not by_name.get(name) and name.endswith(("Error", "Exception")):
            found.add("error")
        return found

    out = {}
    for key in bases:
        kinds: set[str] = set().union(*[kind(b, frozenset({key})) for b in bases[key]]) if bases[key] else set()
        if key.endswith(".WorldgenError"):
            kinds |= {"root"}
        if "error" in kinds and "interrupt" not in kinds:
            out[key] = (where[key], "root" in kinds)
    return out


def test_the_exception_finder_sees_classes_outside_errors_py():
    found = exception_classes({
        "errors": "class WorldgenError(Exception): pass\nclass BagError(WorldgenError, ValueError): pass",
        "a": "from errors import BagError\nclass Mine(BagError): pass\nclass Stray(ValueError): pass\n"
             "def f():\n    class _Local(RuntimeError): pass\nclass Plain: pass\nclass Stop(KeyboardInterrupt): pass",
        "b": "import pytest\nclass Third(pytest.UsageError): pass\nclass Deep(errors.WorldgenError): pass",
    })
    assert {k: v[1] for k, v in found.items()} == {
        "errors.WorldgenError": True, "errors.BagError": True, "a.Mine": True, "a.Stray": False, "a._Local": False,
        "b.Third": False, "b.Deep": True}


def test_every_exception_class_in_the_package_is_a_worldgen_error():
    """Callers catch WorldgenError, and the command line maps it to one line with its exit status: an exception
    class of the package that is not one escapes both, whichever module defines it (private ones too: an
    internal signal that leaks is still the package's error). A KeyboardInterrupt's subclass (a build stopped
    by Ctrl-C) is an interrupt, not an error, and stays out of ``except Exception``."""
    found = exception_classes({name: path.read_text() for name, path in modules().items()})
    assert "worldgen.errors.WorldgenError" in found and "worldgen.sim.gazebo.GazeboError" in found
    stray = sorted(where for where, rooted in found.values() if not rooted)
    assert not stray, "exception classes that do not descend from WorldgenError (worldgen/errors.py):\n" + \
        "\n".join(stray)


def files_py_names() -> set[str]:
    """The file names worldgen/files.py spells: its module-level strings with a dot (``WORLDS_DIR`` is a word)."""
    return {node.value.value for node in ast.parse((PACKAGE / "files.py").read_text()).body
            if isinstance(node, ast.Assign) and isinstance(node.value, ast.Constant)
            and isinstance(node.value.value, str) and "." in node.value.value}


def file_names_spelled(text: str, names: set[str]) -> list[tuple[int, str]]:
    """Where ``text`` spells one of ``names`` as a string: the whole string, or its last part after a slash (the
    literal piece of ``f"{folder}/world.json"``). A sentence that mentions a name in passing is no spelling."""
    return [(node.lineno, node.value) for node in ast.walk(ast.parse(text))
            if isinstance(node, ast.Constant) and isinstance(node.value, str)
            and (node.value in names or ("/" in node.value and node.value.rpartition("/")[2] in names))]


def test_the_file_name_finder_sees_paths_built_around_a_name():
    text = 'a = "world.sdf"\nb = f"{d}/world.sdf"\nc = "the world.sdf of a folder"\nd = "world.sdfx"'
    assert file_names_spelled(text, {"world.sdf"}) == [(1, "world.sdf"), (2, "/world.sdf")]


def test_every_file_name_the_package_writes_is_spelled_only_in_files_py():
    """files.py names the files of a world folder (the formats' included), of a pack and of a report folder; a
    second spelling anywhere else (a template's name, a temporary file handed to a simulator, a path built
    with an f-string) is one a rename would miss."""
    names = files_py_names()
    assert {"world.json", "world.sdf", "world.mjcf.xml", "world.urdf", "world.usda", "world.usdc",
            "report.json", "report.csv", "report.md"} <= names
    found = [f"{path.relative_to(PACKAGE.parent)}:{line} {value!r}" for name, path in sorted(modules().items())
             if path.name != "files.py" or path.parent != PACKAGE
             for line, value in file_names_spelled(path.read_text(), names)]
    assert not found, "file names spelled outside worldgen/files.py:\n" + "\n".join(found)


def renames(text: str) -> list[tuple[int, str]]:
    """Where ``text`` moves a file or folder into place by hand: ``os.rename``/``os.replace``/``os.renames``,
    ``shutil.move``, or a path's ``.rename(target)``/``.replace(target)`` (one argument, unlike ``str.replace``)."""
    out = []
    for node in ast.walk(ast.parse(text)):
        if not (isinstance(node, ast.Call) and isinstance(node.func, ast.Attribute)):
            continue
        owner = node.func.value.id if isinstance(node.func.value, ast.Name) else None
        call = f"{owner}.{node.func.attr}" if owner else f".{node.func.attr}"
        if call in {"os.rename", "os.replace", "os.renames", "shutil.move"} or \
                (node.func.attr in {"rename", "replace"} and len(node.args) == 1 and not node.keywords):
            out.append((node.lineno, call))
    return out


def test_the_rename_finder_sees_paths_renamed_and_not_strings_replaced():
    text = ("os.replace(a, b)\ntmp.rename(out)\nshutil.move(a, b)\nPath(x).replace(y)\n"
            "s.replace('a', 'b')\ndataclasses.replace(r, checks=())\nos.path.join(a, b)")
    assert renames(text) == [(1, "os.replace"), (2, "tmp.rename"), (3, "shutil.move"), (4, ".replace")]


def test_files_and_folders_are_moved_into_place_only_in_files_py():
    """A write is atomic when it is written aside, flushed, then renamed: files.py does it (write_atomically,
    write_folder_atomically, atomic_folder, move_into_place), with the fsync and the file modes a rename by
    hand forgets, and the swap an existing folder needs."""
    found = [f"{path.relative_to(PACKAGE.parent)}:{line} {call}" for name, path in sorted(modules().items())
             if path != PACKAGE / "files.py" for line, call in renames(path.read_text())]
    assert not found, "renames outside worldgen/files.py (use its atomic writers):\n" + "\n".join(found)


#: Lines under MAX_LINES a module keeps free: a module standing at the cap is one change from having its text
#: squeezed to fit (docstrings re-wrapped long, blank lines dropped) instead of being split where its
#: concerns part.
HEADROOM = 20


def test_modules_keep_headroom_under_the_line_cap():
    """A module that grows toward the cap is split by concern (server apart from install, a structure's
    building apart from its queries) while there is still room to do it, not squeezed under it."""
    found = [f"{path.relative_to(PACKAGE.parent)} has {n} lines" for name, path in sorted(modules().items())
             if (n := len(path.read_text().splitlines())) > MAX_LINES - HEADROOM]
    assert not found, f"modules within {HEADROOM} lines of the {MAX_LINES}-line cap (split them by concern):\n" + \
        "\n".join(found)


#: The most lines a function may have; unlike MAX_FUNCTION_LINES, no ``# long:`` comment waives it.
FUNCTION_CEILING = 90
#: Functions over the ceiling that another piece of work of issue 35 is rewriting, each with that work. An
#: entry that no longer names a function over the ceiling fails the test below: remove it then.
OVER_CEILING_PENDING: dict[tuple[str, str], str] = {}


def function_lengths(text: str) -> list[tuple[str, int, int, str]]:
    """(name, first line, length, the line above its ``def`` or first decorator) of every function in ``text``."""
    lines = text.splitlines()
    out = []
    for node in ast.walk(ast.parse(text)):
        if isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef)):
            first = min([node.lineno] + [d.lineno for d in node.decorator_list])
            above = lines[first - 2].strip() if first >= 2 else ""
            out.append((node.name, node.lineno, node.end_lineno - node.lineno + 1, above))
    return out


def test_the_function_measure_counts_decorators_out_and_reads_the_line_above():
    text = "x = 1\n# long: why\n@decorator\ndef f():\n    a = 1\n    return a\n"
    assert function_lengths(text) == [("f", 4, 3, "# long: why")]


def test_no_function_passes_the_ceiling_and_long_says_why_only_where_it_is_needed():
    """A ``# long:`` reason waives the 60-line rule up to FUNCTION_CEILING lines; past that a function is broken
    into named steps whatever its reason. A reason above a function of 60 lines or fewer is one left behind."""
    over, stale, pending = [], [], set()
    for name, path in sorted(modules().items()):
        rel = path.relative_to(PACKAGE).as_posix()
        for function, line, length, above in function_lengths(path.read_text()):
            where = f"worldgen/{rel}:{line} {function} ({length} lines)"
            if length > FUNCTION_CEILING:
                if (rel, function) in OVER_CEILING_PENDING:
                    pending.add((rel, function))
                else:
                    over.append(where)
            elif length <= MAX_FUNCTION_LINES and above.startswith(LONG_REASON):
                stale.append(where)
    assert not over, f"functions over {FUNCTION_CEILING} lines (break them into named steps):\n" + "\n".join(over)
    assert not stale, f"'{LONG_REASON}' above functions of {MAX_FUNCTION_LINES} lines or fewer:\n" + "\n".join(stale)
    done = sorted(set(OVER_CEILING_PENDING) - pending)
    assert not done, f"OVER_CEILING_PENDING names functions no longer over {FUNCTION_CEILING} lines: {done}"


def test_the_type_checker_reads_the_whole_package():
    """``make test`` runs mypy with pyproject's settings: over the whole package, not a list of entry points
    that the rest of the package hides behind. A module left out waits for a move that is under way, and
    its exclusion goes when the module does (an exclusion that matches no module fails here)."""
    import re

    tomllib = pytest.importorskip("tomllib")  # Python 3.11 on; the CI's Python has it
    config = tomllib.loads((PACKAGE.parent / "pyproject.toml").read_text())["tool"]["mypy"]
    assert config["files"] == ["worldgen"], config["files"]
    for pattern in config.get("exclude", []):
        matched = [p for p in PACKAGE.rglob("*.py") if re.search(pattern, p.relative_to(PACKAGE.parent).as_posix())]
        assert len(matched) == 1, f"mypy exclusion {pattern!r} matches {len(matched)} modules, not one: drop it"


def test_every_type_ignore_names_its_error_and_says_why():
    """A ``# type: ignore`` silences one error code, and a comment (after it, or on the line above) says why
    the checker is wrong there; a bare ignore hides whatever else goes wrong on that line later."""
    import re

    ignore = re.compile(r"#\s*type:\s*ignore(\[[a-z0-9_, -]+\])?(.*)$")
    found = []
    for name, path in sorted(modules().items()):
        lines = path.read_text().splitlines()
        for i, line in enumerate(lines):
            m = ignore.search(line)
            if not m:
                continue
            reason = m.group(2).strip().lstrip("#").strip() or (lines[i - 1].strip().startswith("#") and i > 0)
            if not m.group(1) or not reason:
                found.append(f"{path.relative_to(PACKAGE.parent)}:{i + 1} {line.strip()}")
    assert not found, "type: ignore without an error code or a reason:\n" + "\n".join(found)


# -- campaigns --------------------------------------------------------------------------------------------

BUILTIN_RAISES_ALLOWED[("campaign/__init__.py", "AttributeError")] = \
    "a module's __getattr__ protocol (names loaded on first use)"


def test_the_campaign_package_loads_its_modules_on_first_use():
    """``import worldgen.campaign`` imports none of its modules (nor Optuna): a campaign's name is loaded when used."""
    import subprocess
    import sys

    code = ("import sys, worldgen.campaign as c; assert not [m for m in sys.modules if m.startswith('worldgen.campaign.')"
            " or m == 'optuna'], sorted(sys.modules); c.run; assert 'worldgen.campaign.runner' in sys.modules")
    subprocess.run([sys.executable, "-c", code], check=True, cwd=PACKAGE.parent)


# -- Gazebo releases: tools, messages and variables --


def release_spellings() -> tuple[dict[str, str], tuple[str, ...]]:
    """(exact strings -> what they are, message-package prefixes) that a release's row owns: its command-line
    tool, its partition, plugin-path and discovery variables, and its message package (``gz.msgs.``)."""
    from worldgen.export import contract

    exact: dict[str, str] = {}
    for row in contract.GZ_RELEASES.values():
        exact.update({row.cli: "a release's tool", row.partition_var: "a partition variable",
                      row.plugin_path_var: "a plugin-path variable"})
        exact.update({v: "a discovery variable" for v in row.discovery_vars})
    return exact, tuple(sorted({row.msgs + "." for row in contract.GZ_RELEASES.values()}))


def release_spelled_outside_the_contract(package: Path) -> list[str]:
    exact, prefixes = release_spellings()
    found = []
    for path in sorted(package.rglob("*.py")):
        if path == package / "export" / "contract.py" or "templates" in path.relative_to(package).parts:
            continue
        for node in ast.walk(ast.parse(path.read_text(), str(path))):
            if isinstance(node, ast.Constant) and isinstance(node.value, str) and \
                    (node.value in exact or node.value.startswith(prefixes)):
                what = exact.get(node.value, "a message type")
                found.append(f"{path.relative_to(package.parent)}:{node.lineno} {node.value!r} ({what})")
    return found


def test_a_releases_tools_messages_and_variables_are_spelled_only_in_the_contract():
    """The Gazebo harness, the drive bridge and the scan speak the release of the install they run through its
    contract row (``ign``/``gz``, ``IGN_PARTITION``/``GZ_PARTITION``, ``ignition.msgs``/``gz.msgs``): a literal
    elsewhere is code that speaks one release only (issue 39 found the harness speaking Fortress alone)."""
    found = release_spelled_outside_the_contract(PACKAGE)
    assert not found, "read these from the release's row in worldgen.export.contract:\n" + "\n".join(found)


def test_the_release_spelling_check_finds_a_planted_tool_and_message(tmp_path):
    (tmp_path / "export").mkdir()
    (tmp_path / "sim").mkdir()
    (tmp_path / "export" / "contract.py").write_text('CLI = "ign"\n')
    (tmp_path / "sim" / "gazebo.py").write_text('"""Calls ign with ignition.msgs.Empty."""\n'
                                                'run(["ign", "service"], "ignition.msgs.Empty", env["GZ_PARTITION"])\n')
    assert sorted(release_spelled_outside_the_contract(tmp_path)) == sorted([
        f"{tmp_path.name}/sim/gazebo.py:2 'ign' (a release's tool)",
        f"{tmp_path.name}/sim/gazebo.py:2 'ignition.msgs.Empty' (a message type)",
        f"{tmp_path.name}/sim/gazebo.py:2 'GZ_PARTITION' (a partition variable)"])
