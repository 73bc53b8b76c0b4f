"""MJCF exporter: Scene -> MJCF bytes for MuJoCo, filled into ``templates/world.mjcf.xml``.

How the scene maps onto MJCF:

- Every node's name is its geom's name (and its body's name where it has a body).
- A static root node without children is a bare geom in ``<worldbody>`` at its
  world pose: nothing can move it, so it needs no body.
- A dynamic root node is a body with a ``<freejoint>`` (named after the node),
  its mass and diagonal inertia in an ``<inertial>``.
- A node with a parent is a body nested in its parent's body at ``node.pose``:
  on a ``hinge`` when a revolute scene Joint names it as child, rigidly
  otherwise (a fixed Joint, or no Joint at all).
- Initial joint angle: ``node.pose`` is where the node *is* (the pose the
  feasibility check and world.json use), that is the pose at ``joint.initial``.
  The hinge gets ``ref = initial``: MuJoCo then sets ``qpos0 = initial`` and
  rotates the body by ``qpos - ref``, so the model compiles with the door where
  the scene has it and ``qpos`` reads the same angle as the scene's Joint and
  as world.json's ``doors[].angle``; the range is the Joint's limits as given.
- Sizes: boxes as half extents, cylinders as "radius half-length", spheres as
  radius. Meshes are inlined as ``<mesh vertex face scale>`` assets so that
  ``mujoco.MjModel.from_xml_string`` needs no files (MuJoCo re-centres a mesh
  on its centroid: ``model.mesh_pos``/``mesh_quat`` hold that offset).
- Friction: "slide torsional rolling" = node.material.friction and MuJoCo's own
  defaults for the two others. Colour: ``rgba``.
- Nodes without collision (role ``marker``): ``contype="0" conaffinity="0"``.
- Movers: ``<body mocap="true">`` in the worldbody, named after the mover, at
  its first waypoint, with a cylinder geom of the same name; driven through
  ``data.mocap_pos`` (:func:`worldgen.scene.motion.drive_mocap`). Mocap bodies
  push dynamic bodies (a robot) but never collide with static geometry. URDF
  has no element for a scripted motion, so movers are left out of it.
- Physics: ``<option timestep gravity>``; the real-time factor, which MuJoCo
  does not know, as ``<custom><numeric name="real_time_factor">``.
"""

from __future__ import annotations

from typing import Optional

from worldgen.errors import SceneError
from worldgen.export.bodies import joints_by_child, mass_properties
from worldgen.export.xml import XmlText, fill, load_template, sub
from worldgen.files import MJCF_NAME
from worldgen.floats import fmt, fmt_seq
from worldgen.scene import Box, Cylinder, Joint, Mesh, Node, Scene, Sphere
from worldgen.scene.ground import FLOOR_NAME, Field, ground_pieces, yaw_quat
from worldgen.scene.mover import MOVER_RGBA

__all__ = ["to_mjcf", "TEMPLATE"]

TEMPLATE = MJCF_NAME  # worldgen/templates names each skeleton after the file it becomes
#: MuJoCo's defaults for the torsional and rolling friction coefficients.
TORSIONAL_FRICTION = 0.005
ROLLING_FRICTION = 0.0001
def to_mjcf(scene: Scene, name: str = "world") -> bytes:
    """The scene as an MJCF document: UTF-8 bytes, pretty-printed.

    The skeleton, the option and the mesh assets are filled with lxml; the bodies and geoms
    are written as text (:class:`~worldgen.export.xml.XmlText`). Parse the bytes with
    :func:`~worldgen.export.xml.parse_bytes` to edit the model (the RL environment adds its robot so).
    """
    joints = joints_by_child(scene)
    tree = load_template(TEMPLATE)
    root = tree.getroot()
    root.set("model", name)
    option = root.find("option")
    option.set("timestep", fmt(scene.physics.step_size))
    option.set("gravity", fmt_seq(scene.physics.gravity))
    mesh_assets = _write_mesh_assets(root.find("asset"), scene)
    _check_joint_names(scene, joints)
    # MuJoCo has no pacing of its own: the real-time factor travels as a custom
    # number (model.numeric("real_time_factor")) for a runner that wants it.
    sub(sub(root, "custom"), "numeric", name="real_time_factor", data=fmt(scene.physics.real_time_factor))
    children: dict[Optional[str], list[Node]] = {}
    for node in scene.nodes:  # one pass, keeping the scene's node order
        children.setdefault(node.parent, []).append(node)
    out = XmlText(depth=2)
    replaced, pieces = ground_pieces(scene)  # nothing on flat ground
    for node in children.get(None, ()):
        if not (replaced and node.name == FLOOR_NAME):
            _write_node(out, node, joints, children, mesh_assets)
    if pieces:
        _write_ground(out, root.find("asset"), scene, pieces)
    _write_mocap(out, scene)
    return fill(tree, root.find("worldbody"), out)


def _check_joint_names(scene: Scene, joints: dict[str, Joint]) -> None:
    """Free joints are named after their node; they must not clash with a scene joint."""
    scene_names = {j.name for j in scene.joints}
    for node in scene.nodes:
        if _is_free(node, joints) and node.name in scene_names:
            raise SceneError(f"node {node.name!r} is dynamic and its free joint's name clashes with a scene joint")


def _is_free(node: Node, joints: dict[str, Joint]) -> bool:
    return node.parent is None and not node.static and node.name not in joints


def _write_mesh_assets(asset, scene: Scene) -> dict[tuple, str]:
    """One ``<mesh>`` per distinct (uri, scale); returns {(uri, scale): asset name}."""
    names: dict[tuple, str] = {}
    for node in scene.nodes:
        shape = node.shape
        if not isinstance(shape, Mesh):
            continue
        key = (shape.uri, shape.scale)
        if key in names:
            continue
        # Named after the first node using it: node names are unique and plain.
        names[key] = node.name
        sub(asset, "mesh", name=node.name, scale=fmt_seq(shape.scale),
            vertex=fmt_seq(shape.vertices.ravel()), face=" ".join(str(int(i)) for i in shape.faces.ravel()))
    return names


def _pose_attrs(pose) -> str:
    return f' pos="{fmt_seq((pose.x, pose.y, pose.z))}" euler="{fmt_seq((pose.roll, pose.pitch, pose.yaw))}"'


def _write_node(out: XmlText, node: Node, joints, children, mesh_assets) -> None:
    joint = joints.get(node.name)
    kids = children.get(node.name, ())
    if node.parent is None and node.static and joint is None and not kids:
        if node.shape is not None:
            _write_geom(out, node, mesh_assets, _pose_attrs(node.pose))
        return
    out.open("body", f' name="{node.name}"{_pose_attrs(node.pose)}')
    mass, inertia = mass_properties(node)
    out.empty("inertial", f' pos="0 0 0" mass="{mass}" diaginertia="{" ".join(inertia)}"')
    if _is_free(node, joints):
        out.empty("freejoint", f' name="{node.name}"')
    elif joint is not None and joint.kind == "revolute":
        rot = joint.pose.rotation
        axis = rot @ joint.axis  # MJCF wants the axis in the body (child) frame
        lo, hi = joint.limits
        out.empty("joint", f' name="{joint.name}" type="hinge" pos="{fmt_seq((joint.pose.x, joint.pose.y, joint.pose.z))}"'
                           f' axis="{fmt_seq(axis)}" limited="true" range="{fmt_seq((lo, hi))}" ref="{fmt(joint.initial)}"'
                           f' damping="{fmt(joint.damping)}" actuatorfrclimited="true"'
                           f' actuatorfrcrange="{fmt_seq((-joint.effort, joint.effort))}"')
    if node.shape is not None:
        _write_geom(out, node, mesh_assets, "")
    for child in kids:
        _write_node(out, child, joints, children, mesh_assets)
    out.close("body")


def _write_geom(out: XmlText, node: Node, mesh_assets, pose_attrs: str) -> None:
    shape = node.shape
    if isinstance(shape, Box):
        kind = f' type="box" size="{fmt_seq(s / 2.0 for s in shape.size)}"'
    elif isinstance(shape, Cylinder):
        kind = f' type="cylinder" size="{fmt_seq((shape.radius, shape.length / 2.0))}"'
    elif isinstance(shape, Sphere):
        kind = f' type="sphere" size="{fmt(shape.radius)}"'
    elif isinstance(shape, Mesh):
        kind = f' type="mesh" mesh="{mesh_assets[(shape.uri, shape.scale)]}"'
    else:
        raise SceneError(f"node {node.name!r}: unknown shape {shape!r}")
    friction = fmt_seq((node.material.friction, TORSIONAL_FRICTION, ROLLING_FRICTION))
    # Visual only: no contact with anything, drawn in group 2 with the other visuals.
    visual = "" if node.collision else ' contype="0" conaffinity="0" group="2"'
    out.empty("geom", f' name="{node.name}"{kind}{pose_attrs} rgba="{fmt_seq(node.material.rgba)}"'
                      f' friction="{friction}"{visual}')


def _write_ground(out: XmlText, asset, scene: Scene, pieces) -> None:
    """The terrain's pieces (worldgen.scene.ground): a mesh asset of corner points (MuJoCo takes their
    convex hull) or a height field each, and a static geom of the floor's material for it."""
    floor = next((n for n in scene.nodes if n.name == FLOOR_NAME), None)
    rgba, friction = (floor.material.rgba, floor.material.friction) if floor is not None else ((0.7,) * 3 + (1.0,), 1.0)
    look = f' rgba="{fmt_seq(rgba)}" friction="{fmt_seq((friction, TORSIONAL_FRICTION, ROLLING_FRICTION))}"'
    for piece in pieces:
        if isinstance(piece, Field):
            low, high = float(piece.grid.min()), float(piece.grid.max())
            rise = max(high - low, 1e-6)  # MuJoCo scales the elevations to [0, 1] of this
            sub(asset, "hfield", name=piece.name, nrow=str(piece.grid.shape[0]), ncol=str(piece.grid.shape[1]),
                size=fmt_seq((piece.length / 2, piece.width / 2, rise, piece.base)),
                # MuJoCo's first row of elevations lies at the largest y: the grid's rows go in reversed.
                elevation=fmt_seq(((piece.grid - low) / rise)[::-1].ravel()))
            out.empty("geom", f' name="{piece.name}" type="hfield" hfield="{piece.name}"'
                              f' pos="{fmt_seq((piece.cx, piece.cy, low))}" quat="{fmt_seq(yaw_quat(piece.yaw))}"{look}')
        else:
            sub(asset, "mesh", name=piece.name, vertex=fmt_seq(piece.points.ravel()))
            out.empty("geom", f' name="{piece.name}" type="mesh" mesh="{piece.name}"{look}')


def _write_mocap(out: XmlText, scene: Scene) -> None:
    """One mocap body (with a cylinder geom of the same name) per mover, at the end of ``<worldbody>``."""
    for mover in scene.movers:
        _, x, y = mover.trajectory[0]
        out.open("body", f' name="{mover.name}" mocap="true" pos="{fmt_seq((x, y, mover.height / 2.0))}"')
        out.empty("geom", f' name="{mover.name}" type="cylinder" size="{fmt_seq((mover.radius, mover.height / 2.0))}"'
                          f' rgba="{fmt_seq(MOVER_RGBA)}"'
                          f' friction="{fmt_seq((mover.friction, TORSIONAL_FRICTION, ROLLING_FRICTION))}"')
        out.close("body")
