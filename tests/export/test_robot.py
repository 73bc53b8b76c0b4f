"""robot.sdf and robot.urdf: libsdformat, check_urdf and MuJoCo accept them for any footprint, the lidar is
world.json's, every body stays inside the footprint, and the bytes are the same in a fresh process."""

from __future__ import annotations

import math
import subprocess
import sys

import mujoco
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st
from support.reftools_mujoco import load_and_step
from support.reftools_sdf import check_robot_sdf
from support.reftools_urdf import check_urdf

import worldgen
from worldgen.errors import ParameterError
from worldgen.export import robot as robot_export
from worldgen.export.contract import GZ_RELEASES
from worldgen.export.ros2 import DEFAULT_ROBOT_NAME
from worldgen.export.xml import parse_bytes


def _world(**params):
    return worldgen.generate("cluttered", seed=3, size=[6, 6], n_obstacles=3, **params)


@pytest.fixture(scope="module")
def world():
    return _world(lidar_samples=180, lidar_height=0.25, lidar_range_max=12.0)


def _floats(text: str) -> list[float]:
    return [float(v) for v in text.split()]


def _check_files(tmp_path, world, **kw):
    sdf = tmp_path / "robot.sdf"
    sdf.write_text(robot_export.robot_sdf(world, **kw))
    ok, messages = check_robot_sdf(sdf)
    assert ok, messages
    urdf = tmp_path / "robot.urdf"
    urdf.write_text(robot_export.robot_urdf(world))
    out = check_urdf(urdf)
    assert "root Link: base_footprint" in out
    return sdf, urdf


def test_sdf_and_urdf_pass_the_reference_tools(tmp_path, world):
    for release in GZ_RELEASES:
        _check_files(tmp_path, world, gz_release=release, lidar_noise=0.01)
    _check_files(tmp_path, world, sensors=False)
    model, data = load_and_step(tmp_path / "robot.urdf", steps=200)
    # MuJoCo keeps the moving bodies (the two wheels) and fuses every fixed one into its parent.
    hinges = [model.joint(i).name for i in range(model.njnt) if model.jnt_type[i] == mujoco.mjtJoint.mjJNT_HINGE]
    assert sorted(hinges) == ["left_wheel_joint", "right_wheel_joint"]


def test_lidar_topics_and_frames_are_what_the_docs_say(world):
    root = parse_bytes(robot_export.robot_sdf(world, lidar_noise=0.02).encode()).getroot()
    lidar = world.metadata["sensors"]["lidar"]
    sensor = root.find(".//sensor[@type='gpu_lidar']")
    horizontal = sensor.find("lidar/scan/horizontal")
    assert int(horizontal.findtext("samples")) == lidar["samples"] == 180
    assert float(horizontal.findtext("min_angle")) == lidar["angle_min"]
    assert float(horizontal.findtext("max_angle")) == lidar["angle_max"]
    assert float(sensor.findtext("lidar/range/min")) == lidar["range_min"]
    assert float(sensor.findtext("lidar/range/max")) == lidar["range_max"] == 12.0
    assert float(sensor.findtext("lidar/noise/stddev")) == 0.02
    assert sensor.findtext("topic") == "scan"
    scan_z = _floats(root.findtext(".//link[@name='base_scan']/pose"))[2]
    assert scan_z == pytest.approx(lidar["pose"][2] - world.metadata["tasks"][0]["spawn"][2]) == 0.25
    drive = root.find(".//plugin[@name='gz::sim::systems::DiffDrive']")
    assert {k: drive.findtext(k) for k in ("topic", "odom_topic", "tf_topic", "frame_id", "child_frame_id")} == {
        "topic": "cmd_vel", "odom_topic": "odom", "tf_topic": "tf", "frame_id": "odom", "child_frame_id": "base_footprint"}
    truth = root.find(".//plugin[@name='gz::sim::systems::OdometryPublisher']")
    assert truth.findtext("odom_topic") == "ground_truth/odom" and truth.findtext("odom_frame") == "map"
    assert truth.findtext("tf_topic") == f"/model/{DEFAULT_ROBOT_NAME}/pose"
    assert root.find("model").get("name") == robot_export.DEFAULT_NAME == DEFAULT_ROBOT_NAME
    assert root.find(".//sensor[@type='imu']").findtext("topic") == "imu"
    assert root.find(".//sensor[@type='gpu_lidar']") is not None
    bare = parse_bytes(robot_export.robot_sdf(world, sensors=False).encode()).getroot()
    assert bare.find(".//sensor") is None


def _extent_ok(d, root) -> None:
    """Every collision lies inside the footprint cylinder [0, height] x radius; wheels and casters touch the floor."""
    lowest = math.inf
    for link in root.iter("link"):
        pose = _floats(link.findtext("pose"))
        for col in link.iter("collision"):
            cpose = _floats(col.findtext("pose"))
            geometry = col.find("geometry")
            if geometry.find("cylinder") is not None:
                r, length = float(geometry.findtext("cylinder/radius")), float(geometry.findtext("cylinder/length"))
                if abs(pose[3]) > 1e-9:      # a wheel: its axis along y
                    reach_xy, lo, hi = math.hypot(abs(pose[0]) + r, abs(pose[1]) + length / 2), pose[2] - r, pose[2] + r
                else:
                    z = pose[2] + cpose[2]
                    reach_xy, lo, hi = math.hypot(pose[0], pose[1]) + r, z - length / 2, z + length / 2
            else:
                r = float(geometry.findtext("sphere/radius"))
                reach_xy, lo, hi = math.hypot(pose[0], pose[1]) + r, pose[2] - r, pose[2] + r
            # 1e-6: the files keep 6 decimals
            assert reach_xy <= d.radius + 1e-6 and hi <= d.height + 1e-6 and lo >= -1e-6, link.get("name")
            lowest = min(lowest, lo)
    assert lowest == pytest.approx(0.0, abs=1e-6)


@settings(max_examples=15, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(radius=st.floats(0.08, 0.5), height=st.floats(0.1, 1.2), lidar=st.floats(0.05, 1.0))
def test_any_footprint_fits_its_cylinder_and_loads(tmp_path, radius, height, lidar):
    w = worldgen.generate("minimal", seed=1, robot_radius=round(radius, 3), robot_height=round(height, 3),
                          lidar_height=round(lidar, 3))
    d = robot_export.dimensions(w)
    sdf, urdf = _check_files(tmp_path, w)
    _extent_ok(d, parse_bytes(sdf.read_bytes()).getroot())
    assert d.wheel_separation / 2 + d.wheel_width / 2 <= 0.9 * d.radius + 1e-12
    load_and_step(urdf, steps=50)


def test_bytes_are_the_same_in_a_fresh_process(world):
    code = ("import worldgen, hashlib; from worldgen.export.robot import robot_sdf, robot_urdf; "
            "w = worldgen.generate('cluttered', seed=3, size=[6, 6], n_obstacles=3, lidar_samples=180, "
            "lidar_height=0.25, lidar_range_max=12.0); "
            "print(hashlib.sha256((robot_sdf(w, lidar_noise=0.01) + robot_urdf(w)).encode()).hexdigest())")
    fresh = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True).stdout.strip()
    import hashlib
    here = hashlib.sha256((robot_export.robot_sdf(world, lidar_noise=0.01) + robot_export.robot_urdf(world)).encode())
    assert fresh == here.hexdigest()


@pytest.mark.parametrize("kw", [{"lidar_noise": -0.1}, {"lidar_noise": math.nan}, {"gz_release": "citadel"},
                                {"lidar_rate": 0}])
def test_bad_arguments_name_what_is_allowed(world, kw):
    with pytest.raises(ParameterError, match=next(iter(kw))):
        robot_export.robot_sdf(world, **kw)


def test_the_urdf_is_the_sdf_tree(world):
    """Every link of the URDF sits where the SDF puts it, relative to base_link (same tree, same numbers)."""
    sdf = parse_bytes(robot_export.robot_sdf(world).encode()).getroot()
    urdf = parse_bytes(robot_export.robot_urdf(world).encode()).getroot()
    base = _floats(sdf.findtext(".//link[@name='base_link']/pose"))
    assert float(urdf.find("joint[@name='base_footprint_joint']/origin").get("xyz").split()[2]) == base[2]
    for joint in urdf.iter("joint"):
        child, parent = joint.find("child").get("link"), joint.find("parent").get("link")
        if parent != "base_link":
            continue
        xyz = _floats(joint.find("origin").get("xyz"))
        rpy = _floats(joint.find("origin").get("rpy"))
        pose = _floats(sdf.findtext(f".//link[@name='{child}']/pose"))
        assert [p - b for p, b in zip(pose[:3], base[:3])] == pytest.approx(xyz, abs=1e-6), child
        assert pose[3:] == pytest.approx(rpy, abs=1e-6), child
        sdf_joint = sdf.find(f".//joint[@name='{joint.get('name')}']")
        assert sdf_joint.get("type") == {"continuous": "revolute", "fixed": "fixed"}[joint.get("type")]
