"""How movers (scene.movers) are written: an SDF ``<actor>`` or an MJCF mocap body; never URDF.

SDF (both 1.9 and 1.6, the same element): one ``<actor name=mover>`` holding a
link ``body`` with the mover's cylinder (visual and collision, its base on the
floor) and a ``<script>`` that loops one ``<trajectory>`` of timed
``<waypoint>``s, one per trajectory row (pose ``x y 0 0 0 0``). What the two
Gazebo lines make of it (see also the SDF exporter's docstring):

* Gazebo classic carries every link of an actor along the trajectory, so the
  cylinder is drawn and walks the script; ``tension="1"`` makes it pass through
  the waypoints instead of overshooting them on a Catmull-Rom spline (the
  default, tension 0). A skin is optional there.
* Gazebo Sim (Fortress to Harmonic) needed a skin mesh with a skeleton
  animation until trajectory-only actors were accepted (gz-sim pull request
  1947, in Fortress and later releases from 2023); drawing arbitrary links of an
  actor is still an open gap (gz-sim issue 418), so there the mover may move
  unseen. It ignores ``tension`` (gz-sim issue 243) and interpolates the poses.
  worldgen ships no skin: the worlds must load without a network or model
  database; add a ``<skin>``/``<animation>`` (e.g. Fuel's walking actor) to see
  a person.
* Neither Gazebo gives actors physics: no gravity, no contact. The collision
  element is there for plugins that enable it (Gazebo classic's actor
  collisions example calls ``Link::Init``); a robot drives through a stock
  actor, and GPU sensors see only what is drawn. Separation from movers is
  judged from world.json's trajectories, not from simulator contacts.

MJCF: ``<body name=mover mocap="true">`` in the worldbody at the first
waypoint with a cylinder geom of the same name. Mocap bodies are moved by
writing ``data.mocap_pos`` (:func:`worldgen.movers.drive_mocap`); they push
dynamic bodies (a robot) but never collide with static geometry.

URDF has no element for a scripted motion, so movers are left out, and
world.json says so per mover (``formats.urdf`` is null).
"""

from __future__ import annotations

from lxml import etree

from worldgen.export.xml import XmlText, sub
from worldgen.floats import fmt, fmt_seq
from worldgen.scene import Mover, Scene
from worldgen.scene.mover import MOVER_RGBA

__all__ = ["write_sdf_actors", "write_mjcf_mocap", "TRAJECTORY_TYPE"]

#: The trajectory's ``type``: it would name a skin animation played along it, if there were one.
TRAJECTORY_TYPE = "walk"


def write_sdf_actors(out: XmlText, scene: Scene) -> None:
    """Write one ``<actor>`` per mover at the end of the SDF ``<world>`` (``out`` is at its children's depth)."""
    for mover in scene.movers:
        _sdf_actor(out, mover)


def _sdf_actor(out: XmlText, mover: Mover) -> None:
    out.open("actor", f' name="{mover.name}"')
    out.open("link", ' name="body"')
    out.leaf("pose", fmt_seq((0.0, 0.0, mover.height / 2.0, 0.0, 0.0, 0.0)))
    out.open("collision", ' name="collision"')
    _cylinder(out, mover)
    out.close("collision")
    out.open("visual", ' name="visual"')
    _cylinder(out, mover)
    colour = fmt_seq(MOVER_RGBA)
    out.open("material")
    out.leaf("ambient", colour)
    out.leaf("diffuse", colour)
    out.close("material")
    out.close("visual")
    out.close("link")
    out.open("script")
    out.leaf("loop", "true" if mover.loop else "false")
    out.leaf("delay_start", "0")
    out.leaf("auto_start", "true")
    out.open("trajectory", f' id="0" type="{TRAJECTORY_TYPE}" tension="1"')
    for t, x, y in mover.trajectory:
        out.open("waypoint")
        out.leaf("time", fmt(t))
        out.leaf("pose", fmt_seq((x, y, 0.0, 0.0, 0.0, 0.0)))
        out.close("waypoint")
    out.close("trajectory")
    out.close("script")
    out.close("actor")


def _cylinder(out: XmlText, mover: Mover) -> None:
    out.open("geometry")
    out.open("cylinder")
    out.leaf("radius", fmt(mover.radius))
    out.leaf("length", fmt(mover.height))
    out.close("cylinder")
    out.close("geometry")


def write_mjcf_mocap(worldbody: etree._Element, scene: Scene) -> None:
    """Append one mocap body (with a cylinder geom of the same name) per mover to ``<worldbody>``."""
    from worldgen.export.mjcf import ROLLING_FRICTION, TORSIONAL_FRICTION  # mjcf imports this module

    for mover in scene.movers:
        _, x, y = mover.trajectory[0]
        body = sub(worldbody, "body", name=mover.name, mocap="true", pos=fmt_seq((x, y, mover.height / 2.0)))
        sub(body, "geom", name=mover.name, type="cylinder", size=fmt_seq((mover.radius, mover.height / 2.0)),
            rgba=fmt_seq(MOVER_RGBA), friction=fmt_seq((mover.friction, TORSIONAL_FRICTION, ROLLING_FRICTION)))
