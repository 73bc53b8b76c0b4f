"""worldgen.shrink: the smallest failing world, written and honest about where it came from."""

import json

import pytest

import worldgen
from worldgen.errors import ParameterError
from worldgen.export import metadata
from worldgen.verify import check_folder


@pytest.fixture(scope="module")
def busy():
    return worldgen.generate("cluttered", seed=3, size=[10, 10], n_obstacles=30, n_movers=1)


def obstacles(world):
    return [n.name for n in world.scene.nodes if n.role == "obstacle"]


def test_shrinks_to_the_one_obstacle_that_matters(busy, tmp_path):
    culprit = obstacles(busy)[7]
    calls = []

    def still_fails(world):
        calls.append(world)
        return culprit in obstacles(world)

    result = worldgen.shrink(busy, still_fails, tmp_path)
    assert obstacles(result.world) == [culprit] and result.world.scene.movers == ()
    assert len(result.removed) == 30 and result.calls == len(calls) < 60
    assert all(w.feasibility.feasible for w in calls)
    meta = json.loads((result.path / "world.json").read_text())
    metadata.validate(meta)
    assert meta["feasibility"]["feasible"] is True and meta["metrics"]["obstacle_count"] == 1
    assert meta["generator"] == "cluttered" and meta["seed"] == 3
    assert meta["params"] == json.loads(json.dumps(busy.params))  # the original's: check regenerates it
    assert meta["edits"] == [{"op": "remove_mover", "mover": "mover_0"}] + \
        [{"op": "remove", "node": name} for name in sorted(set(obstacles(busy)) - {culprit})]
    assert [e["name"] for e in meta["entities"] if e["role"] == "obstacle"] == [culprit]


def test_keeps_what_the_failure_needs(busy, tmp_path):
    # A failure that needs any three obstacles and the mover keeps exactly those.
    result = worldgen.shrink(busy, lambda w: len(obstacles(w)) >= 3 and len(w.scene.movers) == 1, tmp_path)
    assert len(obstacles(result.world)) == 3 and len(result.world.scene.movers) == 1
    # Reference paths are re-proven for the thinner world: never longer than before.
    assert result.world.feasibility.paths[0].length <= busy.feasibility.paths[0].length + 1e-9


def test_refuses_a_world_that_does_not_fail(busy, tmp_path):
    with pytest.raises(ParameterError, match="parameter 'still_fails' must return True for the world given"):
        worldgen.shrink(busy, lambda w: False, tmp_path)
    with pytest.raises(ParameterError, match="parameter 'max_calls' must be an integer >= 1"):
        worldgen.shrink(busy, lambda w: True, tmp_path, max_calls=0)


def test_a_shrunk_world_passes_worldgen_check(busy, tmp_path):
    """The removals are edits: check regenerates the original, replays them (each re-proved), and finds the same
    bytes. Before shrink recorded its removals as edits, check failed every shrunk world at 'regenerate'."""
    culprits = obstacles(busy)[3:5]
    result = worldgen.shrink(busy, lambda w: set(culprits) <= set(obstacles(w)), tmp_path)
    assert sorted(obstacles(result.world)) == sorted(culprits)
    outcome = check_folder(result.path)
    assert outcome.ok, outcome.line()


# -- worlds with people ----------------------------------------------------------


@pytest.fixture(scope="module")
def crowds():
    """A people preset (eight people reacting in four ways, six obstacles) and a random crowd (six people,
    three of four reacting, ten obstacles, two scripted movers)."""
    from worldgen.presets import generate_preset

    return {"crowd_reacting": generate_preset("crowd_reacting", 0),
            "random": worldgen.generate("cluttered", seed=4, size=[10, 10], n_obstacles=10, n_movers=2, n_people=6,
                                        people_behaviour="regular,scared,curious,impassive")}


def people(world):
    return [m.name for m in world.scene.movers if m.person]


def certified(world) -> bool:
    """A candidate as shrink may hand it over: feasible, and among people every task certified."""
    checks = {c.name: c.ok for c in world.feasibility.checks}
    return world.feasibility.feasible and (not people(world) or checks.get("timed_path") is True)


@pytest.mark.parametrize("kind", ["crowd_reacting", "random"])
def test_keeps_exactly_the_person_the_failure_needs(crowds, kind, tmp_path):
    world = crowds[kind]
    target = "person_3"
    handed = []

    def still_fails(candidate):
        handed.append(candidate)
        return target in people(candidate)

    result = worldgen.shrink(world, still_fails, tmp_path)
    assert people(result.world) == [target] and result.world.scene.movers[0].name == target
    assert result.people == tuple(sorted(set(people(world)) - {target}))
    assert result.counts == {"people": len(people(world)) - 1, "movers": len(world.scene.movers) - len(people(world)),
                             "obstacles": len(obstacles(world))}
    assert obstacles(result.world) == [] and all(certified(c) for c in handed)
    meta = json.loads((result.path / "world.json").read_text())
    assert [e["op"] for e in meta["edits"]] == ["remove_person"] * result.counts["people"] + \
        ["remove_mover"] * result.counts["movers"] + ["remove"] * result.counts["obstacles"]
    # The person kept keeps its behaviour and tube; its walk is its walk alone in an empty room now.
    kept = next(p for p in world.metadata["people"] if p["name"] == target)
    assert [{k: v for k, v in p.items() if k != "trajectory"} for p in meta["people"]] == \
        [{k: v for k, v in kept.items() if k != "trajectory"}]
    outcome = check_folder(result.path)  # regenerates, replays the edits, walks and certifies again
    assert outcome.ok, outcome.line()


def test_the_same_shrink_twice_writes_the_same_bytes(crowds, tmp_path):
    world = crowds["random"]
    obstacle = obstacles(world)[2]

    def still_fails(candidate):
        return "person_1" in people(candidate) and obstacle in obstacles(candidate)

    first = worldgen.shrink(world, still_fails, tmp_path / "a")
    second = worldgen.shrink(world, still_fails, tmp_path / "b")
    files = sorted(p.relative_to(first.path) for p in first.path.rglob("*") if p.is_file())
    assert files == sorted(p.relative_to(second.path) for p in second.path.rglob("*") if p.is_file())
    assert all((first.path / f).read_bytes() == (second.path / f).read_bytes() for f in files)
    assert first.record() | {"path": ""} == second.record() | {"path": ""}
    assert people(first.world) == ["person_1"] and obstacles(first.world) == [obstacle]


def test_a_candidate_whose_people_cannot_be_certified_is_skipped(monkeypatch, tmp_path):
    """In this small crowded room, the world without person_0 has no certificate (the others end their walk
    where the robot finds no way through): shrink builds that candidate, skips it, and never hands it over,
    so the failure that needs every other person keeps person_0 too."""
    from worldgen.verify import edits

    world = worldgen.generate("cluttered", seed=5, size=[6, 6], n_obstacles=8, n_people=5, people_duration=30.0,
                              people_behaviour="regular,scared,curious")
    others = {"person_1", "person_2", "person_3", "person_4"}
    built, handed = [], []
    real = edits.with_edits

    def spy(w, e):
        made = real(w, e)
        built.append((tuple(x.get("person", "") for x in e), made))
        return made

    monkeypatch.setattr(edits, "with_edits", spy)

    def still_fails(candidate):
        assert certified(candidate)
        handed.append(candidate)
        return others <= set(people(candidate))

    result = worldgen.shrink(world, still_fails, tmp_path)
    refused = [names for names, made in built if made is None]
    assert ("person_0",) in [tuple(n for n in names if n) for names in refused]  # that one alone, among others
    assert result.skipped == len(refused) >= 1 and result.calls == len(handed)  # the first: the world itself
    assert sorted(people(result.world)) == sorted(others | {"person_0"})
    assert check_folder(result.path).ok


def test_every_candidate_handed_over_holds_its_certificate_as_check_reads_it(crowds, tmp_path):
    """The property, proven from each candidate's world.json as ``worldgen check`` proves it (verify.timed),
    for every candidate of a shrink that needs two people and three obstacles."""
    from worldgen.verify.timed import check_timed

    world = crowds["crowd_reacting"]
    handed = []

    def still_fails(candidate):
        handed.append(candidate)
        return {"person_0", "person_5"} <= set(people(candidate)) and len(obstacles(candidate)) >= 3

    result = worldgen.shrink(world, still_fails, tmp_path)
    assert sorted(people(result.world)) == ["person_0", "person_5"] and len(obstacles(result.world)) == 3
    for candidate in handed:
        assert certified(candidate)
        check_timed(candidate.metadata, candidate)  # raises TimedPathError at the first fault


def test_a_world_folder_in_a_folder_out(crowds, tmp_path):
    """What a campaign's worker calls: the path of a written world in, the shrunk world written, plain data back."""
    from worldgen.verify import load_world

    folder = crowds["random"].write(tmp_path / "in")
    assert load_world(folder).content_hash == crowds["random"].content_hash
    result = worldgen.shrink(str(folder), lambda w: "person_5" in people(w), tmp_path / "out")
    record = result.record()
    assert json.loads(json.dumps(record)) == record and record["counts"]["people"] == 5
    assert result.path.parent == tmp_path / "out" and check_folder(result.path).ok
    with pytest.raises(ParameterError, match="holds no world worldgen can rebuild: metadata"):
        worldgen.shrink(tmp_path / "out" / "nothing", lambda w: True, tmp_path / "out2")
