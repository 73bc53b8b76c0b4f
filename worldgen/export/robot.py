"""A differential-drive robot sized to a world's footprint: ``robot.sdf`` for Gazebo, and the parts
``robot.urdf`` for ROS shares with it (:mod:`worldgen.export.robot_urdf` writes that).

    >>> import worldgen
    >>> from worldgen.export.robot import robot_sdf
    >>> from worldgen.export.robot_urdf import robot_urdf
    >>> world = worldgen.generate("cluttered", seed=0, size=[6, 6], n_obstacles=4)
    >>> sdf = robot_sdf(world)                       # spawn it with Gazebo's create service
    >>> '<model name="robot">' in sdf, "<topic>cmd_vel</topic>" in sdf
    (True, True)
    >>> robot_urdf(world).count("<link ")            # base_footprint, base_link, 2 wheels, 2 casters, lidar, imu
    8

Every number comes from the world's one robot description
(:func:`worldgen.groundtruth.folder.robot_description_of`, the one the environment and ``worldgen drive``
in MuJoCo build from too): the body is world.json's ``robot`` footprint, a cylinder of ``radius`` whose top
is at ``height``, of the description's mass; everything else sits inside it. Two drive wheels on the y axis and two
frictionless caster spheres (front and back) carry it; the chassis' collision starts a caster
radius above the floor, so only wheels and casters touch it. Frames: the model's frame is
``base_footprint`` (on the floor under the centre: the pose a spawn and world.json give),
``base_link`` sits on the wheel axis above it, ``base_scan`` at world.json's lidar height and
``imu_link`` at the centre of the chassis.

Gazebo systems on the model (its own topics, as nav2 expects them, not gz-sim's
``/model/<name>/...`` defaults): DiffDrive takes ``cmd_vel`` and publishes ``odom`` and ``tf``
(``odom`` -> ``base_footprint``, starting at zero at the spawn) and holds the robot to its motion
limits (speed, turn rate and acceleration: world.json's ``robot.max_speed``, ``max_turn_rate``,
``max_acceleration``, their documented defaults where a world states none); OdometryPublisher publishes the
ground truth, the model's pose in the world frame (= the map frame), on ``ground_truth/odom``
(``map`` -> ``base_footprint``), the topic the ROS 2 bundle bridges as ``/ground_truth``, and the
same pose on its ``tf_topic``, ``/model/<name>/pose``. Every topic name and the release's plugin
names come from :mod:`worldgen.export.contract`. Sensors: a ``gpu_lidar`` on ``scan`` whose rays are
world.json's ``sensors.lidar`` (samples, angles, range_min, range_max, height) with optional
Gaussian noise, and an IMU on ``imu``. The lidar sits inside the footprint cylinder, as world.json
puts it; the chassis' visual leaves a window around its plane so the lidar never sees the robot.

The URDF is the same tree for robot_state_publisher and RViz (links, joints, inertias,
geometry); Gazebo spawns the SDF. Both are bytes-stable: same world and arguments, same text.
(``robot_urdf``, ``Dimensions`` and ``dimensions`` are still importable from here.)
"""

from __future__ import annotations

import math
from collections.abc import Mapping

from lxml import etree

from worldgen.errors import ParameterError
from worldgen.export.contract import CMD_VEL, DEFAULT_GZ_RELEASE, GROUND_TRUTH, IMU, JOINT_STATES, ODOM, SCAN, TF, release
from worldgen.export.robot_body import COLOUR, DEFAULT_NAME, Dimensions, chassis, described, dimensions, inertia_cylinder, parts
from worldgen.export.robot_urdf import robot_urdf
from worldgen.export.xml import sub, to_bytes
from worldgen.floats import fmt, fmt_seq
from worldgen.scene.robot import LidarDescription, RobotDescription

__all__ = ["DEFAULT_NAME", "SENSOR_FRAME_ELEMENT", "LIDAR_WINDOW", "CASTER_SPRING", "CASTER_DAMPING", "CASTER_TRAVEL",
           "CASTER_PRELOAD", "Dimensions", "dimensions", "robot_sdf", "robot_urdf"]

#: The element Gazebo's sensors take their message frame from. Without it a scan's frame is the scoped
#: sensor name (``robot::base_scan::lidar``, measured in Fortress 6.18), a frame no URDF has, and AMCL and
#: the costmaps drop the scans. ``gz_frame_id`` is read by Fortress 6.18's ign-sensors (beside its older
#: ``ignition_frame_id``) and is the only element gz-sensors 8 (Harmonic) reads (measured in 8.14: without it
#: the scan's frame is the scoped name): one element serves every release. It is a Gazebo extension, not
#: SDFormat, so a strict libsdformat check flags it and sdformat 14 warns about it on every spawn (the
#: Gazebo harness knows that warning: worldgen.sim.gazebo_log.SENSOR_FRAME_NOTE).
SENSOR_FRAME_ELEMENT = "gz_frame_id"
#: Half-height (m) of the gap the chassis' visual leaves around the lidar's plane: what a gpu_lidar
#: renders is visuals, and SDFormat 1.9 has no visibility mask for a lidar, so the window keeps the
#: robot out of its own scan (the collision cylinder is whole).
LIDAR_WINDOW = 0.01
#: On terrain only, the casters' suspension: stiffness (N/m), damping (N s/m), travel either way and
#: preload (m, how far below the wheels' ground the spring would rest). Stiff enough that the body pitches
#: a few degrees under the DiffDrive's acceleration, soft enough that a caster lifted 2 cm by a ramp's
#: foot leaves most of the weight on the wheels.
CASTER_SPRING, CASTER_DAMPING, CASTER_TRAVEL, CASTER_PRELOAD = 5000.0, 100.0, 0.03, 0.003


def _on_terrain(world) -> bool:
    """Whether ``world`` (a World or world.json) has terrain; a description alone is of a flat world's robot."""
    if isinstance(world, RobotDescription):
        return False
    return bool((world if isinstance(world, Mapping) else world.metadata).get("terrain"))


def _sdf_inertial(link, mass: float, diag, pose: str = "0 0 0 0 0 0") -> None:
    inertial = sub(link, "inertial")
    sub(inertial, "pose", pose)
    sub(inertial, "mass", fmt(mass))
    inertia = sub(inertial, "inertia")
    for key, value in zip(("ixx", "iyy", "izz"), diag):
        sub(inertia, key, fmt(value))
    for key in ("ixy", "ixz", "iyz"):
        sub(inertia, key, "0")


def _sdf_shape(parent, kind: str, name: str, shape: tuple, pose: str, mu: float | None = None) -> None:
    el = sub(parent, kind, name=name)
    sub(el, "pose", pose)
    geometry = sub(el, "geometry")
    if shape[0] == "cylinder":
        cyl = sub(geometry, "cylinder")
        sub(cyl, "radius", fmt(shape[1]))
        sub(cyl, "length", fmt(shape[2]))
    else:
        sub(sub(geometry, "sphere"), "radius", fmt(shape[1]))
    if kind == "visual":
        material = sub(el, "material")
        sub(material, "ambient", COLOUR)
        sub(material, "diffuse", COLOUR)
    elif mu is not None:
        ode = sub(sub(sub(el, "surface"), "friction"), "ode")
        sub(ode, "mu", fmt(mu))
        sub(ode, "mu2", fmt(mu))


def _visual_bands(d: Dimensions) -> list[tuple[float, float]]:
    """(bottom, top) above the floor of each piece of the chassis' visual: whole, or cut by the lidar window."""
    low, high = d.lidar_height - LIDAR_WINDOW, d.lidar_height + LIDAR_WINDOW
    if low <= d.chassis_bottom or high >= d.height:
        return [(d.chassis_bottom, d.height)]
    return [(d.chassis_bottom, low), (high, d.height)]


def _sdf_links(model, d: Dimensions, mass: float) -> None:
    length, zc = chassis(d)
    base = sub(model, "link", name="base_link")
    sub(base, "pose", fmt_seq((0, 0, d.wheel_radius, 0, 0, 0)))
    _sdf_inertial(base, mass, inertia_cylinder(mass, d.radius, length), fmt_seq((0, 0, zc, 0, 0, 0)))
    _sdf_shape(base, "collision", "chassis_collision", ("cylinder", d.radius, length), fmt_seq((0, 0, zc, 0, 0, 0)))
    for k, (low, high) in enumerate(_visual_bands(d)):
        _sdf_shape(base, "visual", f"chassis_visual_{k}", ("cylinder", d.radius, high - low),
                   fmt_seq((0, 0, (low + high) / 2.0 - d.wheel_radius, 0, 0, 0)))
    for name, joint, xyz, shape, mass, mu in parts(d):
        link = sub(model, "link", name=name)
        # A wheel's cylinder axis (its z) turns onto the model's y axis.
        roll = -math.pi / 2 if shape[0] == "cylinder" else 0.0
        sub(link, "pose", fmt_seq((xyz[0], xyz[1], xyz[2] + d.wheel_radius, roll, 0, 0)))
        diag = inertia_cylinder(mass, shape[1], shape[2]) if shape[0] == "cylinder" else (0.4 * mass * shape[1] ** 2,) * 3
        _sdf_inertial(link, mass, diag)
        # A wheel touches the floor as the sphere of its radius: DART (Fortress and Harmonic alike) touched a lying
        # cylinder at one end of its width, the same end for both wheels, and the robot turned on the spot about a
        # point 2 cm (half a wheel's width) to one side of its centre (docs/drive.md, barn seed 22).
        touching = ("sphere", shape[1]) if shape[0] == "cylinder" else shape
        _sdf_shape(link, "collision", "collision", touching, "0 0 0 0 0 0", mu)
        _sdf_shape(link, "visual", "visual", shape, "0 0 0 0 0 0")
        j = sub(model, "joint", name=f"{name}_joint", type=joint)
        sub(j, "parent", "base_link")
        sub(j, "child", name)
        if joint == "revolute":
            # In the wheel's frame (turned -90 deg about x) its z axis is the model's +y: forward is +rotation.
            axis = sub(j, "axis")
            sub(axis, "xyz", "0 0 1")


def _sdf_sensors(model, d: Dimensions, lidar: LidarDescription, lidar_noise: float, lidar_rate: float) -> None:
    scan_link = sub(model, "link", name="base_scan")
    sub(scan_link, "pose", fmt_seq((0, 0, d.lidar_height, 0, 0, 0)))
    _sdf_inertial(scan_link, 0.01, (1e-5, 1e-5, 1e-5))
    sensor = sub(scan_link, "sensor", name="lidar", type="gpu_lidar")
    sub(sensor, "always_on", "true")
    sub(sensor, "update_rate", fmt(lidar_rate))
    sub(sensor, "visualize", "false")
    sub(sensor, "topic", SCAN.gz_name)
    sub(sensor, SENSOR_FRAME_ELEMENT, "base_scan")
    ray = sub(sensor, "lidar")
    horizontal = sub(sub(ray, "scan"), "horizontal")
    sub(horizontal, "samples", str(lidar.samples))
    sub(horizontal, "resolution", "1")
    sub(horizontal, "min_angle", fmt(lidar.angle_min))
    sub(horizontal, "max_angle", fmt(lidar.angle_max))
    rng = sub(ray, "range")
    sub(rng, "min", fmt(lidar.range_min))
    sub(rng, "max", fmt(lidar.range_max))
    sub(rng, "resolution", "0.001")
    noise = sub(ray, "noise")
    sub(noise, "type", "gaussian")
    sub(noise, "mean", "0")
    sub(noise, "stddev", fmt(lidar_noise))
    for name in ("base_scan", "imu_link"):
        j = sub(model, "joint", name=f"{name}_joint", type="fixed")
        sub(j, "parent", "base_link")
        sub(j, "child", name)
    imu_link = sub(model, "link", name="imu_link")
    sub(imu_link, "pose", fmt_seq((0, 0, d.wheel_radius + chassis(d)[1], 0, 0, 0)))
    _sdf_inertial(imu_link, 0.01, (1e-5, 1e-5, 1e-5))
    imu = sub(imu_link, "sensor", name="imu", type="imu")
    sub(imu, "always_on", "true")
    sub(imu, "update_rate", "50")
    sub(imu, "topic", IMU.gz_name)
    sub(imu, SENSOR_FRAME_ELEMENT, "imu_link")


def _sdf_plugins(model, d: Dimensions, robot: RobotDescription, name: str, gz_release: str, odom_rate: float) -> None:
    row = release(gz_release)
    filename, cls = row.plugin("diff-drive", "DiffDrive")
    drive = sub(model, "plugin", filename=filename, name=cls)
    for key, value in (("left_joint", "left_wheel_joint"), ("right_joint", "right_wheel_joint"),
                       ("wheel_separation", fmt(d.wheel_separation)), ("wheel_radius", fmt(d.wheel_radius)),
                       ("odom_publish_frequency", fmt(odom_rate)), ("topic", CMD_VEL.gz_name), ("odom_topic", ODOM.gz_name),
                       ("tf_topic", TF.gz_name), ("frame_id", "odom"), ("child_frame_id", "base_footprint")):
        sub(drive, key, value)
    # The robot's limits, held by the DiffDrive whatever a twist asks. Without an acceleration limit a twist
    # sets the wheels' speed in one step; the tyres (mu 1) then give the body about 6.5 m/s^2 (measured in
    # Fortress 6.18 and Harmonic 8.14 alike), so the wheels spin on a start and the body slides on after a
    # stop (the 0.22 m issue 39 saw); below the tyres' grip the body follows its wheels. A turn gets the same
    # rim acceleration: a wheel's rim moves at the turn rate times half the separation.
    a, turn = robot.acceleration, robot.acceleration / (d.wheel_separation / 2.0)
    for limit, rate in (("max_linear_acceleration", a), ("min_linear_acceleration", -a),
                        ("max_angular_acceleration", turn), ("min_angular_acceleration", -turn),
                        ("max_linear_velocity", robot.max_speed), ("min_linear_velocity", -robot.max_speed),
                        ("max_angular_velocity", robot.turn_rate), ("min_angular_velocity", -robot.turn_rate)):
        sub(drive, limit, fmt(rate))
    filename, cls = row.plugin("odometry-publisher", "OdometryPublisher")
    truth = sub(model, "plugin", filename=filename, name=cls)
    for key, value in (("odom_frame", "map"), ("robot_base_frame", "base_footprint"),
                       ("odom_publish_frequency", fmt(odom_rate)), ("odom_topic", GROUND_TRUTH.gz_name),
                       ("tf_topic", f"/model/{name}/pose"), ("dimensions", "2")):
        sub(truth, key, value)
    filename, cls = row.plugin("joint-state-publisher", "JointStatePublisher")
    states = sub(model, "plugin", filename=filename, name=cls)
    sub(states, "topic", JOINT_STATES.gz_name)


def robot_sdf(world, *, name: str = DEFAULT_NAME, lidar_noise: float = 0.0, gz_release: str = DEFAULT_GZ_RELEASE,
              sensors: bool = True, lidar_rate: float = 10.0, odom_rate: float = 50.0) -> str:
    """``robot.sdf`` (SDFormat 1.9, one ``<model>``) of the robot for ``world`` (a World, world.json's content or
    a :class:`~worldgen.scene.robot.RobotDescription`).

    ``lidar_noise``: the lidar's Gaussian noise, standard deviation in m (0: exact ranges);
    ``gz_release``: whose plugin names the systems get (``fortress``, ``garden``, ``harmonic``, ``ionic``);
    ``sensors=False`` leaves lidar and IMU out (a run that reads no sensor needs no renderer);
    ``lidar_rate``, ``odom_rate``: publishing rates, Hz.
    """
    if not (lidar_noise >= 0 and math.isfinite(lidar_noise)):
        raise ParameterError(f"parameter 'lidar_noise' must be a finite standard deviation >= 0 m, got {lidar_noise!r}")
    if not (lidar_rate > 0 and odom_rate > 0):
        raise ParameterError(f"rates must be > 0 Hz, got lidar_rate={lidar_rate!r}, odom_rate={odom_rate!r}")
    release(gz_release)
    robot = described(world)
    d = dimensions(robot)
    root = etree.Element("sdf", version="1.9")
    model = sub(root, "model", name=name)
    sub(model, "pose", "0 0 0 0 0 0")
    sub(model, "frame", name="base_footprint", attached_to="base_link").append(
        _el("pose", fmt_seq((0, 0, -d.wheel_radius, 0, 0, 0)), relative_to="base_link"))
    _sdf_links(model, d, robot.mass)
    if _on_terrain(world):  # only there: a flat world's robot keeps its bytes
        _suspend_casters(model)
    if sensors:
        _sdf_sensors(model, d, robot.lidar, float(lidar_noise), float(lidar_rate))
    _sdf_plugins(model, d, robot, name, gz_release, float(odom_rate))
    return to_bytes(root).decode()


def _suspend_casters(model) -> None:
    """Put each caster on a vertical spring (docs/terrain.md): rigid, the two casters and two wheels stand on
    four points, and where the ground bends up (a ramp's foot) the casters lift the wheels off it, which
    then have no grip (measured in Fortress and Harmonic: the robot stalls at every ramp's foot). On springs
    the casters follow the ground and the wheels keep the weight. The URDF keeps them fixed: nothing reads
    a caster's joint."""
    for joint in model.findall("joint"):
        if joint.get("name", "").endswith("caster_joint"):
            joint.set("type", "prismatic")
            axis = sub(joint, "axis")
            sub(axis, "xyz", "0 0 1")
            limit = sub(axis, "limit")
            sub(limit, "lower", fmt(-CASTER_TRAVEL))
            sub(limit, "upper", fmt(CASTER_TRAVEL))
            dynamics = sub(axis, "dynamics")
            sub(dynamics, "spring_stiffness", fmt(CASTER_SPRING))
            # Rest a little below the wheels' ground: pressed up to it, the casters keep a light contact.
            sub(dynamics, "spring_reference", fmt(-CASTER_PRELOAD))
            sub(dynamics, "damping", fmt(CASTER_DAMPING))


def _el(tag: str, text: str, **attrs):
    el = etree.Element(tag, attrs)
    el.text = text
    return el
