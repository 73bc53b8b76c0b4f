"""The judging moved from worldgen.testing to worldgen.judge: the old names still import, as the very module
of the new place, and warn with the new name."""
import importlib
import sys

import pytest

import worldgen.testing
from worldgen.testing import MOVED

OLD = sorted(MOVED)


def _forget(monkeypatch, old):
    """As if the old name had never been imported in this process (the finder answers only a first import)."""
    monkeypatch.delitem(sys.modules, old, raising=False)
    monkeypatch.delattr(worldgen.testing, old.rpartition(".")[2], raising=False)


@pytest.mark.parametrize("old", OLD)
def test_an_old_name_imports_the_new_module_and_warns(monkeypatch, old):
    _forget(monkeypatch, old)
    new = importlib.import_module(MOVED[old])
    with pytest.warns(DeprecationWarning, match=f"{old} has moved to {MOVED[old]}") as caught:
        module = importlib.import_module(old)
    assert module is new
    assert sys.modules[old] is new
    assert new.__name__ == new.__spec__.name == MOVED[old]  # the real module keeps its own identity
    assert len(caught) == 1


def test_each_spelling_of_an_old_import_warns_at_the_importing_line(monkeypatch):
    from worldgen.judge import evaluate as new_evaluate
    from worldgen.judge.figures import Contact as NewContact
    from worldgen.judge.stats import success_bound as new_success_bound

    for old in ("worldgen.testing.figures", "worldgen.testing.evaluate", "worldgen.testing.stats"):
        _forget(monkeypatch, old)
    with pytest.warns(DeprecationWarning) as caught:
        import worldgen.testing.stats
        from worldgen.testing import evaluate
        from worldgen.testing.figures import Contact
    assert Contact is NewContact and evaluate is new_evaluate
    assert worldgen.testing.stats.success_bound is new_success_bound
    assert [w.filename for w in caught] == [__file__] * 3
    assert [str(w.message).split()[0] for w in caught] == \
        ["worldgen.testing.stats", "worldgen.testing.evaluate", "worldgen.testing.figures"]


def test_the_finder_answers_only_the_moved_names():
    with pytest.raises(ModuleNotFoundError):
        importlib.import_module("worldgen.testing.no_such_module")


def test_the_new_names_import_without_warning(recwarn):
    for new in MOVED.values():
        importlib.import_module(new)
    assert not [w for w in recwarn if issubclass(w.category, DeprecationWarning) and "has moved" in str(w.message)]
