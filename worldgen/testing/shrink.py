"""Shrink a failing world: drop obstacles and movers while the user's test still fails.

Usage, with the planner under test in ``my_planner_reaches_goal``::

    result = worldgen.shrink(world, lambda w: not my_planner_reaches_goal(w), "shrunk/")
    result.world.path, result.removed        # the smallest failing world, written

The search is a greedy delta debugging over the world's obstacle nodes: try
to drop half of what is left, then quarters, and so on down to single
obstacles, keeping every removal after which ``still_fails(world)`` is still
True, until no single obstacle can go. Movers are dropped first (all of them,
then one at a time). ``max_calls`` bounds the callback calls.

Every candidate is the original world with edits of :mod:`worldgen.verify.edits`
(``remove_mover``, then ``remove``, in name order), re-checked by the feasibility
checker: removing obstacles cannot make a task undrivable, but the reference
paths, lengths and clearances of a thinner world are shorter, and world.json
must tell the truth about the world that was written. A candidate that somehow
is not feasible is skipped, never handed to the callback.

The written world.json records the original's ``generator``, ``seed`` and
``params`` and the removals as ``edits``, so ``worldgen check`` regenerates
the original and replays them, re-proving each, exactly as for a curriculum's
edited level. Worlds with people are not shrunk: their timed certificate is
made with the walk, which removing a person would leave stale.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path
from typing import Callable

from worldgen.errors import ParameterError

__all__ = ["ShrinkResult", "shrink", "DEFAULT_MAX_CALLS"]

DEFAULT_MAX_CALLS = 500


@dataclass(frozen=True)
class ShrinkResult:
    """The smallest failing world found (written to ``path``), the names removed, and the callback calls made."""

    world: object
    path: Path
    removed: tuple[str, ...]
    calls: int


class _Search:
    def __init__(self, world, still_fails, max_calls: int):
        self.world = world
        self.still_fails = still_fails
        self.max_calls = max_calls
        self.calls = 0

    def build(self, drop_nodes: set, drop_movers: set):
        from worldgen.verify.edits import with_edits

        edits = [{"op": "remove_mover", "mover": m} for m in sorted(drop_movers)] + \
                [{"op": "remove", "node": n} for n in sorted(drop_nodes)]
        return with_edits(self.world, edits)

    def fails(self, drop_nodes: set, drop_movers: set) -> bool:
        if self.calls >= self.max_calls:
            return False
        candidate = self.build(drop_nodes, drop_movers)
        if candidate is None:
            return False
        self.calls += 1
        return bool(self.still_fails(candidate))

    def reduce(self, items: list, dropped: set, other: set, nodes: bool) -> set:
        """Greedy chunk removal over ``items``; returns the grown ``dropped`` set."""
        chunk = max(len(items) // 2, 1)
        while items and self.calls < self.max_calls:
            removed_any = False
            i = 0
            while i < len(items):
                trial = dropped | set(items[i:i + chunk])
                ok = self.fails(trial, other) if nodes else self.fails(other, trial)
                if ok:
                    dropped = trial
                    items = items[:i] + items[i + chunk:]
                    removed_any = True
                else:
                    i += chunk
            if chunk == 1 and not removed_any:
                break
            chunk = max(chunk // 2, 1)
        return dropped


def shrink(world, still_fails: Callable[[object], bool], out_dir, max_calls: int = DEFAULT_MAX_CALLS) -> ShrinkResult:
    """Remove obstacles and movers while ``still_fails(world)`` stays True; write the smallest failing world.

    ``world`` is a :class:`~worldgen.World`; ``still_fails`` gets a World (not
    written; call ``.write`` or ``.to_mjcf()`` as the test needs) and returns
    True when the failure is still there. It must fail on ``world`` itself.
    """
    if not hasattr(world, "scene"):
        raise ParameterError(f"parameter 'world' must be a worldgen World, got {type(world).__name__}")
    if isinstance(max_calls, bool) or not isinstance(max_calls, int) or max_calls < 1:
        raise ParameterError(f"parameter 'max_calls' must be an integer >= 1, got {max_calls!r}")
    if any(m.person for m in world.scene.movers):
        raise ParameterError("shrink takes worlds without people: their timed certificate is made with the walk, "
                             "which removing a person or an obstacle would leave stale")
    if not still_fails(world):
        raise ParameterError("parameter 'still_fails' must return True for the world given (the failure to shrink), got False")
    search = _Search(world, still_fails, max_calls)
    movers = [m.name for m in world.scene.movers]
    drop_movers = search.reduce(movers, set(), set(), nodes=False) if movers else set()
    from worldgen.verify.edits import removable

    obstacles = [n.name for n in world.scene.nodes if removable(world.scene, n)]
    drop_nodes = search.reduce(obstacles, set(), drop_movers, nodes=True)
    smallest = search.build(drop_nodes, drop_movers) if (drop_nodes or drop_movers) else world
    path = smallest.write(Path(out_dir))
    return ShrinkResult(smallest, path, tuple(sorted(drop_nodes | drop_movers)), search.calls + 1)
