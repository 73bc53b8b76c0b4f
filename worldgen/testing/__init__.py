"""Testing robots against worlds, the test author's face: oracles over recorded runs
(:mod:`~worldgen.testing.oracles`, over the judge's figures and evaluation), shrink a failing world, and
the pytest plugin (fixtures, the ``worldgen`` marker, pack parametrisation).

The judging itself lives in :mod:`worldgen.judge`. Its modules' old names here
(``worldgen.testing.criteria``, ``.evaluate``, ``.figures``, ``.proxemics``, ``.social``, ``.stats``) still
import, as the very module of the new place, with a DeprecationWarning that names it (:data:`MOVED`).
"""

import sys
from importlib.abc import Loader, MetaPathFinder
from importlib.machinery import ModuleSpec

__all__ = ["oracles", "shrink", "plugin", "MOVED"]

#: Old module name -> where it lives now.
MOVED = {f"{__name__}.{name}": f"worldgen.judge.{name}"
         for name in ("criteria", "evaluate", "figures", "proxemics", "social", "stats")}


class _Moved(MetaPathFinder, Loader):
    """Imports an old name of :data:`MOVED` as the module at its new place.

    A finder rather than small modules left at the old paths: a file there would keep git from seeing the
    move as a rename, and changes made to the old file on another branch would then not merge into the
    new one. And the importer gets the one module object, so patching either name patches both.
    """

    def find_spec(self, fullname, path=None, target=None):
        return ModuleSpec(fullname, self) if fullname in MOVED else None

    def create_module(self, spec):
        return None  # a placeholder: exec_module puts the real module in its place

    def exec_module(self, module):
        import importlib
        import warnings

        new = MOVED[module.__name__]
        warnings.warn(f"{module.__name__} has moved to {new}: import it from there", DeprecationWarning,
                      stacklevel=2)  # the import statement: warnings skips the import machinery's frames
        # The import system hands the importer whatever sys.modules holds under the name once this returns.
        sys.modules[module.__name__] = importlib.import_module(new)


if not any(isinstance(finder, _Moved) for finder in sys.meta_path):
    sys.meta_path.append(_Moved())
