"""remove_person and the people of an edited world walked again (worldgen.verify.rewalk): the generator's own
draw, walked through the edited scene, certified anew; the same world whichever way the edits are applied;
``worldgen check`` replays it byte for byte; a world whose people cannot be certified is not made."""

from __future__ import annotations

import json

import pytest

import worldgen
from worldgen import feasibility
from worldgen.errors import ParameterError
from worldgen.presets import generate_preset
from worldgen.verify import check_folder
from worldgen.verify.edits import apply_edit, replay_edits, with_edits
from worldgen.verify.rewalk import people_plan, settle


@pytest.fixture(scope="module")
def crowd():
    """A random crowd that reacts to the robot, among obstacles and scripted movers."""
    return worldgen.generate("cluttered", seed=4, size=[10, 10], n_obstacles=10, n_movers=2, n_people=6,
                             people_behaviour="regular,scared,curious,impassive")


def people(world):
    return [m for m in world.scene.movers if m.person]


@pytest.mark.parametrize("make", [lambda: generate_preset("crowd_reacting", 0), lambda: generate_preset("group_in_corridor", 0),
                                  lambda: generate_preset("person_crossing", 0)],
                         ids=["crowd_reacting", "group_in_corridor", "person_crossing"])
def test_the_plan_drawn_again_walks_the_generated_people_exactly(make):
    # The re-walk is generation's: with nothing removed it gives the very rows, and the same certificate.
    world = make()
    static = feasibility.check(world.scene, world.tasks, world.robot)
    scene, report = settle(world, people_plan(world), world.scene, world.tasks, static)
    assert scene.movers == world.scene.movers and scene.content_hash() == world.scene.content_hash()
    assert [t.rows.tolist() for t in report.timed_paths] == [t.rows.tolist() for t in world.feasibility.timed_paths]


def test_removing_a_person_walks_the_others_again_and_keeps_their_names_and_behaviours(crowd, tmp_path):
    edited = with_edits(crowd, [{"op": "remove_person", "person": "person_2"}])
    assert edited is not None and edited.feasibility.feasible
    assert [m.name for m in people(edited)] == ["person_0", "person_1", "person_3", "person_4", "person_5"]
    # The crowd model walked them without person_2: someone's walk changed (they no longer step round it).
    before = {m.name: m.trajectory for m in people(crowd)}
    assert any(m.trajectory != before[m.name] for m in people(edited))
    # ... and every task is certified among the new walk, not the old one.
    timed = next(c for c in edited.feasibility.checks if c.name == "timed_path")
    assert timed.ok and "among 5 people" in timed.detail
    meta = json.loads((edited.write(tmp_path) / "world.json").read_text())
    original = {p["name"]: p.get("behaviour") for p in crowd.metadata["people"]}
    assert {p["name"]: p.get("behaviour") for p in meta["people"]} == {k: v for k, v in original.items() if k != "person_2"}
    assert meta["params"]["n_people"] == 6 and meta["edits"] == [{"op": "remove_person", "person": "person_2"}]
    outcome = check_folder(edited.path)
    assert outcome.ok, outcome.line()


def test_the_settled_world_does_not_depend_on_the_order_or_the_grouping_of_the_edits(crowd):
    obstacle = next(n.name for n in crowd.scene.nodes if n.role == "obstacle")
    edits = [{"op": "remove_person", "person": "person_1"}, {"op": "remove_mover", "mover": "mover_0"},
             {"op": "remove", "node": obstacle}, {"op": "remove_person", "person": "person_4"}]
    at_once, replayed = with_edits(crowd, edits), replay_edits(crowd, edits)
    assert at_once.content_hash == replayed.content_hash
    assert at_once.feasibility.timed_paths[0].rows.tolist() == replayed.feasibility.timed_paths[0].rows.tolist()
    reordered = with_edits(crowd, edits[::-1])
    assert reordered.scene.content_hash() == at_once.scene.content_hash()
    step = with_edits(with_edits(crowd, edits[:2]), edits[2:])  # an edited world carries the draw on
    assert step.content_hash == at_once.content_hash


def test_removing_everyone_leaves_a_world_without_people(tmp_path):
    world = generate_preset("group_in_corridor", 0)
    edited = with_edits(world, [{"op": "remove_person", "person": f"person_{i}"} for i in range(3)])
    assert people(edited) == [] and "timed_path" not in {c.name for c in edited.feasibility.checks}
    meta = json.loads((edited.write(tmp_path) / "world.json").read_text())
    assert "people" not in meta and all("timed_path" not in t for t in meta["tasks"])
    assert check_folder(edited.path).ok


def test_what_names_no_person_is_no_edit(crowd):
    assert with_edits(crowd, [{"op": "remove_person", "person": "person_9"}]) is None
    assert with_edits(crowd, [{"op": "remove_person", "person": "mover_0"}]) is None  # a scripted mover, not a person
    assert with_edits(crowd, [{"op": "remove_mover", "mover": "person_0"}]) is None  # a person, not a scripted mover


def test_a_world_whose_people_cannot_be_certified_again_is_not_made():
    # In this small crowded room, without person_0 the others end their walk where the robot has no way through.
    world = worldgen.generate("cluttered", seed=5, size=[6, 6], n_obstacles=8, n_people=5, people_duration=30.0,
                              people_behaviour="regular,scared,curious")
    edit = {"op": "remove_person", "person": "person_0"}
    scene, tasks = apply_edit(world.scene, world.tasks, edit)
    static = feasibility.check(scene, tasks, world.robot)
    assert static.feasible  # statically nothing changed: the certificate is what fails
    _, report = settle(world, people_plan(world), scene, tasks, static)
    assert [c.name for c in report.failed()] == ["timed_path"]
    assert with_edits(world, [edit]) is None
    with pytest.raises(ParameterError, match="among its people re-walked"):
        replay_edits(world, [edit])


def test_people_that_are_not_the_generators_draw_are_refused(crowd):
    moved = [m if not m.person else type(m)(m.name, m.radius, m.height, [(0.0, 0.0, 0.0), (1.0, 0.5, 0.0)], False,
                                              m.friction, person=True) for m in crowd.scene.movers]
    forged = worldgen.World(crowd.generator, crowd.seed, crowd.params, crowd.scene.with_movers(moved), crowd.tasks,
                            crowd.robot, crowd.feasibility, crowd.attempts)
    with pytest.raises(ParameterError, match="not the draw of its generator"):
        with_edits(forged, [{"op": "remove_person", "person": "person_0"}])
