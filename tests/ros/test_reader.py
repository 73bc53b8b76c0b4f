"""Reading runs from real ROS 2 bags (written by rosbags, sqlite3 and mcap, Humble and Jazzy definitions).

Each bag records a trajectory known by construction in a small cluttered world, so every figure read
back has an exact reference: the trajectory itself, and the oracles on it.
"""

import math

import numpy as np
import pytest
from support.runs import along, idle_then, small_world, spawn_of, toward, write_bag

from worldgen import oracles
from worldgen.errors import BagError
from worldgen.ros import read_run

pytest.importorskip("rosbags")

STORAGE_DISTRO = [("sqlite3", "humble"), ("sqlite3", "jazzy"), ("mcap", "humble"), ("mcap", "jazzy")]


@pytest.fixture(scope="module")
def world(tmp_path_factory):
    return small_world(tmp_path_factory.mktemp("world"))


def _single_file(folder):
    return next(p for p in folder.iterdir() if p.suffix in (".mcap", ".db3"))


@pytest.mark.parametrize("storage,distro", STORAGE_DISTRO)
def test_a_clean_run_reads_back_exactly_from_the_tf_chain(world, tmp_path, storage, distro):
    truth = along(world)
    bag = write_bag(tmp_path / "run", world, truth, storage=storage, distro=distro)
    for path in (bag, _single_file(bag)):  # the rosbag2 folder and its storage file alone
        run = read_run(path, world)
        assert run.source == "tf" and run.source_detail == "map->odom->base_footprint" and run.drift_bounded
        assert run.start == "command" and run.start_time == pytest.approx(0.0)
        assert run.trajectory.shape == truth.shape
        np.testing.assert_allclose(run.trajectory[:, :3], truth[:, :3], atol=1e-9)
    assert run.metadata == {} or run.metadata["worldgen.task"] == "task_0"  # single files carry no metadata.yaml
    assert read_run(bag, world).metadata["worldgen.task"] == "task_0"
    figures = oracles.run(run.trajectory, world)
    assert figures.reached_goal and not figures.collisions
    goal = np.asarray(oracles.load(world).task()["goal"][:2])
    tol = oracles.load(world).task()["goal_tolerance"]
    first = truth[np.hypot(*(truth[:, 1:3] - goal).T) <= tol][0, 0]
    assert figures.time_to_goal == pytest.approx(first, abs=1e-9)


@pytest.mark.parametrize("storage", ["sqlite3", "mcap"])
def test_idle_time_before_the_drive_is_not_counted_from_the_first_command(world, tmp_path, storage):
    drive = along(world)
    bag = write_bag(tmp_path / "run", world, idle_then(drive, 3.0), storage=storage)
    by_command = read_run(bag, world)
    by_bag = read_run(bag, world, start="bag")
    by_motion = read_run(bag, world, start="motion")
    assert by_command.start_time == pytest.approx(3.0) and by_bag.start_time == pytest.approx(0.0)
    t_cmd = oracles.time_to_goal(by_command.trajectory, world)
    t_bag = oracles.time_to_goal(by_bag.trajectory, world)
    assert t_bag - t_cmd == pytest.approx(3.0, abs=1e-9)
    # motion: the first sample 0.1 m or more from where the robot stood (BARN's clock)
    d = np.hypot(*(drive[:, 1:3] - drive[0, 1:3]).T)
    assert by_motion.start_time == pytest.approx(3.0 + drive[np.argmax(d >= 0.1), 0])


def test_the_goal_sent_starts_the_run_when_asked(world, tmp_path):
    bag = write_bag(tmp_path / "run", world, idle_then(along(world), 2.0), goal=(1.5, 0.0, 0.0, 0.0))
    run = read_run(bag, world, start="goal")
    assert run.start == "goal" and run.start_time == pytest.approx(1.5)
    assert run.trajectory[0, 0] == pytest.approx(1.5) and len(run.trajectory) == len(idle_then(along(world), 2.0)) - 30


def test_a_stamped_command_from_jazzy_nav2_starts_the_run_too(world, tmp_path):
    bag = write_bag(tmp_path / "run", world, idle_then(along(world), 2.0), stamped_cmd=True)
    assert read_run(bag, world).start_time == pytest.approx(2.0)


def test_a_first_command_sent_before_any_clock_is_timed_by_the_next_one(world, tmp_path):
    """worldgen drive in Gazebo commands at time 0, before the first pose and /clock (0.05 s): the unstamped
    Twist is timed by the first clocked message after it. It was timed by its receive time in ns read as s,
    past the bag's end, and the run was judged from its last pose ("the run starts 8.41 m from the spawn")."""
    drive = along(world)
    commands = np.vstack([[0.0, 0.5, 0.0], np.column_stack([drive[1:, 0], np.full(len(drive) - 1, 0.5),
                                                          np.zeros(len(drive) - 1)])])
    bag = write_bag(tmp_path / "run", world, drive[1:], commands=commands)
    run = read_run(bag, world)
    assert run.start_time == pytest.approx(drive[1, 0]) and len(run.trajectory) == len(drive) - 1


@pytest.mark.parametrize("storage,distro", [("sqlite3", "humble"), ("mcap", "jazzy")])
def test_drifting_odometry(world, tmp_path, storage, distro):
    truth = along(world)
    drift = 0.05  # rad of heading error per metre driven
    # With the localisation's map -> odom on /tf, the chain gives the truth however the odometry drifts.
    tf_bag = write_bag(tmp_path / "tf", world, truth, drift=drift, storage=storage, distro=distro)
    run = read_run(tf_bag, world)
    assert run.source == "tf"
    np.testing.assert_allclose(run.trajectory[:, :3], truth[:, :3], atol=1e-9)
    # A simulator's ground-truth topic wins over everything else.
    gt_bag = write_bag(tmp_path / "gt", world, truth, drift=drift, storage=storage, distro=distro,
                       topics=("clock", "odom", "tf", "cmd_vel", "ground_truth"))
    run = read_run(gt_bag, world)
    assert run.source == "ground_truth" and run.source_detail == "/ground_truth"
    np.testing.assert_allclose(run.trajectory[:, :3], truth[:, :3], atol=1e-9)
    # /odom alone: composed with the spawn, it drifts, and the run says so.
    odom_bag = write_bag(tmp_path / "odom", world, truth, drift=drift, storage=storage, distro=distro,
                         topics=("clock", "odom", "cmd_vel"))
    run = read_run(odom_bag, world)
    assert run.source == "odom" and not run.drift_bounded and "unbounded drift" in run.source_detail
    # Reference: the odometry turns the motion since the spawn by drift * distance driven so far.
    sx, sy, syaw = spawn_of(world)
    travelled = np.concatenate([[0.0], np.cumsum(np.hypot(*np.diff(truth[:, 1:3], axis=0).T))])
    dx, dy = truth[:, 1] - sx, truth[:, 2] - sy
    lx, ly = math.cos(syaw) * dx + math.sin(syaw) * dy, -math.sin(syaw) * dx + math.cos(syaw) * dy
    b = drift * travelled
    ox, oy = np.cos(b) * lx - np.sin(b) * ly, np.sin(b) * lx + np.cos(b) * ly
    expect_x = sx + math.cos(syaw) * ox - math.sin(syaw) * oy
    expect_y = sy + math.sin(syaw) * ox + math.cos(syaw) * oy
    np.testing.assert_allclose(run.trajectory[:, 1], expect_x, atol=1e-9)
    np.testing.assert_allclose(run.trajectory[:, 2], expect_y, atol=1e-9)
    # No /odom and no localisation: the odom -> base transform is the odometry, with the same drift.
    tf_only = write_bag(tmp_path / "tf_only", world, truth, drift=drift, storage=storage, distro=distro,
                        topics=("clock", "tf", "cmd_vel"), map_odom=False)
    alone = read_run(tf_only, world)
    assert alone.source == "odom" and alone.source_detail == "/tf odom->base_footprint + spawn (unbounded drift)"
    np.testing.assert_allclose(alone.trajectory[:, 1:3], run.trajectory[:, 1:3], atol=1e-12)
    end_error = math.hypot(run.trajectory[-1, 1] - truth[-1, 1], run.trajectory[-1, 2] - truth[-1, 2])
    assert end_error > 0.1  # the drift is visible: 0.05 rad/m over a few metres


def test_a_collision_run_reads_back_with_its_contact(world, tmp_path):
    meta = oracles.load(world).meta
    obstacle = next(e for e in meta["entities"] if e["role"] == "obstacle")
    truth = toward(world, obstacle["pose"][:2])
    run = read_run(write_bag(tmp_path / "run", world, truth, storage="mcap"), world)
    contacts = oracles.collisions(run.trajectory, world)
    assert obstacle["name"] in {c.entity for c in contacts}
    assert [(c.time, c.entity) for c in contacts] == [(c.time, c.entity) for c in oracles.collisions(truth, world)]


def test_a_missing_topic_is_one_line_naming_the_topics_found(world, tmp_path):
    no_cmd = write_bag(tmp_path / "nocmd", world, along(world), topics=("clock", "odom", "tf"))
    with pytest.raises(BagError) as err:
        read_run(no_cmd, world)
    msg = str(err.value)
    assert "\n" not in msg and "needs /cmd_vel" in msg and "/odom (nav_msgs/msg/Odometry)" in msg and "/tf " in msg
    assert read_run(no_cmd, world, start="bag").source == "tf"  # the bag's start needs no command
    no_pose = write_bag(tmp_path / "nopose", world, along(world), topics=("clock", "cmd_vel"))
    with pytest.raises(BagError, match=r"no pose source: need /ground_truth, /tf with map->odom->base_footprint"
                                             r"\|base_link, or /odom; topics found: /clock \(rosgraph_msgs/msg/Clock\), "
                                             r"/cmd_vel \(geometry_msgs/msg/Twist\)$"):
        read_run(no_pose, world)
    with pytest.raises(BagError, match="start='goal' needs a goal topic"):
        read_run(write_bag(tmp_path / "nogoal", world, along(world)), world, start="goal")


@pytest.mark.parametrize("storage", ["sqlite3", "mcap"])
def test_a_truncated_file_is_one_line(world, tmp_path, storage):
    bag = write_bag(tmp_path / "run", world, along(world), storage=storage)
    data = _single_file(bag)
    data.write_bytes(data.read_bytes()[: data.stat().st_size // 2])
    for path in (bag, data):
        with pytest.raises(BagError) as err:
            read_run(path, world)
        assert "\n" not in str(err.value) and "cannot be read as a ROS bag" in str(err.value)
        assert str(err.value).startswith(f"bag '{path}'")


def test_a_run_that_does_not_start_at_the_spawn_names_the_distance(world, tmp_path):
    truth = along(world)
    moved = truth.copy()
    moved[:, 1] += 0.6
    moved[:, 2] += 0.8  # 1.00 m away
    bag = tmp_path / "run"
    from worldgen.ros import write_run
    write_run(bag, moved, spawn=tuple(moved[0, 1:4]), world_id="elsewhere")  # odometry zeroed where it really started
    from worldgen.ros import RunMismatchError
    with pytest.raises(RunMismatchError) as err:  # a BagError: read, but not this task's run
        read_run(bag, world)
    msg = str(err.value)
    assert "\n" not in msg and "the run starts 1.00 m from the task's spawn" in msg and "spawn_tolerance 0.25 m" in msg
    assert read_run(bag, world, spawn_tolerance=1.5).source == "tf"
    assert read_run(bag).start_time == pytest.approx(0.0)  # without a world there is no spawn to check against


def test_mcap_bags_decode_with_the_official_mcap_reader(world, tmp_path):
    """The reference reader (mcap with mcap-ros2-support) decodes every message from the definitions the bag carries."""
    mcap_reader = pytest.importorskip("mcap.reader")
    decoder = pytest.importorskip("mcap_ros2.decoder")
    truth = along(world)
    for distro in ("humble", "jazzy"):
        bag = write_bag(tmp_path / distro, world, truth, storage="mcap", distro=distro,
                        topics=("clock", "odom", "tf", "cmd_vel", "ground_truth"))
        counts: dict = {}
        poses = []
        with _single_file(bag).open("rb") as f:
            reader = mcap_reader.make_reader(f, decoder_factories=[decoder.DecoderFactory()])
            assert reader.get_header().profile == "ros2"
            for schema, channel, message, msg in reader.iter_decoded_messages():
                assert schema.encoding == "ros2msg" and channel.message_encoding == "cdr"
                counts[channel.topic] = counts.get(channel.topic, 0) + 1
                if channel.topic == "/ground_truth":
                    poses.append((msg.header.stamp.sec + msg.header.stamp.nanosec * 1e-9, msg.pose.pose.position.x,
                                  msg.pose.pose.position.y))
        n = len(truth)
        assert counts == {"/clock": n, "/odom": n, "/tf": n, "/cmd_vel": n, "/ground_truth": n, "/tf_static": 1}
        np.testing.assert_allclose(np.array(poses), truth[:, :3], atol=1e-9)


def test_reading_needs_rosbags_and_says_what_to_install(monkeypatch, tmp_path):
    import sys

    from worldgen.errors import MissingDependencyError
    monkeypatch.setitem(sys.modules, "rosbags", None)
    with pytest.raises(MissingDependencyError, match=r"pip install 'worldgen\[ros\]'$"):
        read_run(tmp_path / "x")


def test_a_bag_without_message_definitions_reads_with_the_release_typestore(world, tmp_path):
    """Humble's sqlite3 recorder stores no message definitions: the reader falls back to the release's types."""
    import sqlite3

    truth = along(world)
    bag = write_bag(tmp_path / "run", world, truth, storage="sqlite3", distro="humble")
    db = _single_file(bag)
    with sqlite3.connect(db) as conn:
        conn.execute("DELETE FROM message_definitions")
        conn.execute("UPDATE topics SET type_description_hash = ''")
    for distro in ("humble", None):
        run = read_run(bag, world, distro=distro)
        assert run.source == "tf"
        np.testing.assert_allclose(run.trajectory[:, :3], truth[:, :3], atol=1e-9)


# -- bags holding no pose topic, like ROS 2's own test bags: refused by their topic list alone -------------

_EVENT = """\
service_msgs/msg/ServiceEventInfo info
test_msgs/msg/BasicTypes_Request[<=1] request
test_msgs/msg/BasicTypes_Response[<=1] response
"""


def _foreign_bag(path, kind: str, storage: str):
    """A bag as rosbag2's own tests record them: /rosout only, a std_msgs/String chatter, or service events."""
    from rosbags.rosbag2 import StoragePlugin, Writer
    from rosbags.typesys import Stores, get_types_from_msg, get_typestore

    store = get_typestore(Stores.ROS2_JAZZY)
    if kind == "events":
        fields = "bool bool_value\nint32 int32_value\nstring string_value\n"
        types = get_types_from_msg(fields, "test_msgs/msg/BasicTypes_Request")
        types |= get_types_from_msg(fields, "test_msgs/msg/BasicTypes_Response")
        (event,) = get_types_from_msg(_EVENT, "test_msgs/msg/BasicTypes_Event").values()
        store.register(types | {"test_msgs/srv/BasicTypes_Event": event})  # the name rosbag2 records
    plugin = StoragePlugin.MCAP if storage == "mcap" else StoragePlugin.SQLITE3
    with Writer(path, version=9, storage_plugin=plugin) as writer:
        for k in range(5):
            if kind == "rosout":
                Log, Time = store.types["rcl_interfaces/msg/Log"], store.types["builtin_interfaces/msg/Time"]
                msg, topic = Log(stamp=Time(sec=k, nanosec=0), level=20, name="talker", msg=f"hello {k}", file="t.cpp",
                                 function="main", line=k), "/rosout"
            elif kind == "string":
                msg, topic = store.types["std_msgs/msg/String"](data=f"hello {k}"), "/chatter"
            else:
                T = store.types
                info = T["service_msgs/msg/ServiceEventInfo"](
                    event_type=0, stamp=T["builtin_interfaces/msg/Time"](sec=k, nanosec=0), client_gid=np.zeros(16, np.uint8),
                    sequence_number=k)
                req = T["test_msgs/msg/BasicTypes_Request"](bool_value=True, int32_value=k, string_value="x")
                msg, topic = T["test_msgs/srv/BasicTypes_Event"](info=info, request=[req], response=[]), \
                    "/test_service/_service_event"
            if k == 0:
                conn = writer.add_connection(topic, msg.__msgtype__, typestore=store)
            writer.write(conn, k * 10**9, store.serialize_cdr(msg, msg.__msgtype__))
    return path


@pytest.mark.parametrize("kind,topic", [("rosout", "/rosout (rcl_interfaces/msg/Log)"),
                                        ("string", "/chatter (std_msgs/msg/String)"),
                                        ("events", "/test_service/_service_event (test_msgs/srv/BasicTypes_Event)")])
@pytest.mark.parametrize("storage", ["sqlite3", "mcap"])
def test_a_bag_without_a_pose_topic_is_refused_by_its_topic_list_without_decoding(world, tmp_path, monkeypatch,
                                                                                  kind, topic, storage):
    from rosbags.highlevel import AnyReader

    from worldgen.ros import bagio

    bag = _foreign_bag(tmp_path / kind, kind, storage)
    calls = {"messages": 0, "decoder": 0}
    messages, decoder = AnyReader.messages, bagio.decoder

    def counted_messages(self, *a, **kw):
        calls["messages"] += 1
        return messages(self, *a, **kw)

    def counted_decoder(*a, **kw):
        calls["decoder"] += 1
        return decoder(*a, **kw)

    monkeypatch.setattr(AnyReader, "messages", counted_messages)
    monkeypatch.setattr("worldgen.ros.reader.decoder", counted_decoder)
    for start in ("command", "bag"):
        with pytest.raises(BagError) as err:
            read_run(bag, world, start=start)
        message = str(err.value)
        assert "\n" not in message and message.startswith(f"bag '{bag}': no pose source: need /ground_truth")
        assert message.endswith(f"topics found: {topic}")
    assert calls == {"messages": 0, "decoder": 0}
