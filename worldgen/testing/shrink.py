"""Shrink a failing world: drop people, movers and obstacles while the user's test still fails.

Usage, with the planner under test in ``my_planner_reaches_goal``::

    result = worldgen.shrink(world, lambda w: not my_planner_reaches_goal(w), "shrunk/")
    result.world.path, result.removed, result.counts     # the smallest failing world, written

The search is a greedy delta debugging, one kind of thing at a time: people first, then scripted movers,
then obstacles (every root obstacle that holds nothing). Of each kind it tries to drop everything left,
then halves, then quarters, and so on down to single ones, keeping every removal after which
``still_fails(world)`` is still True, until no single one can go. People go first because each of them
changes the others' walk and every certificate, and a world without the people a failure does not need
is the cheapest to search further. ``max_calls`` bounds the callback calls.

Every candidate is the original world with edits of :mod:`worldgen.verify.edits` (``remove_person``,
``remove_mover``, then ``remove``, each kind in name order), re-checked by the feasibility checker:
removing obstacles cannot make a task undrivable, but the reference paths, lengths and clearances of a
thinner world are shorter, and world.json must tell the truth about the world that was written. In a
world with people, the people left are walked again from the generator's own draw and every task is
certified among them anew (:mod:`worldgen.verify.rewalk`): the others' walk changes when a person or an
obstacle goes, and the re-walk is what the candidate is. A candidate that is not feasible, or whose
people leave some task no certified way through, is skipped (counted in ``skipped``), never handed to
the callback.

The written world.json records the original's ``generator``, ``seed`` and ``params`` and the removals as
``edits``, so ``worldgen check`` regenerates the original and replays them, re-proving each and walking
and certifying the people again, exactly as for a curriculum's edited level.

From a worker (a campaign's, say), ``world`` may be a world folder's path: the world its world.json
describes is rebuilt (generator, seed, params, then its edits) and proven the one recorded
(:func:`worldgen.verify.folder.load_world`), and :meth:`ShrinkResult.record` is plain data to hand back.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path
from typing import Callable, Union

from worldgen.errors import ParameterError

__all__ = ["ShrinkResult", "shrink", "DEFAULT_MAX_CALLS", "KINDS"]

DEFAULT_MAX_CALLS = 500
#: What shrink removes, in the order it tries, and the edit that removes one of each.
KINDS = ("people", "movers", "obstacles")
_EDIT = {"people": ("remove_person", "person"), "movers": ("remove_mover", "mover"), "obstacles": ("remove", "node")}


@dataclass(frozen=True)
class ShrinkResult:
    """The smallest failing world found (written to ``path``), the names removed (all, and per kind), the
    callback calls made, and the candidates skipped because they could not be proven or certified."""

    world: object
    path: Path
    removed: tuple[str, ...]
    calls: int
    people: tuple[str, ...] = ()
    movers: tuple[str, ...] = ()
    obstacles: tuple[str, ...] = ()
    skipped: int = 0

    @property
    def counts(self) -> dict[str, int]:
        """How many of each kind were removed: ``{"people": n, "movers": n, "obstacles": n}``."""
        return {kind: len(getattr(self, kind)) for kind in KINDS}

    def record(self) -> dict:
        """The result as plain data (JSON as it is): what a worker hands back instead of the World."""
        return {"path": str(self.path), "world_id": getattr(self.world, "world_id", None),
                "removed": {kind: list(getattr(self, kind)) for kind in KINDS}, "counts": self.counts,
                "calls": self.calls, "skipped": self.skipped}


class _Search:
    def __init__(self, world, still_fails, max_calls: int):
        self.world = world
        self.still_fails = still_fails
        self.max_calls = max_calls
        self.calls = 0
        self.skipped = 0
        self.dropped: dict[str, frozenset] = {kind: frozenset() for kind in KINDS}
        self.smallest = world  # the last candidate that still failed

    def build(self, dropped: dict):
        from worldgen.verify.edits import with_edits

        edits = [{"op": _EDIT[kind][0], _EDIT[kind][1]: name} for kind in KINDS for name in sorted(dropped[kind])]
        return with_edits(self.world, edits)

    def fails(self, dropped: dict) -> bool:
        if self.calls >= self.max_calls:
            return False
        candidate = self.build(dropped)
        if candidate is None:  # not feasible, or its people cannot be certified: never the callback's
            self.skipped += 1
            return False
        self.calls += 1
        if not self.still_fails(candidate):
            return False
        self.smallest = candidate
        return True

    def reduce(self, kind: str, items: list) -> None:
        """Greedy chunk removal over ``items`` of ``kind``: all of them, then halves, down to single ones."""
        chunk = len(items)
        while items and self.calls < self.max_calls:
            removed_any = False
            i = 0
            while i < len(items):
                trial = dict(self.dropped, **{kind: self.dropped[kind] | set(items[i:i + chunk])})
                if self.fails(trial):
                    self.dropped = trial
                    items = items[:i] + items[i + chunk:]
                    removed_any = True
                else:
                    i += chunk
            if chunk == 1 and not removed_any:
                break
            chunk = max(chunk // 2, 1)


def shrink(world, still_fails: Callable[[object], bool], out_dir, max_calls: int = DEFAULT_MAX_CALLS) -> ShrinkResult:
    """Remove people, movers and obstacles while ``still_fails(world)`` stays True; write the smallest failing world.

    ``world`` is a :class:`~worldgen.World`, or the path of a world folder (its world.json's world is
    rebuilt); ``still_fails`` gets a World (not written; call ``.write`` or ``.to_mjcf()`` as the test
    needs) and returns True when the failure is still there. It must fail on ``world`` itself. The
    smallest world is written into ``out_dir`` (its folder: ``result.path``).
    """
    world = _world(world)
    if isinstance(max_calls, bool) or not isinstance(max_calls, int) or max_calls < 1:
        raise ParameterError(f"parameter 'max_calls' must be an integer >= 1, got {max_calls!r}")
    if not still_fails(world):
        raise ParameterError("parameter 'still_fails' must return True for the world given (the failure to shrink), got False")
    from worldgen.verify.edits import removable

    search = _Search(world, still_fails, max_calls)
    search.reduce("people", [m.name for m in world.scene.movers if m.person])
    search.reduce("movers", [m.name for m in world.scene.movers if not m.person])
    search.reduce("obstacles", [n.name for n in world.scene.nodes if removable(world.scene, n)])
    path = search.smallest.write(Path(out_dir))
    dropped = {kind: tuple(sorted(search.dropped[kind])) for kind in KINDS}
    return ShrinkResult(search.smallest, path, tuple(sorted(name for names in dropped.values() for name in names)),
                        search.calls + 1, skipped=search.skipped, **dropped)


def _world(world: Union[object, str, Path]):
    """The World to shrink: ``world`` itself, or the one a world folder's world.json describes."""
    if isinstance(world, (str, Path)):
        from worldgen.verify.folder import load_world

        return load_world(world)
    if not hasattr(world, "scene"):
        raise ParameterError(f"parameter 'world' must be a worldgen World or a world folder's path, got {type(world).__name__}")
    return world
