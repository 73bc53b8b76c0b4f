"""The systems under test of a campaign (worldgen.campaign.systems): each kind on a real world, judged as
``worldgen judge`` judges a bag; a command that crashes, hangs or leaves no bag is unjudged with its reason;
bad specs are one line; the planted-weakness policy fails only in its corner."""

from __future__ import annotations

import os
import pickle
import shlex
import sys
import time
from pathlib import Path

import pytest

import worldgen
from worldgen.campaign import SYSTEM_KEYS, Outcome, system_from_spec
from worldgen.errors import ParameterError

pytest.importorskip("gymnasium")
pytest.importorskip("mujoco")
pytest.importorskip("rosbags")

SCRIPT = Path(__file__).resolve().parent.parent / "support" / "bag_command.py"
FOLLOWER = "worldgen.envs.policies:PathFollower.for_env"
PLANTED = "support.planted:FreezesNearPeople.for_env"
#: The timed path turns on the spot: its followers need turn rates above the environment's default 1 rad/s.
TURNS = {"angular_velocity": 4.0}


def command(mode: str, timeout: float = 60) -> dict:
    line = f"{shlex.quote(sys.executable)} {shlex.quote(str(SCRIPT))} {mode} {{world}} {{task}} {{run}} {{bag}}"
    return {"command": line, "timeout": timeout}


@pytest.fixture(scope="module")
def worlds(tmp_path_factory):
    """A small cluttered world without people, and one where a person crosses the robot's way."""
    root = tmp_path_factory.mktemp("systems")
    plain = worldgen.generate("cluttered", seed=0, size=[8, 8], n_obstacles=6).write(root / "worlds", preview=False)
    crossed = worldgen.generate("cluttered", seed=0, size=[8, 8], n_obstacles=4, n_people=1,
                                people_scenario="crossing").write(root / "worlds", preview=False)
    return {"plain": Path(plain), "crossed": Path(crossed), "root": root}


def world_id(folder: Path) -> str:
    return folder.name


# -- each kind on a real world ---------------------------------------------------------------------------------

def test_a_policy_in_the_environment_is_judged_as_its_bag(worlds, tmp_path):
    system = system_from_spec({"policy": FOLLOWER})
    out = system.run(worlds["plain"], "task_0", "run0", tmp_path)
    assert isinstance(out, Outcome) and system.kind == "policy"
    assert (out.verdict, out.reason) == ("passed", "")
    row = out.row
    assert row["outcome"] == "success" and row["readable"] is True
    assert row["run"] == f"{world_id(worlds['plain'])}__task_0__run0"
    assert row["collisions"] == [] and row["time_to_goal"] > 0 and row["source"] == "ground_truth"
    assert Path(row["bag"]) == (tmp_path / "bags" / f"{world_id(worlds['plain'])}__task_0__run0").resolve()
    assert out.seconds > 0
    again = system.run(worlds["plain"], "task_0", "run0", tmp_path)  # the same world and policy: the same run
    assert again.row == row


def test_a_policy_runs_in_a_world_that_would_not_regenerate(worlds, tmp_path):
    """A shrunk world was edited since it was generated: the run needs its files only, never its generator."""
    import json
    import shutil

    edited = tmp_path / "edited" / worlds["plain"].name
    shutil.copytree(worlds["plain"], edited)
    meta = json.loads((edited / "world.json").read_text())
    meta["content_hash"] = "0" * len(meta["content_hash"])
    (edited / "world.json").write_text(json.dumps(meta))
    out = system_from_spec({"policy": FOLLOWER}).run(edited, "task_0", "run0", tmp_path / "work")
    assert (out.verdict, out.reason) == ("passed", "")


def test_a_policy_runs_in_an_edited_world_with_reacting_people(tmp_path):
    """Reacting people need the scene, which an edited (shrunk) world gives only with its edits replayed."""
    from worldgen.verify.edits import with_edits

    world = worldgen.generate("cluttered", seed=1, size=[8, 8], n_obstacles=4, n_people=2, people_behaviour="scared",
                              people_scenario="crossing")
    obstacle = next(n.name for n in world.scene.nodes if n.role == "obstacle")
    edited = with_edits(world, [{"op": "remove", "node": obstacle}])
    folder = Path(edited.write(tmp_path / "worlds", preview=False))
    out = system_from_spec({"policy": FOLLOWER}).run(folder, "task_0", "run0", tmp_path / "work")
    assert out.verdict in ("passed", "failed") and out.row["world_id"] == edited.world_id


def test_among_reacting_people_a_policy_is_judged_against_where_they_walked(tmp_path, monkeypatch):
    """The verdict and the person figures agree with the environment's own (Episode.figures: people as they
    walked), not with world.json's recorded walks, which a person who stepped aside never kept to."""
    import json

    import worldgen.campaign.systems as systems

    seen = []
    episode = systems._episode

    def spy(env, obs, act):
        out = episode(env, obs, act)
        seen.append(env.unwrapped.episode.figures())
        return out

    monkeypatch.setattr(systems, "_episode", spy)
    world = worldgen.generate("cluttered", seed=2, size=[8, 8], n_obstacles=4, n_people=3, people_behaviour="surprised")
    folder = Path(world.write(tmp_path / "worlds", preview=False))
    system = system_from_spec({"policy": "worldgen.envs.policies:GapHeuristic.for_env"})
    out = system.run(folder, "task_0", "run0", tmp_path / "work")
    figures = seen[-1]
    assert (out.verdict == "passed") == figures["success"]
    assert out.row["min_separation"] == pytest.approx(figures["min_separation"], abs=1e-6)
    walked = json.loads((tmp_path / "work" / "walked" / f"{world.world_id}__task_0__run0" / "world.json").read_text())
    assert all("recorded_trajectory" in p for p in walked["people"])  # every one of them reacted


def test_a_policy_that_raises_is_unjudged(worlds, tmp_path):
    out = system_from_spec({"policy": "support.planted:Breaks.for_env"}).run(worlds["plain"], "task_0", "r", tmp_path)
    assert out.verdict == "unjudged" and out.row == {}
    assert out.reason == "policy raised RuntimeError: the network's weights are NaN"


def test_the_reference_robot_drives_in_mujoco(worlds, tmp_path):
    system = system_from_spec({"drive": {"sim": "mujoco"}})
    assert system.kind == "drive"
    out = system.run(worlds["plain"], "task_0", "ref", tmp_path)
    assert (out.verdict, out.reason) == ("passed", "")
    assert out.row["run"] == f"{world_id(worlds['plain'])}__task_0__ref" and out.row["collisions"] == []
    assert Path(out.row["bag"]).is_dir()
    assert [p.name for p in (tmp_path / "bags").iterdir()] == [f"{world_id(worlds['plain'])}__task_0__ref"]



def test_a_factory_without_arguments_is_called_without_the_environment(worlds, tmp_path):
    out = system_from_spec({"policy": "support.planted:Stands"}).run(worlds["plain"], "task_0", "r", tmp_path)
    assert (out.verdict, out.reason) == ("failed", "goal not reached")
    assert out.row["path_length"] == 0.0


def test_an_action_of_an_unknown_shape_is_the_recipes_mistake(worlds, tmp_path):
    system = system_from_spec({"policy": "support.planted:TwoArguments"})
    with pytest.raises(ParameterError, match=r"action\(\) must take \(observation\), \(x, y, yaw\) or \(x, y, yaw, t\)"):
        system.run(worlds["plain"], "task_0", "r", tmp_path)

# -- the command kind ----------------------------------------------------------------------------------------

def test_a_command_that_leaves_a_clean_bag_passes(worlds, tmp_path):
    out = system_from_spec(command("success")).run(worlds["plain"], "task_0", "run0", tmp_path)
    assert (out.verdict, out.reason) == ("passed", "")
    assert out.row["outcome"] == "success" and out.row["run"] == f"{world_id(worlds['plain'])}__task_0__run0"


def test_a_command_whose_robot_collides_fails_naming_the_collision(worlds, tmp_path):
    out = system_from_spec(command("collision")).run(worlds["plain"], "task_0", "run0", tmp_path)
    assert out.verdict == "failed"
    assert out.reason.startswith("collision with obstacle_") and out.reason == out.row["reason"]
    assert out.row["outcome"] == "failure" and out.row["collisions"]


@pytest.mark.parametrize("mode, reason", [
    ("crash", "exit status 1"),
    ("nobag", "no readable bag: "),
    ("garbage", "no readable bag: "),
])
def test_a_command_that_leaves_nothing_to_judge_is_unjudged(worlds, tmp_path, mode, reason):
    out = system_from_spec(command(mode)).run(worlds["plain"], "task_0", "run0", tmp_path)
    assert out.verdict == "unjudged" and out.row == {}
    assert out.reason.startswith(reason) and "\n" not in out.reason
    log = tmp_path / "logs" / f"{world_id(worlds['plain'])}__task_0__run0.log"
    assert log.is_file()
    if mode == "crash":
        assert "lost the transform" in log.read_text()


def test_a_command_past_its_timeout_is_killed_with_its_process_group(worlds, tmp_path):
    started = time.perf_counter()
    out = system_from_spec(command("hang", timeout=3)).run(worlds["plain"], "task_0", "run0", tmp_path)
    assert (out.verdict, out.reason, out.row) == ("unjudged", "timed out after 3 s", {})
    assert time.perf_counter() - started < 3 + 5 + 10  # the grace, and a loaded machine
    child = int((tmp_path / "bags" / f"{world_id(worlds['plain'])}__task_0__run0.child").read_text())
    for _ in range(50):  # the child, in the command's process group, died with it
        try:
            os.kill(child, 0)
        except ProcessLookupError:
            break
        time.sleep(0.1)
    else:
        pytest.fail(f"the command's child {child} outlived the timeout")


def test_criteria_decide_the_verdict_and_name_the_failed_criterion(worlds, tmp_path):
    strict = {"safety": {"obstacle_clearance": 5.0}}
    out = system_from_spec(command("success"), criteria=strict).run(worlds["plain"], "task_0", "run0", tmp_path)
    assert out.verdict == "failed" and out.row["success"] is True
    assert out.reason.startswith("safety.obstacle_clearance: required >= 5")


def test_a_success_rate_bound_is_read_per_run_as_its_point_form(worlds, tmp_path):
    bound = {"navigation": {"success_rate": {"min": 0.95, "confidence": 0.95}}}
    clean = system_from_spec(command("success"), criteria=bound).run(worlds["plain"], "task_0", "a", tmp_path)
    crash = system_from_spec(command("collision"), criteria=bound).run(worlds["plain"], "task_0", "b", tmp_path)
    assert (clean.verdict, crash.verdict) == ("passed", "failed")  # 1/1's lower bound (0.05) would fail both
    assert crash.reason.startswith("collision with obstacle_")


# -- the planted weakness --------------------------------------------------------------------------------------

def test_the_planted_weakness_fails_only_where_a_person_comes_near_ahead(worlds, tmp_path):
    planted = system_from_spec({"policy": PLANTED, "env": TURNS})
    outside = planted.run(worlds["plain"], "task_0", "run0", tmp_path)
    inside = planted.run(worlds["crossed"], "task_0", "run0", tmp_path)
    assert (outside.verdict, inside.verdict) == ("passed", "failed")
    assert inside.reason == "goal not reached"  # it froze: the time ran out
    # The same follower without the flaw passes the crossed world: the failure is the weakness's.
    sound = system_from_spec({"policy": "worldgen.envs.policies:TimedFollower.for_env", "env": TURNS})
    assert sound.run(worlds["crossed"], "task_0", "run1", tmp_path).verdict == "passed"


# -- specs -----------------------------------------------------------------------------------------------------

def test_systems_are_picklable_values(worlds):
    for spec in ({"policy": FOLLOWER, "env": {"lidar_beams": 90}}, {"drive": {"sim": "mujoco"}}, command("success")):
        system = system_from_spec(spec, criteria={"navigation": {"success_rate": 1.0}})
        assert pickle.loads(pickle.dumps(system)) == system
        hash(system)
    assert SYSTEM_KEYS == {"policy", "env", "drive", "command", "timeout"}


@pytest.mark.parametrize("spec, says", [
    ({"policy": "no_such_module_xyz:make"}, "cannot import module 'no_such_module_xyz'"),
    ({"policy": "worldgen.envs.policies:NoSuchPolicy"}, "has no 'NoSuchPolicy'"),
    ({"policy": "worldgen.envs.policies"}, "must be 'module:factory'"),
    ({"command": "true {world} {task}"}, "{bag}"),
    ({"command": "true {bag} {where}"}, "unknown placeholder {where}"),
    ({"command": "no-such-program-xyz {bag}"}, "not a program"),
    ({"command": "true 'unclosed {bag}"}, "cannot be split"),
    ({"policy": FOLLOWER, "drive": {"sim": "mujoco"}}, "exactly one kind of system (policy, drive, command), got policy and drive"),
    ({}, "got none"),
    ({"policy": FOLLOWER, "seed": 3}, "unknown key 'seed'"),
    ({"policy": FOLLOWER, "timeout": 3}, "'timeout' does not go with policy"),
    ({"policy": FOLLOWER, "env": {"lidar_beams": 0}}, "lidar_beams"),
    ({"policy": FOLLOWER, "env": {"preset": "drl_arena"}}, "'preset' is the campaign's to choose"),
    ({"drive": {"sim": "webots"}}, "system.drive.sim must be one of gazebo, mujoco"),
    ({"command": "true {bag}", "timeout": 0}, "system.timeout must be a number of seconds > 0"),
])
def test_a_bad_spec_is_one_line(spec, says):
    with pytest.raises(ParameterError) as err:
        system_from_spec(spec)
    assert says in str(err.value) and "\n" not in str(err.value)
    assert err.value.exit_status == 2


def test_bad_criteria_are_refused_before_any_run():
    with pytest.raises(ParameterError, match="unknown section 'speed'"):
        system_from_spec({"drive": {"sim": "mujoco"}}, criteria={"speed": {"max": 1}})



@pytest.mark.parametrize("spec", [{"policy": FOLLOWER}, {"drive": {"sim": "mujoco"}}, command("success")])
def test_a_task_the_world_lacks_or_a_folder_without_a_world_is_the_campaigns_mistake(worlds, tmp_path, spec):
    system = system_from_spec(spec)
    with pytest.raises(ParameterError, match=r"must be one of the world's tasks \(task_0\), got 'task_9'"):
        system.run(worlds["plain"], "task_9", "run0", tmp_path)
    with pytest.raises(ParameterError, match=r"is not a world folder \(no world.json\)"):
        system.run(tmp_path, "task_0", "run0", tmp_path)


@pytest.mark.parametrize("spec", [{"policy": FOLLOWER}, {"drive": {"sim": "mujoco"}}])
def test_a_world_written_without_its_mjcf_cannot_run_in_mujoco(tmp_path, spec):
    folder = worldgen.generate("cluttered", seed=0, size=[8, 8], n_obstacles=6).write(tmp_path / "w", formats=["sdf"],
                                                                                       preview=False)
    with pytest.raises(ParameterError, match="no MJCF file|has no mjcf file"):
        system_from_spec(spec).run(Path(folder), "task_0", "run0", tmp_path / "work")


# -- the documented template for the ROS 2 bundle ----------------------------------------------------------

def documented_template() -> dict:
    import yaml

    text = (Path(__file__).resolve().parents[2] / "docs" / "campaigns.md").read_text()
    blocks = [b for b in text.split("```yaml\n")[1:] if "ros2 launch" in b]
    assert len(blocks) == 1, "docs/campaigns.md holds one template for the ROS 2 bundle"
    return yaml.safe_load(blocks[0].split("```")[0])["system"]


@pytest.mark.parametrize("outcome, verdict, reason", [("succeeded", "passed", ""), ("crashed", "unjudged", "exit status 4")])
def test_the_documented_bundle_template_runs_the_launch_file_and_judges_its_bag(tmp_path, monkeypatch, outcome,
                                                                                verdict, reason):
    world = Path(worldgen.generate("cluttered", seed=0, size=[8, 8], n_obstacles=6).write(
        tmp_path / "worlds", preview=False, ros=True))
    launch = list((world / "ros2" / "launch").glob("*.launch.py"))
    assert len(launch) == 1  # the template finds it by this pattern
    stand_in = tmp_path / "bin" / "ros2"
    stand_in.parent.mkdir()
    stand_in.write_text(f"#!/bin/sh\nexec {shlex.quote(sys.executable)} "
                        f"{shlex.quote(str(SCRIPT.parent / 'stand_in_ros2.py'))} \"$@\"\n")
    stand_in.chmod(0o755)
    monkeypatch.setenv("PATH", f"{stand_in.parent}{os.pathsep}{os.environ['PATH']}")
    monkeypatch.setenv("STAND_IN_OUTCOME", outcome)
    system = system_from_spec(documented_template())
    out = system.run(world, "task_0", "run0", tmp_path / "work")
    assert (out.verdict, out.reason) == (verdict, reason)
    bag = tmp_path / "work" / "bags" / f"{world.name}__task_0__run0"
    if verdict == "passed":
        assert out.row["run"] == bag.name and Path(out.row["bag"]) == bag.resolve()
        assert (Path(f"{bag}.out") / f"{bag.name}.result.yaml").is_file()  # beside it, kept for reading
