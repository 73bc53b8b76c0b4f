"""The reference consumer of world.osc: scenario_execution's own OpenSCENARIO 2 parser and resolver.

PyPI's scenario-execution (the ``osc`` extra) brings the parser and the core libraries (osc.types,
osc.standard, osc.robotics, osc.helpers). The libraries a nav2 + Gazebo scenario imports, osc.ros,
osc.gazebo and osc.nav2, ship only inside ROS packages: their declaration files are kept, unchanged, in
tests/export/data/osc/ (README.md there says whence). :func:`osc_libraries` registers them the way those
packages do, as entry points of the ``scenario_execution.osc_libraries`` group, from a distribution made
in a temporary folder put on ``sys.path``.

osc.ros declares two external methods (struct ``msg_conversion``: ``scenario_execution_ros.external_methods
.msg_conversion``; struct ``ament``: ``ament_index_python.packages.get_package_share_directory``) that the
resolver imports to check their parameter names. Neither is installable without ROS, so the same
distribution carries stand-ins with those names and parameters, which raise if a scenario ever called
them (resolving calls nothing; world.osc uses neither).
"""

from __future__ import annotations

import shutil
import sys
from contextlib import contextmanager
from pathlib import Path

from support import missing_tool

__all__ = ["DATA", "LIBRARY_FILES", "osc_libraries", "resolve", "declarations"]

DATA = Path(__file__).resolve().parents[1] / "export" / "data" / "osc"
#: library name -> its declaration file in DATA
LIBRARY_FILES = {"ros": "ros.osc", "gazebo": "gazebo.osc", "nav2": "nav2.osc"}
_PACKAGE = "worldgen_osc_test_libraries"

_STANDINS = {
    "scenario_execution_ros/__init__.py": "",
    "scenario_execution_ros/external_methods/__init__.py": "",
    "scenario_execution_ros/external_methods/msg_conversion.py": (
        "def get_object_member(in_value, member_name=''):\n    raise RuntimeError('a test stand-in: needs ROS')\n\n\n"
        "def to_pose_3d(in_value):\n    raise RuntimeError('a test stand-in: needs ROS')\n"),
    "ament_index_python/__init__.py": "",
    "ament_index_python/packages.py": (
        "def get_package_share_directory(package_name):\n    raise RuntimeError('a test stand-in: needs ROS')\n"),
}


def _distribution(root: Path) -> None:
    package = root / _PACKAGE
    (package / "lib_osc").mkdir(parents=True)
    getters = []
    for name, file in LIBRARY_FILES.items():
        shutil.copyfile(DATA / file, package / "lib_osc" / file)
        getters.append(f"def get_{name}():\n    return {_PACKAGE!r}, {file!r}\n")
    (package / "__init__.py").write_text("\n\n".join(getters))
    info = root / f"{_PACKAGE}-0.0.dist-info"
    info.mkdir()
    (info / "METADATA").write_text(f"Metadata-Version: 2.1\nName: {_PACKAGE}\nVersion: 0.0\n")
    (info / "entry_points.txt").write_text("[scenario_execution.osc_libraries]\n" + "".join(
        f"{name} = {_PACKAGE}:get_{name}\n" for name in LIBRARY_FILES))
    for rel, text in _STANDINS.items():
        (root / rel).parent.mkdir(parents=True, exist_ok=True)
        (root / rel).write_text(text)


@contextmanager
def osc_libraries(root: Path):
    """osc.ros, osc.gazebo and osc.nav2 registered while the block runs (skip or fail without the extra)."""
    try:
        import scenario_execution  # noqa: F401
    except ImportError:
        missing_tool("scenario-execution (pip install 'worldgen[osc]')")
    _distribution(Path(root))
    sys.path.insert(0, str(root))
    try:
        yield
    finally:
        sys.path.remove(str(root))
        for name in [m for m in sys.modules if m.split(".")[0] in (_PACKAGE, "scenario_execution_ros",
                                                                   "ament_index_python")]:
            del sys.modules[name]


#: The parse trees of the library files (the same files for every scenario), by absolute path.
_LIBRARY_TREES: dict[str, object] = {}


def resolve(path: Path):
    """scenario_execution's model of the .osc at ``path``, parsed and resolved (its own exceptions on a fault):
    what ``scenario_execution --dry-run`` does before it builds the behaviour tree, whose actions need ROS.

    Parsing the imported libraries is most of the time (0.4-0.8 s a file); their parse trees, which the
    model builder only walks, are kept across calls. The scenario itself is parsed afresh each time."""
    import os

    import py_trees
    from scenario_execution.model.model_resolver import resolve_internal_model
    from scenario_execution.model.osc2_parser import OpenScenario2Parser
    from scenario_execution.utils.logging import Logger

    logger = Logger("worldgen-test", False)
    parser = OpenScenario2Parser(logger)
    parse, entry = parser.parse_file, os.path.abspath(path)

    def parse_once(file, log_model=False, error_prefix=""):
        where = os.path.abspath(file)
        if where == entry or where in parser.parsed_files:
            return parse(file, log_model, error_prefix)  # the parser's own bookkeeping: None when seen
        if where not in _LIBRARY_TREES:
            _LIBRARY_TREES[where] = parse(file, log_model, error_prefix)
        else:
            parser.parsed_files.append(where)
        return _LIBRARY_TREES[where]

    parser.parse_file = parse_once  # type: ignore[method-assign]
    tree = parser.parse_file(str(path))
    model = parser.load_internal_model(tree, str(path))
    resolve_internal_model(model, py_trees.composites.Sequence(name="", memory=True), logger, False)
    return model


def _type_name(t) -> str:
    """A parameter type as the declaration files spell it (``length``, ``list of key_value``)."""
    def name(d):
        if isinstance(d, str):  # a list of a basic type keeps the words run together: "listofstring"
            return d[len("listof"):] if t.is_list and d.startswith("listof") else d
        return getattr(d, "struct_name", None) or d.name

    return f"list of {name(t.type_def)}" if t.is_list else name(t.type_def)


def declarations(model, kind: str) -> dict:
    """``{qualified name: ((parameter, type, has a default), ...)}`` of every action (``kind="action"``),
    modifier or struct the resolved model holds, in declaration order."""
    from scenario_execution.model import types

    cls = {"action": types.ActionDeclaration, "modifier": types.ModifierDeclaration,
           "struct": types.StructDeclaration}[kind]
    out = {}
    for decl in model.find_children_of_type(cls):
        name = getattr(decl, "qualified_behavior_name", None) or getattr(decl, "name", None) or decl.struct_name
        out[name] = tuple((p.name, _type_name(p.find_first_child_of_type(types.Type)), p.get_value_child() is not None)
                          for p in decl.find_children_of_type(types.ParameterDeclaration))
    return out
