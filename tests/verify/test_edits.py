"""Edits of a proven world (worldgen.verify.edits): a thousand of them, every accepted one re-proved by the
exact checker and re-checked here independently; recorded edits rebuild the same world; an edit that
blocks the goal is refused."""

from __future__ import annotations

import math
from collections import Counter

import numpy as np
import pytest
from support.checks import footprint_distance, recheck

import worldgen
from worldgen.errors import ParameterError
from worldgen.feasibility.report import CHECKER, REQUIRED_CHECKS
from worldgen.verify.edits import EDITS, EditedWorld, apply_edit, edit_world, replay_edits


def test_a_thousand_edits_each_accepted_one_proven_and_rechecked_independently():
    bases = [worldgen.generate("cluttered", seed, n_obstacles=n) for seed, n in zip(range(10), (5, 10, 15, 20, 25) * 2)]
    ops, accepted, refused = Counter(), 0, 0
    for i in range(1000):
        base = bases[i % len(bases)]
        edited = edit_world(base, seed=i)
        if edited is None:
            refused += 1
            continue
        accepted += 1
        ops[edited.edits[-1]["op"]] += 1
        report = edited.feasibility
        assert report.feasible and report.checker == CHECKER
        assert [c.name for c in report.checks] == list(REQUIRED_CHECKS) and all(c.ok for c in report.checks)
        assert all(p is not None and p.length > 0 for p in report.paths)
        recheck(edited)  # shares no code with the checker: the footprint's distance along the whole path
        for task in edited.tasks:
            assert math.hypot(task.goal.x - task.spawn.x, task.goal.y - task.spawn.y) >= base.params["min_spawn_goal_distance"]
        for node in edited.scene.nodes:  # every obstacle still on the floor
            if node.role == "obstacle":
                (x0, y0), (x1, y1) = edited.scene.bounds
                corners = node.shape.local_corners()[:, :2] if node.shape.kind == "box" else None
                if corners is None:
                    r = node.shape.radius
                    assert x0 + r <= node.pose.x + 1e-9 and node.pose.x - 1e-9 <= x1 - r
                else:
                    c, s = math.cos(node.pose.yaw), math.sin(node.pose.yaw)
                    xs = node.pose.x + c * corners[:, 0] - s * corners[:, 1]
                    ys = node.pose.y + s * corners[:, 0] + c * corners[:, 1]
                    assert xs.min() >= x0 - 1e-6 and xs.max() <= x1 + 1e-6 and ys.min() >= y0 - 1e-6 and ys.max() <= y1 + 1e-6
        if i % 4 == 0:  # grow chains of edits as a curriculum does
            bases[i % len(bases)] = edited
    assert accepted >= 900 and set(ops) == set(EDITS), (accepted, refused, ops)


def test_recorded_edits_rebuild_the_same_world_and_change_its_identity():
    world = worldgen.generate("cluttered", 4)
    edited = world
    for seed in range(6):
        edited = edit_world(edited, seed) or edited
    assert isinstance(edited, EditedWorld) and len(edited.edits) >= 4
    again = replay_edits(worldgen.generate("cluttered", 4), edited.edits)
    assert again.content_hash == edited.content_hash and again.world_id != world.world_id
    assert again.world_id.startswith("cluttered-s4-")


def test_a_moved_goal_alone_changes_the_world_id():
    world = worldgen.generate("cluttered", 2)
    goal = world.tasks[0].goal
    edit = {"op": "move_goal", "task": 0, "x": goal.x + 0.05, "y": goal.y}
    moved = replay_edits(world, [edit])
    assert moved.scene.content_hash() == world.scene.content_hash() and moved.world_id != world.world_id
    assert np.allclose(moved.feasibility.paths[0].waypoints[-1], [goal.x + 0.05, goal.y])


def test_an_edit_that_walls_in_the_goal_is_refused():
    world = worldgen.generate("cluttered", 1, n_obstacles=3)
    goal = world.tasks[0].goal
    block = {"op": "add", "name": "edit_obstacle_0", "shape": {"type": "box", "size": [0.8, 0.8, 1.0]},
             "x": goal.x, "y": goal.y, "yaw": 0.0, "material": ["obstacle_box", [0.8, 0.52, 0.25, 1.0], 1.0]}
    scene, _ = apply_edit(world.scene, world.tasks, block)  # the edit applies ...
    node = scene.node("edit_obstacle_0")
    assert footprint_distance(node, np.array([[goal.x, goal.y]]))[0] == 0.0
    with pytest.raises(ParameterError, match="does not give a feasible world"):  # ... and is refused
        replay_edits(world, [block])


def test_worlds_with_movers_are_not_edited_and_bad_operators_are_one_line_errors():
    movers = worldgen.generate("cluttered", 0, n_movers=1)
    assert edit_world(movers, 0) is None
    with pytest.raises(ParameterError, match="parameter 'edits' must name some of move, resize, add, remove, move_goal"):
        edit_world(worldgen.generate("cluttered", 0), 0, ops=("teleport",))


def test_the_same_seed_gives_the_same_edit():
    world = worldgen.generate("cluttered", 5)
    assert [edit_world(world, s).edits for s in range(5)] == [edit_world(world, s).edits for s in range(5)]


def test_an_edited_level_written_to_disk_passes_worldgen_check_and_a_tampered_edit_fails(tmp_path):
    """world.json records the edits; `worldgen check` regenerates the world, replays them (each re-proved)
    and gets the recorded content_hash; an edit changed by hand is caught at `regenerate`."""
    import json

    from worldgen.verify import check_folder

    edited = next(e for s in range(20) if (e := edit_world(worldgen.generate("cluttered", 4), seed=s)) is not None)
    folder = edited.write(tmp_path, preview=False)
    meta = json.loads((folder / "world.json").read_text())
    assert meta["edits"] == [dict(e) for e in edited.edits]
    outcome = check_folder(folder)
    assert outcome.ok, outcome.line()
    assert "edits" not in worldgen.generate("cluttered", 4).metadata  # plain worlds keep their bytes
    meta["edits"][0] = {"op": "remove", "node": "no_such_obstacle"}
    (folder / "world.json").write_text(json.dumps(meta))
    outcome = check_folder(folder)
    assert not outcome.ok and outcome.check == "regenerate" and "edits" in outcome.line(), outcome.line()
