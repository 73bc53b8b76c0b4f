"""A scripted people scenario no draw can play is refused before the first draw; people's parameters
without people are a mistake, not silently dropped."""

from __future__ import annotations

import pytest
from support.cli import run

import worldgen
from worldgen.errors import InfeasibleError, ParameterError
from worldgen.generators import get


def _counting_builds(monkeypatch):
    """The draws generate makes of corridor, by their n_obstacles (the generator spec is frozen: a copy counts)."""
    import dataclasses

    import worldgen.api

    spec = get("corridor")
    calls = []

    def counted(params, rng):
        calls.append(params.get("n_obstacles"))
        return spec.build(params, rng)

    copy = dataclasses.replace(spec, build=counted)
    monkeypatch.setattr(worldgen.api, "get", lambda name: copy if name == "corridor" else get(name))
    return calls


@pytest.mark.parametrize("scenario, where", [("head_on", "place (2.160, 0.513)"), ("overtaking", "start (-1.250, 1.000)")])
def test_a_corridor_script_behind_its_end_wall_is_refused_before_any_draw(monkeypatch, scenario, where):
    calls = _counting_builds(monkeypatch)
    with pytest.raises(InfeasibleError) as err:
        worldgen.generate("corridor", seed=0, n_people=1, people_scenario=scenario)
    message = str(err.value)
    assert "\n" not in message and f"people_scenario '{scenario}' cannot be played in this corridor" in message
    assert f"the {scenario} person's {where} is not free floor in every draw" in message
    assert calls == [0]  # the bare layout once, not max_attempts (50) draws


def test_a_corridor_wide_enough_for_the_script_is_drawn_as_before(monkeypatch):
    world = worldgen.generate("corridor", seed=0, n_people=1, people_scenario="head_on", width=4.0)
    assert world.attempts == 1 and world.metadata["people"]
    # allow_infeasible (negative tests) still draws: the check is for requests that want a world
    calls = _counting_builds(monkeypatch)
    with pytest.raises(InfeasibleError, match="people_placement failed 2x"):
        worldgen.generate("corridor", seed=0, n_people=1, people_scenario="head_on", max_attempts=2,
                          allow_infeasible=True)
    assert calls == [0, 0]  # both draws made, no check before them


@pytest.mark.parametrize("name, value", [("group_size", 3), ("people_scenario", "crossing"), ("person_speed", [0.8, 1.2]),
                                         ("people_duration", 30.0), ("person_radius", 0.3)])
def test_peoples_parameters_without_people_are_one_line_exit_2(name, value):
    with pytest.raises(ParameterError) as err:
        worldgen.generate("cluttered", seed=0, **{name: value})
    assert f"parameter '{name}' sets how people walk, and this world has none: set n_people" in str(err.value)
    with pytest.raises(ParameterError):
        worldgen.generate("cluttered", seed=0, n_people=0, **{name: value})
    text = ",".join(map(str, value)) if isinstance(value, list) else str(value)
    done = run("generate", "cluttered", "--set", f"{name}={text}", "--out", "unused")
    assert done.returncode == 2 and len(done.stderr.splitlines()) == 1 and "set n_people" in done.stderr


def test_the_default_value_of_a_peoples_parameter_is_harmless_without_people():
    plain = worldgen.generate("cluttered", seed=0)
    assert worldgen.generate("cluttered", seed=0, person_radius=0.25, people_scenario="walk").world_id == plain.world_id
