"""Door openers in the navigation environment: which doors open by themselves, and when.

A door leaf is a hinged MuJoCo body (world.json ``doors[]``), and the world's truth plans every reference
path through the doorway with the leaf at its open limit. A robot base without an arm can push a leaf that
swings away from it, but not pull one that swings towards it. The ``doors`` setting says how the leaves open:

- ``"auto"`` (default): a door the robot comes to from the side its leaf swings into (world.json
  ``doors[].passage.normal`` points to that side: a pull door for a robot there) is an automatic door: when
  the robot's centre enters the disc of ``door_trigger`` m about the doorway's centre (``passage.center``)
  on that side, a hinge motor swings the leaf towards its open limit at ``door_speed`` rad/s and holds it
  open for the rest of the episode. A door the robot comes to from the other side stays passive while the
  robot is in that disc: the robot pushes it open (and leaving it through the doorway triggers nothing).
- ``"automatic"``: every door is automatic, from either side.
- ``"push"``: every leaf is passive; a pull door stays shut (the path follower stalls at it).

The motor is a MuJoCo actuator on the hinge, added to the world's MJCF by the environment: an integrator
(its activation, the target angle, ramps at ``door_speed`` and stops at the limits) feeding a stiff,
critically damped position servo (natural frequency :data:`OPENER_OMEGA`, scaled by the leaf's inertia about
the hinge; the leaf trails the ramp by about ``2 door_speed / OPENER_OMEGA``, 0.2 rad at the defaults, and
settles on the open limit). Its torque is bounded by the hinge's own effort limit (the scene joint's
``effort``, MJCF ``actuatorfrcrange``: 100 N m in the door generator's worlds), so a leaf opening onto
the robot presses on it (a door contact, not a collision) rather than shoving it aside. Before it is
triggered the motor is off (zero gains): the leaf is passive.
The trigger is tested at the start of every env step.
"""

from __future__ import annotations

import math
from typing import Any, Sequence

import numpy as np
from lxml import etree

from worldgen.floats import fmt_seq

__all__ = ["DOOR_MODES", "OPENER_OMEGA", "opener_name", "add_openers", "Openers"]

#: The values of the environment's ``doors`` setting.
DOOR_MODES = ("auto", "automatic", "push")
#: Natural frequency (rad/s) of the opener's position servo (critically damped, whatever the leaf's inertia).
OPENER_OMEGA = 20.0


def opener_name(joint: str) -> str:
    """The MJCF name of the opener actuator of hinge ``joint``."""
    return f"{joint}_opener"


def _openable(doors: Sequence[dict], mode: str) -> list[dict]:
    """The doors that get a motor: none when pushing only; else those with a doorway to trigger on."""
    if mode == "push":
        return []
    return [d for d in doors if d.get("passage")]


def add_openers(root, doors: Sequence[dict], mode: str) -> None:
    """Add an opener actuator (off) for each door of world.json ``doors[]`` that ``mode`` may open."""
    chosen = _openable(doors, mode)
    if not chosen:
        return
    actuators = root.find("actuator")
    if actuators is None:
        actuators = etree.SubElement(root, "actuator")
    for d in chosen:
        lo, hi = d["limits"]
        etree.SubElement(actuators, "general", {
            "name": opener_name(d["joint"]), "joint": d["joint"], "dyntype": "integrator", "gaintype": "fixed",
            "gainprm": "0", "biastype": "affine", "biasprm": "0 0 0", "actlimited": "true",
            "actrange": fmt_seq((lo, hi)), "ctrllimited": "true", "ctrlrange": fmt_seq((-1e3, 1e3))})


class Openers:
    """The opener motors of one episode: triggered by the robot's position, then ramping each leaf open.

    ``doors`` are world.json's ``doors[]``; ``model``/``data`` the compiled world (after
    :func:`add_openers`).
    """

    def __init__(self, model, data, doors: Sequence[dict], mode: str, trigger: float, speed: float):
        self.mode, self.trigger, self.speed = mode, float(trigger), float(speed)
        self._data, self._model = data, model
        self._doors: list[dict[str, Any]] = []
        for d in _openable(doors, mode):
            joint = model.joint(d["joint"])
            lo, hi = d["limits"]
            opening = lo if abs(lo) > abs(hi) else hi  # the open limit (scene.doors.open_angle)
            inertia = float(model.dof_M0[joint.dofadr[0]])  # the leaf about its hinge (any angle)
            self._doors.append({
                "name": str(d["name"]), "actuator": int(model.actuator(opener_name(d["joint"])).id),
                "qpos": int(joint.qposadr[0]), "inertia": inertia, "sign": 1.0 if opening >= 0 else -1.0,
                "center": np.asarray(d["passage"]["center"], dtype=float),
                "normal": np.asarray(d["passage"]["normal"], dtype=float)})
        #: Names of the doors whose opener has been triggered, in the order they were.
        self.opened: list[str] = []
        self._pushing: set[str] = set()  # doors whose disc the robot entered from the push side ("auto")

    def __len__(self) -> int:
        return len(self._doors)

    def update(self, x: float, y: float) -> list[str]:
        """Trigger every door the robot at (x, y) now asks to open; the names of those newly triggered."""
        new = []
        p = np.array([x, y])
        for d in self._doors:
            if d["name"] in self.opened:
                continue
            rel = p - d["center"]
            if math.hypot(*rel) > self.trigger:
                self._pushing.discard(d["name"])
                continue
            if self.mode == "auto" and (d["name"] in self._pushing or float(rel @ d["normal"]) <= 0.0):
                self._pushing.add(d["name"])  # came from the push side: it pushes the leaf open itself
                continue
            self._start(d)
            self.opened.append(d["name"])
            new.append(d["name"])
        return new

    def _start(self, d: dict) -> None:
        model, data, i = self._model, self._data, d["actuator"]
        kp = d["inertia"] * OPENER_OMEGA ** 2
        kv = 2.0 * d["inertia"] * OPENER_OMEGA  # critically damped
        model.actuator_gainprm[i, 0] = kp
        model.actuator_biasprm[i, :3] = (0.0, -kp, -kv)
        # The ramp starts where the leaf is now (it may have been pushed), then runs to the open limit.
        data.act[model.actuator_actadr[i]] = data.qpos[d["qpos"]]
        data.ctrl[i] = d["sign"] * self.speed
