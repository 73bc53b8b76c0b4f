"""The public entry point: parameters and a seed in, a checked World out.

    params + seed -> generator -> Scene -> feasibility -> World (exporters on demand)

A request is drawn by :mod:`worldgen.pipeline` (attempt ``k`` draws from its own streams, so a world
never depends on how many attempts a caller allowed, only on which one succeeded); a request for a
difficulty level by :mod:`worldgen.leveling`, which calls the same pipeline for each of its draws.
"""

from __future__ import annotations

from typing import Any

from worldgen.errors import ParameterError
from worldgen.generators import get
from worldgen.pipeline import first_feasible, prepare
from worldgen.seeding import check_seed
from worldgen.world import World

__all__ = ["generate"]


def generate(name: str, seed: int = 0, *, allow_infeasible: bool = False, difficulty: Any = None,
             **params: Any) -> World:
    """Generate, check and return one world; no disk I/O.

    Raises :class:`~worldgen.errors.ParameterError` for bad parameters and
    :class:`~worldgen.errors.InfeasibleError` when ``max_attempts`` draws all
    failed a check. With ``allow_infeasible`` the last failed draw that has a
    scene is returned instead, its ``feasibility`` saying why (for negative tests).
    ``difficulty`` (``"7/10"``) asks for a world at that ``metrics.difficulty_level``
    (:mod:`worldgen.leveling`: the generators whose spec declares a knob).
    """
    spec = get(name)
    seed = check_seed(seed)
    if difficulty is not None:
        if allow_infeasible:
            raise ParameterError("parameter 'difficulty' asks for a drivable world; it excludes allow_infeasible")
        # Imported here, on the first level request: its scoring pulls in the ground truth, which a plain
        # request does not need before its world is written.
        from worldgen.leveling import generate_at_level

        return generate_at_level(spec, seed, difficulty, params)
    return first_feasible(prepare(spec, seed, params, allow_infeasible=allow_infeasible))
