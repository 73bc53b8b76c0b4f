"""pedsim.xml and hunav_agents.yaml: each passes the rules its tool's loader holds it to (tests/support/
crowd_loaders.py, written from their source) and reads back to world.json: starts and goals on the recorded
walk within 1 mm, the walk within the route tolerance of the legs between them, speeds, behaviours, radii.
A world without people is refused (one line, exit 2, nothing written); `worldgen check` re-renders both."""

from __future__ import annotations

import json
import math

import numpy as np
import pytest
from support.cli import run, world_dirs
from support.crowd_loaders import HUNAV_BEHAVIORS, read_hunav, read_pedsim

import worldgen
from worldgen.errors import ParameterError
from worldgen.export.crowd import ROUTE_TOLERANCE
from worldgen.presets import generate_preset, load, names
from worldgen.verify.folder import check_folder

MM = 1e-3
PEOPLE_PRESETS = [n for n in names() if load(n).params.get("n_people")]
#: A random crowd: obstacles, groups, mixed behaviours, and a scripted mover beside the people.
CROWD = {"size": [10.0, 10.0], "n_obstacles": 8, "n_people": 6, "group_size": 2, "people_duration": 20.0,
         "people_behaviour": "regular,scared,impassive,curious", "n_movers": 1}


def _worlds():
    yield from ((name, lambda name=name: generate_preset(name, 0)) for name in PEOPLE_PRESETS)
    yield "random_crowd", lambda: worldgen.generate("cluttered", seed=5, **CROWD)


WORLDS = dict(_worlds())


@pytest.fixture(scope="module", params=sorted(WORLDS))
def case(request):
    world = WORLDS[request.param]()
    meta = world.metadata_for(world.rendered_files(["sdf", "pedsim", "hunav"]))
    return world, meta


def _walkers(meta) -> list[dict]:
    """world.json's people, then its scripted movers: the agents' order in both files."""
    return meta["people"] + meta.get("dynamic_obstacles", [])


def _assert_on_walk(name, trajectory, start, goals):
    """start is the first row; each goal a row after the one before, the last goal the last row; and every
    row within the route tolerance of the legs start -> goal 0 -> goal 1 -> ..."""
    rows = np.asarray(trajectory, dtype=float)[:, 1:3]
    assert math.dist(start, rows[0]) <= MM, f"{name}: starts {start}, world.json {rows[0]}"
    at = 0
    for k, goal in enumerate(goals):
        near = np.flatnonzero(np.hypot(*(rows[at:] - goal).T) <= MM)
        assert near.size, f"{name}: goal {k} {goal} is no row of its walk after row {at}"
        at += int(near[0])
    moves = bool(np.any(rows != rows[0]))
    assert math.dist(goals[-1], rows[-1]) <= MM, f"{name}: its last goal {goals[-1]} is not where it ends {rows[-1]}"
    assert moves or len(goals) == 1
    corners = np.vstack([start, goals])
    a, b = corners[:-1], corners[1:]
    d = b - a
    length2 = np.maximum((d * d).sum(1), 1e-18)
    s = np.clip(((rows[:, None] - a[None]) * d[None]).sum(2) / length2, 0, 1)
    gap = np.hypot(*(rows[:, None] - (a[None] + s[..., None] * d[None])).transpose(2, 0, 1)).min(1)
    assert gap.max() <= ROUTE_TOLERANCE + MM, f"{name}: the walk strays {gap.max():.4f} m from its legs"


def _pace(trajectory) -> float:
    """The median speed of the legs at 0.05 m/s or more, weighted by duration (written out independently)."""
    legs = []
    for (t0, x0, y0), (t1, x1, y1) in zip(trajectory, trajectory[1:]):
        v = math.hypot(x1 - x0, y1 - y0) / (t1 - t0)
        if v >= 0.05:
            legs.append((v, t1 - t0))
    if not legs:
        return 0.0
    legs.sort()
    half, total = sum(dt for _, dt in legs) / 2, 0.0
    for v, dt in legs:
        total += dt
        if total >= half:
            return v
    raise AssertionError("unreachable")


def test_pedsim_passes_its_reader_and_reads_back_to_world_json(case):
    world, meta = case
    read = read_pedsim(world.export_bytes("pedsim"))
    walkers = _walkers(meta)
    assert len(read["agents"]) == len(walkers)
    for agent, entry in zip(read["agents"], walkers):
        assert (agent["n"], agent["dx"], agent["dy"], agent["type"]) == (1, 0.0, 0.0, 0)  # one ADULT, exactly there
        goals = [(read["waypoints"][w]["x"], read["waypoints"][w]["y"]) for w in agent["route"]]
        _assert_on_walk(entry["name"], entry["trajectory"], (agent["x"], agent["y"]), goals)
        assert {read["waypoints"][w]["r"] for w in agent["route"]} == {entry["radius"]}
        assert {read["waypoints"][w]["b"] for w in agent["route"]} == {0}
    (x0, y0), (x1, y1) = meta["bounds"]["min"], meta["bounds"]["max"]
    for edge in [(x0, y0, x1, y0), (x1, y0, x1, y1), (x1, y1, x0, y1), (x0, y1, x0, y0)]:
        assert edge in read["obstacles"], f"the floor's edge {edge} is no wall"


def test_hunav_passes_its_loader_and_reads_back_to_world_json(case):
    world, meta = case
    read = read_hunav(world.export("hunav"))
    assert read["map"] == meta["occupancy"]["yaml"] and meta["files"]["map_yaml"]["path"] == read["map"]
    walkers = _walkers(meta)
    assert [a["name"] for a in read["agents"]] == [e["name"] for e in walkers]
    for agent, entry in zip(read["agents"], walkers):
        person = entry in meta["people"]
        x, y, _, h = agent["init_pose"]
        goals = [(gx, gy) for gx, gy, _ in agent["goals"]]
        _assert_on_walk(entry["name"], entry["trajectory"], (x, y), goals)
        assert agent["behavior"] == HUNAV_BEHAVIORS[entry.get("behaviour", "impassive")]
        assert agent["max_vel"] == pytest.approx(_pace(entry["trajectory"]), abs=1e-6)
        assert agent["radius"] == agent["goal_radius"] == entry["radius"]
        assert agent["cyclic_goals"] is (not person)  # a person walks once; a scripted mover loops
        legs = [(x, y)] + goals
        for k, (gx, gy, gh) in enumerate(agent["goals"]):
            (ax, ay), (bx, by) = legs[k], legs[k + 1]
            assert gh == pytest.approx(math.atan2(by - ay, bx - ax) if (ax, ay) != (bx, by) else 0.0, abs=1e-6)
        assert h == pytest.approx(agent["goals"][0][2], abs=1e-6)


def test_the_random_crowd_has_what_the_presets_lack():
    """The crowd case is what it claims: reacting people of several behaviours, and a scripted mover."""
    world = WORLDS["random_crowd"]()
    read = read_hunav(world.export("hunav"))
    assert {a["behavior"] for a in read["agents"]} >= {1, 2, 4, 5}
    assert [a["cyclic_goals"] for a in read["agents"]].count(True) == 1


def test_the_checkers_refuse_what_the_loaders_would_misread():
    good_xml = (b'<scenario><waypoint id="w" x="1" y="2" r="0.3" b="0"/>'
                b'<agent x="0" y="0" n="1" dx="0" dy="0" type="0"><addwaypoint id="w"/></agent></scenario>')
    assert read_pedsim(good_xml)["agents"][0]["route"] == ["w"]
    for bad, why in [(good_xml.replace(b' r="0.3"', b""), "has no r"),
                     (good_xml.replace(b'x="1"', b'x="1,5"'), "no number"),
                     (good_xml.replace(b'type="0"', b'type="2"'), "not a person"),
                     (b'<scenario><agent x="0" y="0" n="1" dx="0" dy="0" type="0"><addwaypoint id="w"/></agent>'
                      b'<waypoint id="w" x="1" y="2" r="0.3" b="0"/></scenario>', "not read yet"),
                     (good_xml.replace(b"<scenario>", b"<scenario><wall/>"), "no element")]:
        with pytest.raises(AssertionError, match=why):
            read_pedsim(bad)
    world = WORLDS["person_crossing"]()
    good = world.export("hunav")
    assert read_hunav(good)["agents"][0]["name"] == "person_0"
    for bad, why in [(good.replace("radius: 0.25", "radius: 1"), "decimal point"),
                     (good.replace("      id: 1\n", ""), r"person_0\.id = None"),
                     (good.replace("behavior: 2", "behavior: 7"), "none of 1-6"),
                     (good.replace("cyclic_goals: false", "cyclic_goals: 0"), "declared a bool"),
                     (good.replace("      goals:\n        - g0\n", "      goals: []\n"), "non-empty")]:
        assert bad != good, why
        with pytest.raises(AssertionError, match=why):
            read_hunav(bad)


def test_a_world_without_people_is_refused_in_one_line_and_nothing_is_written(tmp_path):
    world = worldgen.generate("cluttered", seed=0, size=[6.0, 6.0], n_obstacles=4, n_movers=1)
    for fmt in ("pedsim", "hunav"):
        with pytest.raises(ParameterError, match=f"format '{fmt}' writes a world's people, and this world has none"):
            world.export(fmt)
        with pytest.raises(ParameterError):
            world.write(tmp_path / "api", formats=["sdf", fmt])
        res = run("generate", "cluttered", "--set", "size=6,6", "--set", "n_obstacles=4", "--out", tmp_path / fmt,
                  "--formats", f"sdf,{fmt}")
        assert res.returncode == 2 and res.stderr.count("\n") == 1 and "set n_people" in res.stderr, res.stderr
        assert "Traceback" not in res.stderr
    assert not world_dirs(tmp_path / "api") and not any(tmp_path.glob("*/*"))


def test_written_and_checked_a_tampered_file_fails(tmp_path):
    res = run("generate", "--preset", "person_crossing", "--out", tmp_path, "--formats", "sdf,pedsim,hunav")
    assert res.returncode == 0, res.stderr
    (folder,) = world_dirs(tmp_path)
    meta = json.loads((folder / "world.json").read_text())
    assert meta["files"]["pedsim"]["path"] == "pedsim.xml" and meta["files"]["hunav"]["path"] == "hunav_agents.yaml"
    assert meta["people"][0]["formats"]["pedsim"] == meta["people"][0]["formats"]["hunav"] == "agent"
    assert check_folder(folder).ok
    agents = folder / "hunav_agents.yaml"
    agents.write_text(agents.read_text().replace("behavior: 2", "behavior: 1"))
    outcome = check_folder(folder)
    assert (outcome.check, outcome.ok) == ("files", False) and "hunav_agents.yaml" in outcome.detail
    # the edit with its hash recorded anew passes the hashes, and regeneration finds it out
    import hashlib

    meta["files"]["hunav"]["sha256"] = hashlib.sha256(agents.read_bytes()).hexdigest()
    (folder / "world.json").write_text(json.dumps(meta))
    outcome = check_folder(folder)
    assert (outcome.check, outcome.ok) == ("reproduce", False), outcome.line()


def test_asking_for_them_changes_world_json_only_by_their_files_and_notes():
    world = WORLDS["person_in_doorway"]()
    default = world.metadata
    assert "pedsim" not in default["files"] and "pedsim" not in default["people"][0]["formats"]
    with_crowd = world.metadata_for(world.rendered_files(["sdf", "mjcf", "urdf", "pedsim", "hunav"]))
    for key in ("pedsim", "hunav"):
        with_crowd["files"].pop(key)
        for entry in with_crowd["people"]:
            assert entry["formats"].pop(key) == "agent"
    assert json.dumps(with_crowd, sort_keys=True) == json.dumps(default, sort_keys=True)


def test_corners_of_hand_made_walks():
    from worldgen.export.crowd import route, routes, walking_speed

    straight = [(0.1 * k, 0.1 * k, 0.0) for k in range(11)]
    assert route(straight).tolist() == [[0.0, 0.0], [1.0, 0.0]]
    standing = [(0.0, 2.0, 3.0), (5.0, 2.0, 3.0)]
    assert route(standing).tolist() == [[2.0, 3.0]] and walking_speed(standing) == 0.0
    # an L walked at 1 m/s with a 2 s stay at the corner: the corner is kept once, the pace is the walking
    ell = [(0.0, 0.0, 0.0), (1.0, 1.0, 0.0), (3.0, 1.0, 0.0), (4.0, 1.0, 1.0)]
    assert route(ell).tolist() == [[0.0, 0.0], [1.0, 0.0], [1.0, 1.0]] and walking_speed(ell) == 1.0
    # a closed loop (a scripted mover): the far corner splits it, then each half keeps its corners
    square = [(0, 0, 0), (1, 2, 0), (2, 2, 2), (3, 0, 2), (4, 0, 0)]
    assert route(square).tolist() == [[0, 0], [2, 0], [2, 2], [0, 2], [0, 0]]
    # a bump of 4 cm stays inside the tolerance, one of 6 cm is a corner; walks apart do not share legs
    low, high = [(0, 0, 0), (1, 1, 0.04), (2, 2, 0)], [(0, 0, 0), (1, 1, 0.06), (2, 2, 0)]
    assert [r.tolist() for r in routes([low, high, straight])] == \
        [[[0, 0], [2, 0]], [[0, 0], [1, 0.06], [2, 0]], [[0.0, 0.0], [1.0, 0.0]]]


def test_every_behaviour_has_hunavs_number():
    """worldgen's behaviours are HuNavSim's names: each is written as the number hunav_msgs gives that name."""
    from worldgen.export.hunav import BEHAVIOR
    from worldgen.people.behaviours import BEHAVIOURS

    assert set(BEHAVIOR) == set(BEHAVIOURS)
    assert all(HUNAV_BEHAVIORS[name] == number for name, number in BEHAVIOR.items())


def test_groups_are_hunavs_group_ids_and_walk_together():
    """The group_passing group of group_in_corridor, and the random crowd's pairs (its mover alone), share a
    group_id; members walked together in world.json (within 2 m of each other, median over the first 10 s)."""
    for name, expected in (("group_in_corridor", [0, 0, 0]), ("random_crowd", [0, 0, 2, 2, 4, 4, -1])):
        world = WORLDS[name]()
        read = read_hunav(world.export("hunav"))
        assert [a["group_id"] for a in read["agents"]] == expected, name
        people = world.metadata["people"]
        t = np.arange(0.0, 10.0, 0.1)

        def at(entry):
            rows = np.asarray(entry["trajectory"])
            return np.column_stack([np.interp(t, rows[:, 0], rows[:, 1]), np.interp(t, rows[:, 0], rows[:, 2])])

        for group in set(expected) - {-1}:
            members = [at(people[i]) for i, g in enumerate(expected) if g == group]
            for a, b in zip(members, members[1:]):
                assert np.median(np.hypot(*(a - b).T)) < 2.0, (name, group)


def test_the_same_bytes_in_another_process():
    import hashlib
    import subprocess
    import sys

    code = ("import hashlib, sys, worldgen\n"
            f"w = worldgen.generate('cluttered', seed=5, **{CROWD!r})\n"
            "sys.stdout.write(' '.join(hashlib.sha256(w.export_bytes(f)).hexdigest() for f in ('pedsim', 'hunav')))\n")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=120, check=True).stdout
    world = WORLDS["random_crowd"]()
    assert out.split() == [hashlib.sha256(world.export_bytes(f)).hexdigest() for f in ("pedsim", "hunav")]
