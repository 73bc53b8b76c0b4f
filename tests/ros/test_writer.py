"""The bag writer class under write_run: open, add a connection per topic, write, close; what it refuses."""

from __future__ import annotations

import pytest

from worldgen.errors import ParameterError

pytest.importorskip("rosbags")


def test_a_bag_written_message_by_message_reads_back(tmp_path):
    from rosbags.highlevel import AnyReader

    from worldgen.ros import BagWriter
    from worldgen.ros.reader import peek_metadata
    from worldgen.ros.writer import WALL_EPOCH_NS

    with BagWriter(tmp_path / "bag", storage="sqlite3", distro="humble", metadata={"worldgen.task": "t1"}) as bag:
        clock = bag.add_connection("/clock")  # the contract's type
        chatter = bag.add_connection("/chatter", "std_msgs/msg/String")
        Time = bag.types["builtin_interfaces/msg/Time"]
        for k in range(3):
            bag.write(clock, WALL_EPOCH_NS + k, bag.types["rosgraph_msgs/msg/Clock"](clock=Time(sec=k, nanosec=0)))
        bag.write(chatter, WALL_EPOCH_NS + 3, bag.types["std_msgs/msg/String"](data="hello"))
    bag.close()  # a second close does nothing
    assert peek_metadata(tmp_path / "bag") == {"worldgen.task": "t1"}
    with AnyReader([tmp_path / "bag"]) as reader:
        assert {c.topic: c.msgtype for c in reader.connections} == {"/clock": "rosgraph_msgs/msg/Clock",
                                                                     "/chatter": "std_msgs/msg/String"}
        got = [(c.topic, t - WALL_EPOCH_NS, reader.deserialize(raw, c.msgtype)) for c, t, raw in reader.messages()]
    assert [(topic, t) for topic, t, _ in got] == [("/clock", 0), ("/clock", 1), ("/clock", 2), ("/chatter", 3)]
    assert got[2][2].clock.sec == 2 and got[3][2].data == "hello"


def test_the_writer_refuses_what_it_cannot_write(tmp_path):
    from worldgen.ros import BagWriter

    with pytest.raises(ParameterError, match="'storage' must be one of sqlite3, mcap"):
        BagWriter(tmp_path / "a", storage="zip")
    with pytest.raises(ParameterError, match="'distro' must be one of humble, jazzy"):
        BagWriter(tmp_path / "a", distro="iron")
    (tmp_path / "taken").mkdir()
    with pytest.raises(ParameterError, match="exists already"):
        BagWriter(tmp_path / "taken")
    bag = BagWriter(tmp_path / "b")
    with pytest.raises(ParameterError, match="not open"):
        bag.add_connection("/clock")
    with bag:
        with pytest.raises(ParameterError, match="'msgtype' is needed for /chatter"):
            bag.add_connection("/chatter")  # the contract does not know it: its type must be given
    assert not (tmp_path / "a").exists()
