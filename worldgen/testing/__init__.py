"""Testing robots against worlds: oracles over recorded runs, evaluate against criteria, shrink a
failing world, and the pytest plugin (fixtures, the ``worldgen`` marker, pack parametrisation)."""

__all__ = ["oracles", "evaluate", "shrink", "plugin"]
