"""One attempt at a world, and attempts until one is kept.

    params + seed -> generator -> Scene -> feasibility -> World

Attempt ``k`` of a request draws from its own streams (:mod:`worldgen.seeding`: the generator's
``attempt_rng(seed, k)``, the movers' and the people's beside it), so a world never depends on how many
attempts a caller allowed, only on which one succeeded; and attempt ``k`` can be made again alone, as a
level request does when it adds people to a draw that landed (worldgen.leveling).
"""

from __future__ import annotations

import logging
from collections import Counter
from dataclasses import dataclass
from typing import Any, Mapping, Optional

from worldgen import feasibility
from worldgen.errors import InfeasibleError
from worldgen.generators import Draft, GeneratorSpec, robot_from_params
from worldgen.generators.infeasible import wall_in_goals
from worldgen.generators.movers import place_movers
from worldgen.groundtruth import occupancy
from worldgen.params import validate_params
from worldgen.scene import Robot
from worldgen.seeding import attempt_rng, mover_rng, people_rng
from worldgen.world import World

__all__ = ["Request", "Attempt", "prepare", "attempt", "first_feasible", "off_path_world"]

#: Where a long request says what it is doing, one level below the request's own line (worldgen.cli.progress).
_progress = logging.getLogger("worldgen.progress.attempt")


@dataclass(frozen=True)
class Request:
    """What every attempt of one request shares: the generator, the seed, the resolved parameters (every
    default filled in), the robot they describe, and whether a world that fails a check may come back."""

    spec: GeneratorSpec
    seed: int
    params: Mapping[str, Any]
    robot: Robot
    allow_infeasible: bool = False


@dataclass(frozen=True)
class Attempt:
    """What attempt ``number`` (0-based) gave.

    ``world`` is None when no world was made: the generator or a common extra refused the draft, or the draft
    failed its static checks with people still to walk (they are walked only on a draft that can be kept).
    ``failed`` names every check the attempt failed with its detail, in the order they ran; ``kept`` is a world
    the request returns (feasible, or infeasible on purpose when it asked for that).
    """

    number: int
    world: Optional[World] = None
    failed: tuple[tuple[str, str], ...] = ()
    kept: bool = False


def prepare(spec: GeneratorSpec, seed: int, params: Mapping[str, Any], *, allow_infeasible: bool = False) -> Request:
    """The request for ``params`` of ``spec`` with ``seed``: the parameters resolved and checked, and a people
    script no draw can play refused before any draw (InfeasibleError, one line)."""
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
    return Request(spec, seed, resolved, robot, allow_infeasible)


def attempt(request: Request, number: int, *, proven: Optional[World] = None) -> Attempt:
    """Attempt ``number`` of ``request``: draw the draft, add the common extras, prove it, and walk and certify
    its people when it has any and can still be kept.

    ``proven``: a world of the same draw whose report stands for this draft's static checks when its scene is
    this draft's (a level request's draw judged without people: the static checks never read the people).
    """
    spec, params, robot, seed = request.spec, request.params, request.robot, request.seed
    draft = spec.build(params, attempt_rng(seed, number))
    plan = None
    if not draft.rejected:
        draft, plan = _with_common_extras(request, draft, number)
    if draft.rejected:
        return Attempt(number, failed=((draft.rejected, draft.detail),))
    assert draft.scene is not None, "a draft that is not rejected has a scene"
    scene = draft.scene
    occupancy.extent(scene, params["map_resolution"])  # the map's size follows from the floor: refuse before planning
    if proven is not None and proven.scene.content_hash() == scene.content_hash():
        report = _static(proven.feasibility)
    else:
        report = feasibility.check(scene, draft.tasks, robot)  # static: people are movers, which it never reads
    if plan is not None or scene.movers:
        if not (report.feasible or request.allow_infeasible or params.get("infeasible")):
            # The people walk and the certificate is sought (the costly part) only on a draw that can still be
            # kept: one that failed a static check is refused here as it would be after (docs/people.md, "Refusal").
            return Attempt(number, failed=_failed(report))
        if plan is not None:
            _progress.info("%s seed %d: attempt %d of max_attempts=%d: walking %d people", spec.name, seed,
                           number + 1, params["max_attempts"], params["n_people"])
        scene, report = _walk_and_certify(request, scene, draft.tasks, plan, report)
    world = World(spec.name, seed, params, scene, draft.tasks, robot, report, number + 1, request.allow_infeasible)
    kept = bool(report.feasible or (params.get("infeasible") and _infeasible_on_purpose(report)))
    return Attempt(number, world, () if kept else _failed(report), kept)


def first_feasible(request: Request) -> World:
    """The first kept world of ``request``'s attempts 0, 1, ... within its ``max_attempts``.

    Raises :class:`~worldgen.errors.InfeasibleError` when every attempt failed a check, naming how often each
    failed; with ``allow_infeasible`` the last failed attempt that made a world is returned instead.
    """
    spec, seed = request.spec, request.seed
    failures: Counter[str] = Counter()
    details: dict[str, str] = {}
    last: Optional[World] = None
    stalled: list[World] = []  # draws that failed only for want of a timed path along the static path
    budget = request.params["max_attempts"]
    for number in range(budget):
        _progress.info("%s seed %d: attempt %d of max_attempts=%d", spec.name, seed, number + 1, budget)
        got = attempt(request, number)
        if got.kept and got.world is not None:
            return got.world
        for check, detail in got.failed:
            failures[check] += 1
            details.setdefault(check, detail)
        if got.world is not None:
            last = got.world
            if {check for check, _ in got.failed} == {"timed_path"}:
                stalled.append(got.world)
    for world in stalled:  # only now, so that every world the sweep along the path makes keeps its draw
        _progress.info("%s seed %d: attempt %d: a timed path off the static path", spec.name, seed, world.attempts)
        found = off_path_world(request, world)
        if found.feasibility.feasible:
            return found
        details["timed_path"] = next(c.detail for c in found.feasibility.failed() if c.name == "timed_path")
    if request.allow_infeasible and last is not None:
        return last
    summary = ", ".join(f"{check} failed {count}x" for check, count in sorted(failures.items()))
    # The detail of the first check that failed, in the order the checks run (a path that does not
    # exist also has no clearance: the hint names path_exists, not the alphabetically first).
    first = next(iter(details), None)
    hint = f" (first {first}: {details[first]})" if first and details.get(first) else ""
    raise InfeasibleError(
        f"no feasible '{spec.name}' world for seed {seed} within max_attempts={budget}: {summary}{hint}",
        dict(failures),
    )


def off_path_world(request: Request, world: World) -> World:
    """``world`` (a draw of ``request`` whose only failed check is ``timed_path``) with a timed path off the
    static path for each task the sweep along it left without one (:mod:`worldgen.people.offpath`): a
    feasible world where every task now has one, else one whose ``timed_path`` check says so."""
    from worldgen.people.behaviours import behaviours_of
    from worldgen.people.offpath import certify_off_path
    from worldgen.people.timed import limits_of

    params = request.params
    behaviours = behaviours_of(params) if params.get("n_people") else None
    report = certify_off_path(world.feasibility, world.scene, world.tasks, request.robot, limits_of(params),
                              behaviours)
    return World(world.generator, world.seed, params, world.scene, world.tasks, request.robot, report,
                 world.attempts, request.allow_infeasible)


def _failed(report) -> tuple[tuple[str, str], ...]:
    """(check, detail) of every check ``report`` failed."""
    return tuple((failed.name, failed.detail) for failed in report.failed())


def _walk_and_certify(request: Request, scene, tasks, plan, report):
    """(scene with its people walked, if it has a ``plan`` for them, and ``report`` with the timed certificate
    among everything that moves: people, their tubes, scripted movers)."""
    from worldgen.people.behaviours import behaviours_of
    from worldgen.people.timed import certify, limits_of

    params, robot = request.params, request.robot
    if plan is not None:
        from worldgen.people.crowd import walk_plan

        scene = scene.with_movers(scene.movers + walk_plan(scene, tasks, robot, params, plan))
    behaviours = behaviours_of(params) if plan is not None else None
    return scene, certify(report, scene, tasks, robot, limits_of(params), behaviours)


def _static(report):
    """``report`` with only its static checks: a proven draw's report (a level request's, made before its people
    were walked) without any certificate it carries, which the attempt makes anew among everything that moves."""
    from dataclasses import replace

    return replace(report, checks=tuple(c for c in report.checks if c.name != "timed_path"), timed_paths=())


def _with_common_extras(request: Request, draft: Draft, number: int):
    """(draft, people's plan or None): the draft with what every generator offers through common parameters.

    ``infeasible``: every goal walled in (worldgen.generators.infeasible), unless the generator
    declares its own ``infeasible`` parameter; ``n_movers``: movers on their own
    RNG stream (worldgen.generators.movers), laid out after any goal walls so they avoid them;
    ``n_people``: people on theirs, drawn after the movers (worldgen.people.places; docs/people.md)
    and walked by the crowd model by :func:`attempt` once the draft passed its static checks.
    """
    spec, params, robot, seed = request.spec, request.params, request.robot, request.seed
    scene = draft.scene
    assert scene is not None, "a draft that is not rejected has a scene"
    if params.get("infeasible") and "infeasible" not in {p.name for p in spec.params}:
        scene, reason = wall_in_goals(scene, draft.tasks, robot, params["friction"])
        if reason:
            return Draft(scene, draft.tasks, rejected="infeasible_placement", detail=reason), None
    if params.get("n_movers"):
        movers, reason = place_movers(scene, draft.tasks, robot, params, mover_rng(seed, number))
        if reason:
            return Draft(scene, draft.tasks, rejected="mover_placement", detail=reason), None
        scene = scene.with_movers(movers)
    plan = None
    if params.get("n_people"):
        from worldgen.people.places import draw_people
        plan, reason = draw_people(scene, draft.tasks, robot, params, people_rng(seed, number))
        if plan is None:
            return Draft(scene, draft.tasks, rejected="people_placement", detail=reason or ""), None
    return (draft if scene is draft.scene else Draft(scene, draft.tasks)), plan


def _infeasible_on_purpose(report) -> bool:
    """A world asked to be infeasible: its start and goal are fine, and the route is what fails."""
    failed = {c.name for c in report.failed()}
    return bool(failed) and failed <= {"path_exists", "path_clearance", "timed_path", "terrain_drivable"}
