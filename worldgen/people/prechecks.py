"""A people scenario that no draw can play, refused before the first draw.

A scripted scenario (``people_scenario`` head_on, crossing, overtaking, group_passing, doorway) puts its
first people at points set against the first task's spawn and goal (:func:`worldgen.people.places.draw_people`).
Where the generator fixes the walls, the spawn and the goal from the parameters alone, as ``corridor``
does (spawn at one end, goal at the other; only obstacles and side openings are drawn), those points are
the same in every draw: a point behind a corridor's end wall is there in all 50 draws. Such a request
is refused at once, with the point and the reason, instead of after ``max_attempts`` draws.
"""

from __future__ import annotations

from typing import Any, Mapping

from worldgen.errors import InfeasibleError
from worldgen.people.behaviours import widest_tube
from worldgen.people.places import SLACK, _scripted, people_footprints
from worldgen.scene import Robot
from worldgen.scene.footprint import FootprintIndex
from worldgen.seeding import attempt_rng

__all__ = ["refuse_unplayable", "FIXED_LAYOUT"]

#: Generators whose walls, spawn and goal follow from the parameters alone (with no side openings drawn).
FIXED_LAYOUT = ("corridor",)


def refuse_unplayable(spec, params: Mapping[str, Any], robot: Robot) -> None:
    """InfeasibleError when ``params``' scripted people cannot stand where the script puts them in any draw."""
    scenario = params.get("people_scenario", "walk")
    if not params.get("n_people") or scenario == "walk" or spec.name not in FIXED_LAYOUT or params.get("side_openings"):
        return
    # The draw's own choices (obstacles) only take floor away: the bare layout is the best any draw does.
    bare = spec.build({**params, "n_obstacles": 0}, attempt_rng(0, 0))
    if bare.rejected or bare.scene is None or not bare.tasks:
        return
    index = FootprintIndex(people_footprints(bare.scene, bare.tasks, robot, widest_tube(params)))
    speed = float(params["person_speed"][0])
    radius = params["person_radius"] + 2 * SLACK
    placed, reason = _scripted(scenario, bare.scene, bare.tasks[0], speed, params, index, radius)
    if placed is None:
        raise InfeasibleError(f"people_scenario '{scenario}' cannot be played in this {spec.name}: {reason} in every "
                              f"draw (its walls, spawn and goal follow from the parameters, and {spec.name} puts the "
                              f"spawn and goal at its ends); widen it, or play the scenario in a room (the person_* "
                              f"presets)", {"people_placement": 0})
