"""The public entry point: parameters and a seed in, a checked World out.

    params + seed -> generator -> Scene -> feasibility -> World (exporters on demand)

The seed becomes random streams through :mod:`worldgen.seeding` (attempt ``k``
draws from its own stream, so a world never depends on how many attempts a
caller allowed, only on which one succeeded).
"""

from __future__ import annotations

import logging
from collections import Counter
from typing import Any, Optional

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

#: Where a long request says what it is doing, one level below the request's own line (worldgen.cli.progress).
_progress = logging.getLogger("worldgen.progress.attempt")


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

        return generate_at_level(generate, spec.name, seed, difficulty, params, people_on=_people_on)
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
        _progress.info("%s seed %d: attempt %d of max_attempts=%d", name, seed, attempt + 1, budget)
        draft = spec.build(resolved, attempt_rng(seed, attempt))
        plan = None
        if not draft.rejected:
            draft, plan = _with_common_extras(spec, resolved, draft, robot, seed, attempt)
        if draft.rejected:
            failures[draft.rejected] += 1
            details.setdefault(draft.rejected, draft.detail)
            continue
        assert draft.scene is not None, "a draft that is not rejected has a scene"
        if map_extent is None:  # the map's size follows from the floor: refuse before planning on it
            map_extent = occupancy.extent(draft.scene, resolved["map_resolution"])
        scene = draft.scene
        report = feasibility.check(scene, draft.tasks, robot)  # static: people are movers, which it never reads
        if plan is not None and (report.feasible or allow_infeasible or resolved.get("infeasible")):
            # The people walk (the costly part) only on a draw that can still be kept: one that failed a static
            # check is refused here as it would be after the walk (docs/people.md, "Refusal").
            _progress.info("%s seed %d: attempt %d of max_attempts=%d: walking %d people", name, seed, attempt + 1,
                           budget, resolved["n_people"])
            scene, report = _walk_and_certify(scene, draft.tasks, robot, resolved, plan, report)
        elif plan is not None:
            _count(failures, details, report)
            continue
        world = World(name, seed, resolved, scene, draft.tasks, robot, report, attempt + 1, allow_infeasible)
        if report.feasible or (resolved.get("infeasible") and _infeasible_on_purpose(report)):
            return world
        _count(failures, details, report)
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


def _people_on(world: World, params: dict) -> Optional[World]:
    """What ``generate(world.generator, world.seed, **params)`` gives when ``params`` are ``world``'s with people
    added and the people pass on the attempt ``world`` passed on without them; None when they do not (the seed
    then passes at a later attempt or at none). Every earlier attempt failed its static checks, which never read
    the people, so it fails with them too: the world is the one ``generate`` returns. For a level request
    (worldgen.leveling), which judges draws without people and walks them only on a draw that landed."""
    spec = get(world.generator)
    resolved = spec.resolve(params)
    robot = robot_from_params(resolved)
    from worldgen.people.prechecks import refuse_unplayable
    refuse_unplayable(spec, resolved, robot)  # a script no draw can play ends the request here, in one line
    attempt = world.attempts - 1
    draft = spec.build(resolved, attempt_rng(world.seed, attempt))
    draft, plan = _with_common_extras(spec, resolved, draft, robot, world.seed, attempt) if not draft.rejected \
        else (draft, None)
    if draft.rejected or plan is None or draft.scene is None:
        return None
    scene, report = draft.scene, world.feasibility
    if scene.content_hash() != world.scene.content_hash():  # never expected: then prove it afresh
        report = feasibility.check(scene, draft.tasks, robot)
    _progress.info("%s seed %d: attempt %d: walking %d people", world.generator, world.seed, attempt + 1,
                   resolved["n_people"])
    scene, report = _walk_and_certify(scene, draft.tasks, robot, resolved, plan, report)
    if not report.feasible:
        return None
    return World(world.generator, world.seed, resolved, scene, draft.tasks, robot, report, attempt + 1, False)


def _walk_and_certify(scene, tasks, robot, resolved: dict, plan, report):
    """(scene with its people walked, ``report`` with the timed certificate among them and their tubes): the one
    place a draft gets its people, for a plain request and for a level request's landed draw alike."""
    from worldgen.people.behaviours import behaviours_of
    from worldgen.people.crowd import walk_plan
    from worldgen.people.timed import certify

    scene = scene.with_movers(scene.movers + walk_plan(scene, tasks, robot, resolved, plan))
    return scene, certify(report, scene, tasks, robot, resolved["robot_speed"], behaviours_of(resolved))


def _count(failures: Counter, details: dict, report) -> None:
    """Counts the checks ``report`` failed, keeping the first detail of each."""
    for failed in report.failed():
        failures[failed.name] += 1
        details.setdefault(failed.name, failed.detail)


def _with_common_extras(spec, resolved, draft: Draft, robot, seed: int, attempt: int):
    """(draft, people's plan or None): the draft with what every generator offers through common parameters.

    ``infeasible``: every goal walled in (worldgen.generators.infeasible), unless the generator
    declares its own ``infeasible`` parameter; ``n_movers``: movers on their own
    RNG stream (worldgen.generators.movers), laid out after any goal walls so they avoid them;
    ``n_people``: people on theirs, drawn after the movers (worldgen.people.places; docs/people.md)
    and walked by the crowd model by the caller once the draft passed its static checks.
    """
    scene = draft.scene
    assert scene is not None, "a draft that is not rejected has a scene"
    if resolved.get("infeasible") and "infeasible" not in {p.name for p in spec.params}:
        scene, reason = wall_in_goals(scene, draft.tasks, robot, resolved["friction"])
        if reason:
            return Draft(scene, draft.tasks, rejected="infeasible_placement", detail=reason), None
    if resolved.get("n_movers"):
        movers, reason = place_movers(scene, draft.tasks, robot, resolved, mover_rng(seed, attempt))
        if reason:
            return Draft(scene, draft.tasks, rejected="mover_placement", detail=reason), None
        scene = scene.with_movers(movers)
    plan = None
    if resolved.get("n_people"):
        from worldgen.people.places import draw_people
        plan, reason = draw_people(scene, draft.tasks, robot, resolved, people_rng(seed, attempt))
        if plan is None:
            return Draft(scene, draft.tasks, rejected="people_placement", detail=reason or ""), None
    return (draft if scene is draft.scene else Draft(scene, draft.tasks)), plan


def _infeasible_on_purpose(report) -> bool:
    """A world asked to be infeasible: its start and goal are fine, and the route is what fails."""
    failed = {c.name for c in report.failed()}
    return bool(failed) and failed <= {"path_exists", "path_clearance", "timed_path"}
