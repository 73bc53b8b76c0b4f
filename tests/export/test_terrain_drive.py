"""A wheeled robot drives up a ramp, along its landing and down again in MuJoCo, on the terrain the MJCF
exports: the physics on the slope carries it over (its chassis rides at the model's height, within 1 cm,
all the way), which no flat stand-in would show.

The robot is a test's own: a free chassis on two driven wheels and a low-friction caster behind them (the drive
loop's robot in worldgen.envs.robot slides in the plane and cannot climb)."""

import math

import numpy as np
import pytest
from lxml import etree

from worldgen.export.mjcf import to_mjcf
from worldgen.scene import Box, Material, Node, Pose, Scene
from worldgen.scene.terrain import Ramp, Terrain

mujoco = pytest.importorskip("mujoco")

WHEEL = 0.05   # wheel radius, m
AXLE_Z = WHEEL  # the chassis' centre rides one wheel radius above the ground
ROBOT = """
<body name="bot" pos="{x} 0 {z}">
  <freejoint name="bot"/>
  <geom name="chassis" type="box" size="0.15 0.1 0.025" mass="3"/>
  <geom name="back" type="sphere" size="0.02" pos="-0.12 0 -0.03" mass="0.05" priority="1" friction="0.001 0.001 0.001"/>
  <body name="left" pos="0 0.13 0"><joint name="left" type="hinge" axis="0 1 0"/>
    <geom type="sphere" size="{r}" mass="0.3" priority="1" friction="1.5 0.01 0.001"/></body>
  <body name="right" pos="0 -0.13 0"><joint name="right" type="hinge" axis="0 1 0"/>
    <geom type="sphere" size="{r}" mass="0.3" priority="1" friction="1.5 0.01 0.001"/></body>
</body>"""


def test_a_robot_drives_up_a_ramp_along_its_landing_and_down_again():
    incline, rise = 6.0, 0.1
    ramp = Ramp(0.0, 0.0, 0.0, 1.5, rise, rise / math.tan(math.radians(incline)), 0.6)
    floor = Node("floor", "floor", Box((10.0, 4.0, 0.1)), Pose(0, 0, -0.05), material=Material("floor"))
    scene = Scene((floor,), bounds=((-5, -2), (5, 2)), terrain=Terrain((ramp,)))
    root = etree.fromstring(to_mjcf(scene))
    root.find("worldbody").append(etree.fromstring(ROBOT.format(x=-3.0, z=AXLE_Z + 0.002, r=WHEEL)))
    actuators = etree.SubElement(root, "actuator")
    for wheel in ("left", "right"):
        etree.SubElement(actuators, "velocity", joint=wheel, kv="20", ctrlrange="-20 20", ctrllimited="true")
    model = mujoco.MjModel.from_xml_string(etree.tostring(root).decode())
    data = mujoco.MjData(model)
    data.ctrl[:] = 0.4 / WHEEL  # 0.4 m/s on both wheels: straight ahead, along +x
    track = []
    for _ in range(int(20.0 / model.opt.timestep)):
        mujoco.mj_step(model, data)
        track.append(data.qpos[:3].copy())
    track = np.array(track)
    assert track[-1, 0] > 3.0, f"stopped at x = {track[-1, 0]:.2f}"  # over the ramp and beyond it
    assert np.abs(track[:, 1]).max() < 0.3  # and straight
    # Where the wheels (+-0.13 m across, both on the ramp) roll on flat ground or the landing, the chassis
    # rides one wheel radius above the model's ground; on the inclines the wheel touches the slope a little
    # ahead of or behind the axle, so it is compared there with the slope's own offset.
    ground = scene.terrain.heights(track[:, :2])
    on_flat = scene.terrain.gradients(track[:, :2]) == 0
    lean = WHEEL / math.cos(math.radians(incline)) - WHEEL  # the axle's extra height above a slope
    assert np.abs(track[on_flat, 2] - AXLE_Z - ground[on_flat]).max() < 0.01
    assert np.abs(track[~on_flat, 2] - AXLE_Z - lean - ground[~on_flat]).max() < 0.01
    assert track[:, 2].max() == pytest.approx(AXLE_Z + rise, abs=0.01)  # up on the landing
