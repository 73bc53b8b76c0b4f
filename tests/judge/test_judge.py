"""`worldgen judge` end to end: real bags in tmp folders, the command in a real process, the report folder read back."""

import csv
import json

import numpy as np
import pytest
from PIL import Image
from support.cli import run
from support.runs import along, idle_then, small_world, toward, write_bag

from worldgen import oracles

pytest.importorskip("rosbags")

CRITERIA = """
navigation:
  success_rate: 1.0
safety:
  collision_tolerance: 0
"""


@pytest.fixture(scope="module")
def setup(tmp_path_factory):
    """One world (folder inside a folder of worlds) and three bags: clean, idle then clean, a collision."""
    root = tmp_path_factory.mktemp("judge")
    world = small_world(root / "worlds")
    meta = oracles.load(world).meta
    obstacle = next(e for e in meta["entities"] if e["role"] == "obstacle")
    bags = root / "bags"
    bags.mkdir()
    clean = write_bag(bags / "clean", world, along(world), storage="mcap", run="clean")
    idle = write_bag(bags / "idle", world, idle_then(along(world), 4.0), storage="sqlite3", distro="humble")
    crash = write_bag(bags / "crash", world, toward(world, obstacle["pose"][:2]), storage="mcap")
    (root / "criteria.yaml").write_text(CRITERIA)
    return {"root": root, "world": world, "clean": clean, "idle": idle, "crash": crash, "obstacle": obstacle["name"],
            "criteria": root / "criteria.yaml"}


def _report(out):
    return json.loads((out / "report.json").read_text())


def test_clean_runs_pass_the_gate(setup, tmp_path):
    out = tmp_path / "report"
    r = run("judge", setup["clean"], setup["idle"], "--world", setup["world"], "--criteria", setup["criteria"], "--out", out)
    assert r.returncode == 0, r.stderr
    assert r.stdout.splitlines()[0] == "2 bags, 2 judged, 2 succeeded, 0 unjudged: PASS" and r.stderr == ""
    report = _report(out)
    assert report["passed"] is True and report["summary"]["unjudged"] == 0
    clean, idle = report["runs"]
    world_id = oracles.load(setup["world"]).meta["world_id"]
    # <world>__<task>__ and the run's own name from the bag's metadata, else the first free index
    assert clean["run"] == f"{world_id}__task_0__clean" and idle["run"] == f"{world_id}__task_0__run0"
    assert clean["outcome"] == idle["outcome"] == "success"
    assert clean["source"] == idle["source"] == "tf" and clean["start"] == "command"
    assert idle["start_time"] == pytest.approx(4.0)
    # the idle seconds before the first command do not count: the same drive, the same time to goal
    assert idle["time_to_goal"] == pytest.approx(clean["time_to_goal"], abs=1e-9)
    truth = oracles.run(along(setup["world"]), setup["world"])
    assert clean["time_to_goal"] == pytest.approx(truth.time_to_goal, abs=1e-9)
    assert clean["path_efficiency"] == pytest.approx(truth.path_efficiency, abs=1e-9)
    assert clean["min_clearance"] == pytest.approx(truth.min_clearance, abs=1e-9)
    with (out / "report.csv").open() as f:
        rows = list(csv.DictReader(f))
    assert [r["run"] for r in rows] == [clean["run"], idle["run"]] and rows[0]["success"] == "True"
    md = (out / "report.md").read_text()
    assert md.startswith("# Run report: PASS\n") and "| navigation.success_rate | >= 1 | 1 | PASS |" in md
    for row in report["runs"]:
        with Image.open(out / row["picture"]) as img:
            assert img.format == "PNG" and img.width >= 400


def test_a_collision_fails_the_gate_and_is_drawn(setup, tmp_path):
    out = tmp_path / "report"
    r = run("judge", setup["clean"], setup["crash"], "--world", setup["world"], "--criteria", setup["criteria"],
            "--out", out)
    assert r.returncode == 1, r.stderr
    report = _report(out)
    crash = report["runs"][1]
    assert crash["success"] is False and crash["reason"].startswith("collision with ")
    assert setup["obstacle"] in {c["entity"] for c in crash["collisions"]}
    assert "FAILED navigation.success_rate: required >= 1, measured 0.5, failed by 0.5" in r.stdout
    # The picture marks the contact in the contact colour, the trajectory of a failed run in the failure colour.
    from worldgen.judge.report import COLOURS
    with Image.open(out / crash["picture"]) as img:
        colours = {c for _, c in img.convert("RGB").getcolors(1 << 20)}
    assert COLOURS["contact"] in colours and COLOURS["path"] in colours and COLOURS["spawn"] in colours


def test_an_unreadable_bag_is_an_unjudged_row_named_on_stderr_and_fails_the_gate(setup, tmp_path):
    broken = tmp_path / "broken.mcap"
    data = next(setup["clean"].glob("*.mcap")).read_bytes()
    broken.write_bytes(data[: len(data) // 3])
    out = tmp_path / "report"
    r = run("judge", setup["clean"], broken, "--world", setup["world"], "--out", out)
    assert r.returncode == 1, r.stderr
    report = _report(out)
    assert report["summary"]["unjudged"] == 1 and report["summary"]["bags"] == 2 and report["summary"]["runs"] == 1
    row = report["runs"][1]
    assert row["outcome"] == "unjudged" and row["success"] is None and row["readable"] is False
    world_id = oracles.load(setup["world"]).meta["world_id"]
    assert row["run"] == f"{world_id}__task_0__run0" and "cannot be read as a ROS bag" in row["reason"]
    assert "bags: 1 of 2 could not be judged; a gate does not pass on missing data" in report["failures"]
    lines = r.stderr.splitlines()
    assert len(lines) == 1 and lines[0].startswith(f"unjudged {broken}: cannot be read as a ROS bag (")
    only_broken = run("judge", broken, "--world", setup["world"], "--out", tmp_path / "r2")
    assert only_broken.returncode == 1 and _report(tmp_path / "r2")["summary"]["runs"] == 0


def test_every_refused_bag_gets_a_line_then_a_count(setup, tmp_path):
    missing = [tmp_path / f"gone{k:02d}" for k in range(23)]
    r = run("judge", *missing, "--world", setup["world"], "--out", tmp_path / "r")
    assert r.returncode == 1
    lines = r.stderr.splitlines()
    assert lines[:20] == [f"unjudged {m}: does not exist" for m in missing[:20]]
    assert lines[20:] == ["... and 3 more not judged or failed (every one in report.md)"]


def test_an_empty_pack_folder_or_a_missing_one_is_a_usage_mistake(setup, tmp_path):
    (tmp_path / "empty").mkdir()
    for pack, message in ((tmp_path / "nowhere", "does not exist"), (tmp_path / "empty", "neither a pack")):
        r = run("judge", setup["clean"], "--pack", pack, "--out", tmp_path / "r")
        assert r.returncode == 2 and message in r.stderr and len(r.stderr.splitlines()) == 1, r.stdout + r.stderr
        assert not (tmp_path / "r").exists()


def test_run_names_are_unique_and_readable_across_worlds(tmp_path):
    """The bundle's launch files number runs per world (worldgen.run 0 in every world): names carry the world."""
    worlds = [small_world(tmp_path / "worlds", seed=s) for s in (0, 1, 2)]
    bags = [write_bag(tmp_path / "bags" / f"w{k}", w, along(w), storage="mcap", run="0") for k, w in enumerate(worlds)]
    r = run("judge", *bags, "--pack", tmp_path / "worlds", "--out", tmp_path / "r")
    assert r.returncode == 0, r.stdout + r.stderr
    report = _report(tmp_path / "r")
    ids = [oracles.load(w).meta["world_id"] for w in worlds]
    assert [row["run"] for row in report["runs"]] == [f"{i}__task_0__run0" for i in ids]
    assert sorted(p.name for p in (tmp_path / "r" / "runs").iterdir()) == sorted(f"{i}__task_0__run0.png" for i in ids)


def test_worlds_named_in_the_bags_metadata_and_a_runs_table(setup, tmp_path):
    worlds = setup["world"].parent
    r = run("judge", setup["clean"], setup["idle"], "--pack", worlds, "--out", tmp_path / "a")
    assert r.returncode == 0, r.stderr
    table = tmp_path / "runs.csv"
    table.write_text(f"bag,world,task,run\n{setup['clean']},{setup['world']},task_0,first\n"
                     f"{setup['crash']},{setup['world'].name},,second\n")
    r = run("judge", "--runs", table, "--pack", worlds, "--out", tmp_path / "b")
    # No criteria: the gate is that every run meets its scenario, and the crash does not.
    assert r.returncode == 1, r.stderr
    report = _report(tmp_path / "b")
    world_id = oracles.load(setup["world"]).meta["world_id"]
    assert [row["run"] for row in report["runs"]] == [f"{world_id}__task_0__first", f"{world_id}__task_0__second"]
    assert [row["success"] for row in report["runs"]] == [True, False]
    assert report["failures"][0].startswith("navigation.success_rate: required >= 1, measured 0.5")


def test_a_bag_from_another_world_is_a_failed_run_not_an_unreadable_one(setup, tmp_path):
    other = small_world(tmp_path / "other", seed=1)
    r = run("judge", setup["clean"], "--world", other, "--out", tmp_path / "r")
    assert r.returncode == 1
    report = _report(tmp_path / "r")
    row = report["runs"][0]
    assert row["outcome"] == "failure" and row["success"] is False and row["readable"] is True
    assert "was recorded in world" in row["reason"]
    assert report["summary"]["runs"] == 1 and report["summary"]["unjudged"] == 0
    assert r.stderr.splitlines() == [f"failed {row['run']} ({setup['clean']}): {row['reason']}"]
    assert "could not be" not in r.stdout


def test_a_run_that_starts_far_from_the_spawn_is_a_failed_run_with_its_distance(setup, tmp_path):
    shifted = along(setup["world"])
    shifted[:, 1] += 6.4 if shifted[0, 1] < 0 else -6.4
    bag = write_bag(tmp_path / "far", setup["world"], shifted, storage="mcap")
    r = run("judge", bag, "--world", setup["world"], "--out", tmp_path / "r")
    assert r.returncode == 1
    report = _report(tmp_path / "r")
    row = report["runs"][0]
    assert row["outcome"] == "failure" and "the run starts 6.40 m from the task's spawn" in row["reason"]
    assert report["summary"]["runs"] == 1 and report["summary"]["successes"] == 0
    assert report["summary"]["unjudged"] == 0 and r.stderr.startswith(f"failed {row['run']} ({bag}): the run starts 6.40 m")


@pytest.mark.parametrize("args,message", [
    (["--out", "R"], "give at least one BAG"),
    (["BAG", "--out", "R"], "say where the worlds are: --world DIR"),
    (["BAG", "--world", "nowhere", "--out", "R"], "--world 'nowhere' is not a world folder (no world.json)"),
    (["BAG", "--world", "WORLD", "--criteria", "BAD", "--out", "R"], "unknown section 'speed'"),
    (["--runs", "TABLE", "--out", "R"], "runs table"),
])
def test_bad_input_is_one_line_exit_2_and_no_report(setup, tmp_path, args, message):
    (tmp_path / "bad.yaml").write_text("speed: {max: 1}\n")
    (tmp_path / "table.csv").write_text("bag\nx\n")
    subst = {"BAG": setup["clean"], "WORLD": setup["world"], "BAD": tmp_path / "bad.yaml", "R": tmp_path / "r",
             "TABLE": tmp_path / "table.csv"}
    r = run("judge", *[subst.get(a, a) for a in args])
    assert r.returncode == 2, r.stdout + r.stderr
    assert len(r.stderr.strip().splitlines()) == 1 and message in r.stderr and "Traceback" not in r.stderr
    assert not (tmp_path / "r").exists() and not list(tmp_path.glob(".r.*"))


def test_an_earlier_report_is_replaced_and_another_folder_refused(setup, tmp_path):
    out = tmp_path / "r"
    assert run("judge", setup["clean"], "--world", setup["world"], "--out", out).returncode == 0
    first = (out / "report.json").read_bytes()
    assert run("judge", setup["clean"], "--world", setup["world"], "--out", out).returncode == 0
    assert (out / "report.json").read_bytes() == first  # same inputs, same bytes
    (tmp_path / "keep").mkdir()
    (tmp_path / "keep" / "notes.txt").write_text("mine")
    r = run("judge", setup["clean"], "--world", setup["world"], "--out", tmp_path / "keep")
    assert r.returncode == 2 and "is not a report folder" in r.stderr
    assert (tmp_path / "keep" / "notes.txt").read_text() == "mine"


def test_help_has_an_example():
    r = run("judge", "--help")
    assert r.returncode == 0 and "worldgen judge runs/*.mcap --world" in r.stdout


def test_decimated_picture_keeps_the_ends():
    from worldgen.judge.runs import _decimate
    t = np.linspace(0, 100, 5001)
    traj = np.column_stack([t, np.cos(t / 10), np.sin(t / 10), t * 0])
    d = _decimate(traj, 100)
    assert len(d) <= 102 and (d[0] == traj[0, :3]).all() and (d[-1] == traj[-1, :3]).all()


def test_the_mujoco_example_loop_is_judged_end_to_end(tmp_path):
    """examples/diffdrive_mujoco.py records real bags; `worldgen judge` on them gives the example's own report,
    and the official mcap reader decodes them."""
    import subprocess
    import sys
    from pathlib import Path

    script = Path(__file__).resolve().parents[2] / "examples" / "diffdrive_mujoco.py"
    ex = subprocess.run([sys.executable, str(script), str(tmp_path / "ex"), "3"], capture_output=True, text=True,
                        timeout=300)
    assert ex.returncode == 0, ex.stdout + ex.stderr
    bags = sorted((tmp_path / "ex" / "bags").iterdir())
    (tmp_path / "c.yaml").write_text(CRITERIA)
    r = run("judge", *bags, "--pack", tmp_path / "ex" / "worlds", "--criteria", tmp_path / "c.yaml", "--out", tmp_path / "r")
    assert r.returncode == 0, r.stdout + r.stderr
    mine, theirs = _report(tmp_path / "r"), _report(tmp_path / "ex" / "report")
    drop = {"bag", "world_folder", "picture"}
    assert [{k: v for k, v in row.items() if k not in drop} for row in mine["runs"]] == \
           [{k: v for k, v in row.items() if k not in drop} for row in theirs["runs"]]
    assert all(row["success"] and row["source"] == "tf" and row["start"] == "command" for row in mine["runs"])
    mcap_reader = pytest.importorskip("mcap.reader")
    decoder = pytest.importorskip("mcap_ros2.decoder")
    with next(bags[0].glob("*.mcap")).open("rb") as f:
        reader = mcap_reader.make_reader(f, decoder_factories=[decoder.DecoderFactory()])
        odom = [m for _, ch, _, m in reader.iter_decoded_messages(topics=["/odom"])]
    assert odom[0].pose.pose.position.x == 0.0 and odom[0].pose.pose.position.y == 0.0  # zeroed at the spawn
    assert odom[0].header.frame_id == "odom" and odom[0].child_frame_id == "base_footprint"


def test_the_progress_bar_goes_to_stderr_when_asked(setup, tmp_path):
    r = run("judge", setup["clean"], setup["idle"], "--world", setup["world"], "--out", tmp_path / "r", "--progress")
    assert r.returncode == 0 and r.stderr.splitlines() == ["judging: 1 of 2 bags (50%)", "judging: 2 of 2 bags (100%)"]
    quiet = run("judge", setup["clean"], "--world", setup["world"], "--out", tmp_path / "q")
    assert quiet.returncode == 0 and quiet.stderr == ""  # not a terminal: no bar


def test_a_run_among_people_is_drawn_with_the_people_where_they_were_at_the_contact(tmp_path):
    """The caption said 'collision with person_0 at t=4.55 s' over an empty line: now the person is drawn."""
    from worldgen.export.preview import layout
    from worldgen.export.topdown import PERSON_COLOURS, discs_at
    from worldgen.judge.report import _HEADER, _WIDTH
    from worldgen.presets import generate_preset

    world = generate_preset("person_head_on").write(tmp_path / "worlds", preview=False)
    bag = write_bag(tmp_path / "bags" / "straight", world, along(world), storage="mcap")  # no yielding: it meets the person
    r = run("judge", bag, "--world", world, "--out", tmp_path / "r")
    assert r.returncode == 1
    row = _report(tmp_path / "r")["runs"][0]
    person = next(c for c in row["collisions"] if c["entity"] == "person_0")
    meta = oracles.load(world).meta
    (_, x, y, radius, colour), = [d for d in discs_at(meta, person["time"]) if d[0] == "person_0"]
    assert colour == PERSON_COLOURS[0]
    lay = layout(meta, _WIDTH)
    with Image.open(tmp_path / "r" / row["picture"]) as img:
        rgb = img.convert("RGB")
        u, v = lay.px(x + 0.6 * radius, y)  # inside the person's disc, off the crossed-out robot at its centre
        assert rgb.getpixel((round(u), round(v) + _HEADER)) == PERSON_COLOURS[0]
        assert {c for _, c in rgb.getcolors(1 << 20)} >= {PERSON_COLOURS[0], (200, 30, 30)}


def test_a_world_or_a_pack_world_is_judged_as_its_folder(setup, tmp_path):
    """judge(world=...) takes a World (unwritten), a pack's world (folder or archive) or a folder, each read through
    worldgen.groundtruth.folder: the same rows, and the report draws every run's picture."""
    import worldgen
    from worldgen.judge import judge, write_report
    from worldgen.pack import Pack, build_pack, parse_recipe
    from worldgen.pack.archive import write_archive

    bags = [setup["clean"], setup["crash"]]
    build_pack(parse_recipe("name: one\nseeds: 1\nworlds:\n  - generator: cluttered\n"
                            "    params: {size: [8, 8], n_obstacles: 6}\n"), tmp_path / "pack")
    pack, archived = Pack.open(tmp_path / "pack"), Pack.open(write_archive(tmp_path / "pack"))
    try:
        assert pack[0].world_id == oracles.load(setup["world"]).meta["world_id"]
        worlds = {"world": worldgen.generate("cluttered", seed=0, size=[8, 8], n_obstacles=6), "pack": pack[0],
                  "archive": archived[0]}
        expected = judge(bags, CRITERIA, world=setup["world"]).report
        for kind, world in worlds.items():
            result = judge(bags, CRITERIA, world=world)
            # A World's colliders are its scene's; a folder's are rebuilt from world.json's 6 decimals.
            drop = {"bag", "world_folder", "picture", "min_clearance"}
            assert [{k: v for k, v in r.items() if k not in drop} for r in result.report["runs"]] == \
                [{k: v for k, v in r.items() if k not in drop} for r in expected["runs"]], kind
            assert [r["min_clearance"] for r in result.report["runs"]] == \
                pytest.approx([r["min_clearance"] for r in expected["runs"]], abs=1e-6), kind
            assert result.passed is False and result.report["summary"]["runs"] == 2, kind
            folder = None if kind != "pack" else str(pack[0].path)  # no folder of its own: None, not a scratch copy
            assert [r["world_folder"] for r in result.report["runs"]] == [folder, folder], kind
            write_report(result, tmp_path / f"report-{kind}")
            assert all((tmp_path / f"report-{kind}" / r["picture"]).is_file() for r in result.report["runs"])
    finally:
        pack.close()
        archived.close()
