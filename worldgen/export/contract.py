"""The contract between worldgen, Gazebo and ROS 2, in two tables: Gazebo's releases and the run's topics.

    >>> from worldgen.export.contract import GROUND_TRUTH, release
    >>> harmonic = release("harmonic")
    >>> harmonic.plugin("diff-drive", "DiffDrive"), harmonic.msg(GROUND_TRUTH.gz_type)
    (('gz-sim-diff-drive-system', 'gz::sim::systems::DiffDrive'), 'gz.msgs.Odometry')
    >>> GROUND_TRUTH.name, GROUND_TRUTH.ros_type, GROUND_TRUTH.gz_topic
    ('/ground_truth', 'nav_msgs/msg/Odometry', '/ground_truth/odom')

Everything that names a release's plugins, its server command or its message package, and every
module that spells a topic of a run (the robot's SDF, the ROS 2 bundle's bridge and recorder, the bag
writer, the bag reader's defaults, the Gazebo drive, ``worldgen judge``'s options) reads them here, so
a topic or a release is renamed in one place (tests/test_layout.py holds that no other module spells
them). The tables sit in ``export/`` because the first reader is an exporter (robot.sdf); every room
after it may import them.

Gazebo releases (gz-sim's and ign-gazebo's ``server.config`` for the plugin names, their ``cmdsim.rb``
for the command line): Fortress (ROS 2 Humble's pair) keeps the ignition names; Garden and later use
the gz ones. :data:`DEFAULT_GZ_RELEASE` is what a bundle and a robot are written for unless told
otherwise; :data:`SIM_GZ_RELEASES` are the releases ``worldgen.sim`` runs and the Gazebo tests run in
(:data:`SIM_GZ_RELEASE`, the first, unless told otherwise); the C++ drive bridge is compiled against the
transport of the one it runs.

The ground truth is ``nav_msgs/msg/Odometry`` on ``/ground_truth``: the robot's OdometryPublisher
publishes the model's world pose (= the map frame's) both as ``Odometry`` on ``ground_truth/odom`` and as
``Pose_V`` on its ``tf_topic``; the Odometry one is the topic ``worldgen drive`` reads from Gazebo, one
pose per message with its frames (``map`` -> ``base_footprint``) and its twist, which ros_gz_bridge
converts to nav_msgs/Odometry in every release. The bag reader still takes a TFMessage, a pose or a
transform on the pose topic, from bags recorded with other bridges.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Optional

from worldgen.errors import ParameterError

__all__ = ["GzRelease", "GZ_RELEASES", "DEFAULT_GZ_RELEASE", "SIM_GZ_RELEASE", "SIM_GZ_RELEASES",
           "release", "release_of_version", "DOOR_OPENER", "DOOR_COMMAND_TOPIC", "WORLD_SYSTEMS",
           "Topic", "TOPICS", "CLOCK", "GROUND_TRUTH", "CONTACTS", "CMD_VEL", "ODOM", "TF", "TF_STATIC", "SCAN", "IMU",
           "JOINT_STATES", "GOAL_POSE", "NAV_FEEDBACK", "NAV_STATUS", "CMD_VEL_STAMPED_TYPE", "GZ_TO_ROS", "ROS_TO_GZ",
           "BRIDGED", "RECORDED", "topic"]


@dataclass(frozen=True)
class GzRelease:
    """One Gazebo release: how it names a system's plugin, its message package, its tools and variables."""

    name: str
    plugin_file: str        # a system's library, ``{}`` the system's file stem (``diff-drive``)
    plugin_class: str       # a system's class, ``{}`` its class name (``DiffDrive``)
    msgs: str               # the message package (``gz.msgs.Odometry``)
    cli: str                # the command-line tool (``gz topic``, ``gz service``)
    server: tuple[str, ...]  # the simulator's command (run without a shell: a shell does not pass SIGINT on)
    seed: bool              # whether the server takes ``--seed`` (gz-sim 8's cmdsim.rb has it; 7 and ign 6 not)
    plugin_path_var: str    # where the server looks for system plugins
    partition_var: str      # the transport partition: processes in different partitions never see each other
    major: int              # the server's major version (``gz sim --versions`` 8.x is Harmonic)
    transport: tuple[str, ...]  # pkg-config names of its transport and message libraries (the drive bridge)
    cxx: str                # those libraries' C++ namespace and header folder
    discovery_vars: tuple[str, str]  # the transport's discovery ports (messages, services)
    home: str               # the folder the server writes under $HOME (server.config, logs)

    def plugin(self, file_stem: str, class_name: str) -> tuple[str, str]:
        """``(filename, name)`` of a system's ``<plugin>`` element in this release."""
        return self.plugin_file.format(file_stem), self.plugin_class.format(class_name)

    def door_opener(self) -> tuple[str, str]:
        """``(filename, name)`` of the system ``worldgen drive`` swings a pull door's leaf open with
        (:data:`DOOR_OPENER`), and its shared library's file name is ``lib<filename>.so``."""
        return self.plugin(*DOOR_OPENER)

    def msg(self, short: str) -> str:
        """The full Gazebo message type of ``short`` (``Odometry`` -> ``gz.msgs.Odometry``)."""
        return f"{self.msgs}.{short}"


# ign-transport and gz-transport read their discovery ports from these (their NodeShared.cc); both default to
# 10317 and 10318 on one multicast group with one wire version (10), whatever the partition.
_IGN_DISCOVERY = ("IGN_DISCOVERY_MSG_PORT", "IGN_DISCOVERY_SRV_PORT")
_GZ_DISCOVERY = ("GZ_DISCOVERY_MSG_PORT", "GZ_DISCOVERY_SRV_PORT")

#: Every release worldgen writes for, one row each, oldest first.
GZ_RELEASES: dict[str, GzRelease] = {r.name: r for r in (
    GzRelease("fortress", "ignition-gazebo-{}-system", "ignition::gazebo::systems::{}", "ignition.msgs", "ign",
              ("ign", "gazebo"), False, "IGN_GAZEBO_SYSTEM_PLUGIN_PATH", "IGN_PARTITION", 6,
              ("ignition-transport11", "ignition-msgs8"), "ignition", _IGN_DISCOVERY, ".ignition"),
    GzRelease("garden", "gz-sim-{}-system", "gz::sim::systems::{}", "gz.msgs", "gz",
              ("gz", "sim"), False, "GZ_SIM_SYSTEM_PLUGIN_PATH", "GZ_PARTITION", 7,
              ("gz-transport12", "gz-msgs9"), "gz", _GZ_DISCOVERY, ".gz"),
    GzRelease("harmonic", "gz-sim-{}-system", "gz::sim::systems::{}", "gz.msgs", "gz",
              ("gz", "sim"), True, "GZ_SIM_SYSTEM_PLUGIN_PATH", "GZ_PARTITION", 8,
              ("gz-transport13", "gz-msgs10"), "gz", _GZ_DISCOVERY, ".gz"),
    GzRelease("ionic", "gz-sim-{}-system", "gz::sim::systems::{}", "gz.msgs", "gz",
              ("gz", "sim"), True, "GZ_SIM_SYSTEM_PLUGIN_PATH", "GZ_PARTITION", 9,
              ("gz-transport14", "gz-msgs11"), "gz", _GZ_DISCOVERY, ".gz"),
)}
#: The joint system that opens a pull door in ``worldgen drive --sim gazebo`` (file stem, class): a position
#: controller on the hinge, its target sent over :data:`DOOR_COMMAND_TOPIC`. Every release's row names it
#: (:meth:`GzRelease.door_opener`); a build may still lack it (the Fortress 6.18 build of shared/gazebo does:
#: worldgen.sim.gazebo_doors looks for the library on the install's plugin path).
DOOR_OPENER = ("joint-position-controller", "JointPositionController")
#: The controller's target angle (a Double, rad from the joint's zero) for ``{joint}`` of model ``{model}``: the
#: controller's own default topic in ign-gazebo 6 and gz-sim 8, written into its ``<topic>`` all the same.
DOOR_COMMAND_TOPIC = "/model/{model}/joint/{joint}/0/cmd_pos"
#: The world systems a server loads from its ``server.config`` when the world names none (file stem, class), the
#: same in every release here. ign-gazebo 6.7 also drops them when only a model names a plugin (measured: no
#: physics, no scene service), so a world given a door opener names them itself.
WORLD_SYSTEMS = (("physics", "Physics"), ("user-commands", "UserCommands"), ("scene-broadcaster", "SceneBroadcaster"))
#: Harmonic pairs with ROS 2 Jazzy, the current LTS pair: what a bundle and a robot are written for by default.
DEFAULT_GZ_RELEASE = "harmonic"
#: What ``worldgen.sim`` runs unless told otherwise: Fortress (ign-gazebo 6), the suite's default install;
#: the drive bridge is compiled against the transport and message libraries of the release it runs.
SIM_GZ_RELEASE = "fortress"
#: The releases ``worldgen.sim`` runs and the Gazebo tests run in, :data:`SIM_GZ_RELEASE` first.
SIM_GZ_RELEASES = ("fortress", "harmonic")


def release(name: str) -> GzRelease:
    """The row of the release ``name``; ParameterError naming the releases for any other name."""
    if name not in GZ_RELEASES:
        raise ParameterError(f"parameter 'gz_release' must be one of {', '.join(GZ_RELEASES)}, got {name!r}")
    return GZ_RELEASES[name]


def release_of_version(version: str) -> GzRelease:
    """The row of a server that says it is ``version`` (``6.18.0``: Fortress); ParameterError for none."""
    major = version.split(".")[0]
    for row in GZ_RELEASES.values():
        if str(row.major) == major:
            return row
    raise ParameterError(f"Gazebo {version} is none of the releases worldgen knows ({', '.join(GZ_RELEASES)})")


#: ros_gz_bridge's directions (its README's YAML keys).
GZ_TO_ROS, ROS_TO_GZ = "GZ_TO_ROS", "ROS_TO_GZ"


@dataclass(frozen=True)
class Topic:
    """One topic of a run: its ROS name and type, the Gazebo topic and type it is bridged from or to (None:
    ROS's own, not bridged), the bridge's direction, and whether ``ros2 bag record`` keeps it."""

    name: str
    ros_type: str
    gz_type: Optional[str]
    gz_topic: Optional[str]
    direction: Optional[str]
    recorded: bool

    @property
    def gazebo_topic(self) -> str:
        """The Gazebo topic; ParameterError for a topic of ROS's own."""
        if self.gz_topic is None:
            raise ParameterError(f"topic {self.name} is ROS's own: it has no Gazebo topic")
        return self.gz_topic

    @property
    def gz_name(self) -> str:
        """The Gazebo topic as a model's SDF names it (relative: Gazebo puts it under ``/``)."""
        return self.gazebo_topic.lstrip("/")


CLOCK = Topic("/clock", "rosgraph_msgs/msg/Clock", "Clock", "/clock", GZ_TO_ROS, True)
GROUND_TRUTH = Topic("/ground_truth", "nav_msgs/msg/Odometry", "Odometry", "/ground_truth/odom", GZ_TO_ROS, True)
CONTACTS = Topic("/contacts", "ros_gz_interfaces/msg/Contacts", "Contacts", "/contacts", GZ_TO_ROS, True)
CMD_VEL = Topic("/cmd_vel", "geometry_msgs/msg/Twist", "Twist", "/cmd_vel", ROS_TO_GZ, True)
ODOM = Topic("/odom", "nav_msgs/msg/Odometry", "Odometry", "/odom", GZ_TO_ROS, True)
TF = Topic("/tf", "tf2_msgs/msg/TFMessage", "Pose_V", "/tf", GZ_TO_ROS, True)
TF_STATIC = Topic("/tf_static", "tf2_msgs/msg/TFMessage", None, None, None, True)
SCAN = Topic("/scan", "sensor_msgs/msg/LaserScan", "LaserScan", "/scan", GZ_TO_ROS, True)
IMU = Topic("/imu", "sensor_msgs/msg/Imu", "IMU", "/imu", GZ_TO_ROS, False)
JOINT_STATES = Topic("/joint_states", "sensor_msgs/msg/JointState", "Model", "/joint_states", GZ_TO_ROS, False)
#: The goal as RViz and nav2's goal topic carry it.
GOAL_POSE = Topic("/goal_pose", "geometry_msgs/msg/PoseStamped", None, None, None, False)
#: nav2's navigate_to_pose action as recorded (hidden topics): the status says when the goal was accepted.
NAV_FEEDBACK = Topic("/navigate_to_pose/_action/feedback", "nav2_msgs/action/NavigateToPose_FeedbackMessage",
                     None, None, None, False)
NAV_STATUS = Topic("/navigate_to_pose/_action/status", "action_msgs/msg/GoalStatusArray", None, None, None, True)
#: ``/cmd_vel``'s type when the controller stamps its commands (Jazzy's nav2 may: ``enable_stamped_cmd_vel``).
CMD_VEL_STAMPED_TYPE = "geometry_msgs/msg/TwistStamped"

#: Every topic of a run.
TOPICS: tuple[Topic, ...] = (CLOCK, GROUND_TRUTH, CONTACTS, CMD_VEL, ODOM, TF, TF_STATIC, SCAN, IMU, JOINT_STATES,
                             GOAL_POSE, NAV_FEEDBACK, NAV_STATUS)
#: What ros_gz_bridge carries between Gazebo and ROS.
BRIDGED: tuple[Topic, ...] = tuple(t for t in TOPICS if t.direction is not None)
#: What ``ros2 bag record`` keeps: what ``worldgen judge`` reads, and the contacts.
RECORDED: tuple[Topic, ...] = tuple(t for t in TOPICS if t.recorded)


def topic(name: str) -> Topic:
    """The row of the ROS topic ``name``."""
    for t in TOPICS:
        if t.name == name:
            return t
    raise ParameterError(f"topic must be one of {', '.join(t.name for t in TOPICS)}, got {name!r}")
