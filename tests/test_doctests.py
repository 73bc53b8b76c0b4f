"""The examples in the package's docstrings run, and say what they show (doctest, in a temporary folder)."""

from __future__ import annotations

import doctest
import importlib
import pkgutil

import pytest

import worldgen


def _modules() -> list[str]:
    return ["worldgen"] + sorted(m.name for m in pkgutil.walk_packages(worldgen.__path__, "worldgen.")
                                 if ".templates" not in m.name)


def _with_examples() -> list[str]:
    out = []
    for name in _modules():
        source = importlib.util.find_spec(name).origin
        if source and ">>>" in open(source, encoding="utf-8").read():
            out.append(name)
    return out


@pytest.mark.parametrize("name", _with_examples())
def test_docstring_examples_run(name, tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)  # examples that write ("worlds/") write here
    module = importlib.import_module(name)
    result = doctest.testmod(module, optionflags=doctest.ELLIPSIS | doctest.NORMALIZE_WHITESPACE, verbose=False)
    assert result.failed == 0, f"{result.failed} of {result.attempted} examples in {name} failed (see above)"
    assert result.attempted > 0


def test_the_examples_cover_the_public_entry_points():
    assert {"worldgen", "worldgen.seeding", "worldgen.testing.oracles", "worldgen.judge.stats",
            "worldgen.envs"} <= set(_with_examples())
