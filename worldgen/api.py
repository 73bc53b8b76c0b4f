"""The public entry point: parameters and a seed in, a checked World out.

    params + seed -> generator -> Scene -> feasibility -> World (exporters on demand)

The seed becomes random streams through :mod:`worldgen.seeding` (attempt ``k``
draws from its own stream, so a world never depends on how many attempts a
caller allowed, only on which one succeeded).
"""

from __future__ import annotations

from collections import Counter
from typing import Any

from worldgen import feasibility
from worldgen.errors import InfeasibleError, ParameterError
from worldgen.generators import Draft, get, robot_from_params
from worldgen.generators.infeasible import wall_in_goals
from worldgen.generators.movers import place_movers
from worldgen.groundtruth import occupancy
from worldgen.params import validate_params
from worldgen.seeding import attempt_rng, check_seed, mover_rng, people_rng
from worldgen.world import World

__all__ = ["generate"]


# long: the pipeline's stages in the order they run (validate, draw, movers, people, prove, record); one reads it top to bottom
def generate(name: str, seed: int = 0, *, allow_infeasible: bool = False, difficulty: Any = None,
             **params: Any) -> World:
    """Generate, check and return one world; no disk I/O.

    Raises :class:`~worldgen.errors.ParameterError` for bad parameters and
    :class:`~worldgen.errors.InfeasibleError` when ``max_attempts`` draws all
    failed a check. With ``allow_infeasible`` the last failed draw that has a
    scene is returned instead, its ``feasibility`` saying why (for negative tests).
    ``difficulty`` (``"7/10"``) asks for a world at that ``metrics.difficulty_level``
    (:mod:`worldgen.leveling`: the cluttered generator).
    """
    spec = get(name)
    seed = check_seed(seed)
    if difficulty is not None:
        if allow_infeasible:
            raise ParameterError("parameter 'difficulty' asks for a drivable world; it excludes allow_infeasible")
        from worldgen.leveling import generate_at_level

        return generate_at_level(generate, spec.name, seed, difficulty, params)
    try:
        resolved = spec.resolve(params)
    except InfeasibleError:
        # The generator knows the request can never be driven (e.g. a corridor narrower
        # than the footprint). A negative test that asked for that still gets the world;
        # its feasibility report then says which checks failed.
        if not allow_infeasible:
            raise
        resolved = validate_params(spec.all_params, params)
    robot = robot_from_params(resolved)
    if resolved.get("n_people") and not allow_infeasible:  # a script no draw can play: refused before drawing
        from worldgen.people.prechecks import refuse_unplayable
        refuse_unplayable(spec, resolved, robot)
    failures: Counter[str] = Counter()
    details: dict[str, str] = {}
    last = None
    budget = resolved["max_attempts"]
    map_extent = None
    for attempt in range(budget):
        draft = spec.build(resolved, attempt_rng(seed, attempt))
        if not draft.rejected:
            draft = _with_common_extras(spec, resolved, draft, robot, seed, attempt)
        if draft.rejected:
            failures[draft.rejected] += 1
            details.setdefault(draft.rejected, draft.detail)
            continue
        assert draft.scene is not None, "a draft that is not rejected has a scene"
        if map_extent is None:  # the map's size follows from the floor: refuse before planning on it
            map_extent = occupancy.extent(draft.scene, resolved["map_resolution"])
        report = feasibility.check(draft.scene, draft.tasks, robot)
        if resolved.get("n_people"):
            from worldgen.people.behaviours import behaviours_of
            from worldgen.people.timed import certify
            report = certify(report, draft.scene, draft.tasks, robot, resolved["robot_speed"], behaviours_of(resolved))
        world = World(name, seed, resolved, draft.scene, draft.tasks, robot, report, attempt + 1, allow_infeasible)
        if report.feasible or (resolved.get("infeasible") and _infeasible_on_purpose(report)):
            return world
        for failed in report.failed():
            failures[failed.name] += 1
            details.setdefault(failed.name, failed.detail)
        last = world
    if allow_infeasible and last is not None:
        return last
    summary = ", ".join(f"{check} failed {count}x" for check, count in sorted(failures.items()))
    # The detail of the first check that failed, in the order the checks run (a path that does not
    # exist also has no clearance: the hint names path_exists, not the alphabetically first).
    first = next(iter(details), None)
    hint = f" (first {first}: {details[first]})" if first and details.get(first) else ""
    raise InfeasibleError(
        f"no feasible '{name}' world for seed {seed} within max_attempts={budget}: {summary}{hint}",
        dict(failures),
    )


def _with_common_extras(spec, resolved, draft: Draft, robot, seed: int, attempt: int) -> Draft:
    """The draft with what every generator offers through common parameters (see the modules).

    ``infeasible``: every goal walled in (worldgen.generators.infeasible), unless the generator
    declares its own ``infeasible`` parameter; ``n_movers``: movers on their own
    RNG stream (worldgen.generators.movers), laid out after any goal walls so they avoid them;
    ``n_people``: people on theirs, walked by the crowd model (worldgen.people.crowd), after
    the movers (docs/people.md).
    """
    scene = draft.scene
    assert scene is not None, "a draft that is not rejected has a scene"
    if resolved.get("infeasible") and "infeasible" not in {p.name for p in spec.params}:
        scene, reason = wall_in_goals(scene, draft.tasks, robot, resolved["friction"])
        if reason:
            return Draft(scene, draft.tasks, rejected="infeasible_placement", detail=reason)
    if resolved.get("n_movers"):
        movers, reason = place_movers(scene, draft.tasks, robot, resolved, mover_rng(seed, attempt))
        if reason:
            return Draft(scene, draft.tasks, rejected="mover_placement", detail=reason)
        scene = scene.with_movers(movers)
    if resolved.get("n_people"):
        from worldgen.people.crowd import walk_people
        people, reason = walk_people(scene, draft.tasks, robot, resolved, people_rng(seed, attempt))
        if reason:
            return Draft(scene, draft.tasks, rejected="people_placement", detail=reason)
        scene = scene.with_movers(scene.movers + people)
    return draft if scene is draft.scene else Draft(scene, draft.tasks)


def _infeasible_on_purpose(report) -> bool:
    """A world asked to be infeasible: its start and goal are fine, and the route is what fails."""
    failed = {c.name for c in report.failed()}
    return bool(failed) and failed <= {"path_exists", "path_clearance", "timed_path"}
