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
    {"groundtruth"}, {"people"}, {"export"}, {"ros"}, {"world"}, {"leveling"}, {"api"}, {"presets"},
    {"verify"}, {"testing"}, {"pack"}, {"judge"}, {"envs"}, {"sim"}, {"campaign"}, {"cli"}, {"__main__"},
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
    ("ros/bundle.py", "AssertionError"): "an invariant of the shipped templates, not of anything a user gives",
    ("pack/archive.py", "FileNotFoundError"): "the archive's file reader answers as open() does",
    ("feasibility/report.py", "KeyError"): "the report's mapping protocol (report['check_name'])",
    ("pack/pack.py", "KeyError"): "the pack's mapping protocol (pack['world_id'])",
    ("__init__.py", "AttributeError"): "a module's __getattr__ protocol (names loaded on first use)",
    ("envs/__init__.py", "AttributeError"): "a module's __getattr__ protocol (names loaded on first use)",
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
