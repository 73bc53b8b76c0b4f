"""Scene -> SDFormat world, as version 1.9 (Gazebo Fortress to Harmonic) or 1.6 (Gazebo classic).

The world is filled into the skeleton ``templates/world.sdf`` (physics, scene,
one directional light; no ``model://`` includes and no ground plane, because the
floor is a node of the scene). Each root node becomes ``<model name=node.name>``
posed in the world; the node and its descendants become links of that model,
each link named after its node, joined by the scene's Joint that names the
child, or by a fixed joint when none does.

What differs between the two targets, and why the output looks as it does
(checked against the SDFormat specs shipped with libsdformat 12 and the
simulators' sources):

* SDF 1.6 predates pose frame semantics (1.8: ``<pose relative_to>``,
  ``<xyz expressed_in>``) and has no light ``<intensity>``. A 1.6 file that
  used them would be rejected by a 1.6 parser (Gazebo classic uses libsdformat
  6 or 9), so in 1.6 a child link's pose is computed here in its model's frame,
  while in 1.9 it is written relative to its parent link, exactly as the scene
  stores it. Both are checked by ``tests/tools/sdf_check.cc``, which parses a
  1.6 file against the 1.6 spec before converting it.
* Pacing: Gazebo classic runs ``real_time_update_rate`` physics steps per wall
  second (0 = as fast as it can) and does not pace by ``real_time_factor``;
  Gazebo Sim paces by ``real_time_factor`` (period = step / factor, and a factor
  of 0 drops the wait) and ignores the update rate. Both are written, kept
  consistent: rate = factor / step, so ``real_time_factor=0`` means
  "unthrottled" in every Gazebo.
* Friction is ``surface/friction/ode/mu`` and ``mu2`` in both versions; Gazebo
  classic's ODE and Gazebo Sim's physics plugins both read that block.
* Initial joint angle: no version carries it portably. 1.6 defines
  ``axis/initial_position`` but Gazebo classic ignores it (gazebo-classic issue
  2694); 1.8 deprecates it, 1.9 removes it, and libsdformat 12 rejects it in a
  1.6 file once converted. In SDF the link poses *are* the joint's zero, so the
  scene's poses (which show a jointed child at its initial angle, e.g. a door
  ajar) are written as they are, and the limits are shifted to keep the same
  physical range: ``lower = lo - initial``, ``upper = hi - initial``. The world
  therefore loads looking exactly like world.json and the other formats; only
  the joint position Gazebo reports is offset: it reads ``angle - initial``
  (world.json's ``doors[].angle`` is the initial angle).
* Mesh ``<uri>`` is the scene's path relative to the world folder. Gazebo Sim
  resolves a relative uri against the SDF file's folder; Gazebo classic looks it
  up on its resource path, so add the world folder to ``GAZEBO_RESOURCE_PATH``.
* No ``<plugin>``: Gazebo Sim loads its default systems (physics, scene
  broadcaster, user commands) when a world names none.
* Movers (``scene.movers``) and people are ``<actor>``s, the same element in 1.6
  and 1.9: a link ``body`` carrying the mover's cylinder (visual and collision,
  its base on the floor) and a ``<script>`` playing one ``<trajectory>`` of
  timed ``<waypoint>``s (one per line). Gazebo plays them as a gz-math spline
  (tangent = (1 - tension) x Catmull-Rom's); ``tension="0"`` keeps Catmull-Rom,
  which is exact on evenly cut straight runs, and the waypoints are world.json's
  rows plus points on its legs, graded about each turn, so that the actor keeps
  within 0.9 mm of world.json at every time (:mod:`worldgen.export.actor_path`).
  Gazebo classic carries every actor link along the script. Gazebo Sim accepts
  skin-less, trajectory-only actors only since gz-sim pull request 1947 (2023),
  may not draw their links (gz-sim issue 418). A Gazebo that ignores
  ``tension`` (gz-sim issue 243; ignition-common's ``PoseAnimation`` never
  passed it to its spline, whose default is 0) plays the same Catmull-Rom
  spline. Neither gives actors physics: the collision element is there for
  plugins that enable it, a stock actor is seen, not felt, and separation from
  movers is judged from world.json's trajectories. worldgen ships no skin (the
  worlds must load without a network); add a ``<skin>``/``<animation>`` to see
  a person.

A model is ``<static>`` only when all its nodes are static. A static root with a
dynamic descendant (a door frame with its leaf) gives a dynamic model whose root
link is welded to the world by a fixed joint, so that the leaf can swing.
"""

from __future__ import annotations

from typing import Optional

import numpy as np

from worldgen.errors import ParameterError, WorldgenError
from worldgen.export.actor_path import TENSION, actor_waypoints
from worldgen.export.formats import SDF_VERSIONS
from worldgen.export.xml import XmlText, escape_text, fill, load_template
from worldgen.files import SDF_NAME
from worldgen.floats import fmt, fmt_seq
from worldgen.scene import Box, Cylinder, Mesh, Node, Pose, Scene, Sphere, matrix_to_pose
from worldgen.scene.graph import Joint
from worldgen.scene.ground import ground_scene
from worldgen.scene.mover import MOVER_RGBA, Mover

__all__ = ["SDF_VERSIONS", "TEMPLATE", "MIN_MOMENT", "TRAJECTORY_TYPE", "HOLD_SECONDS", "script_rows", "to_sdf"]

TEMPLATE = SDF_NAME  # worldgen/templates names each skeleton after the file it becomes
#: Smallest principal moment written (kg m^2): floats keep 6 decimals, and a
#: moment rounded to 0 would make the inertia invalid for every physics engine.
MIN_MOMENT = 1e-6
#: A mover's trajectory ``type``: it would name a skin animation played along it, if there were one.
TRAJECTORY_TYPE = "walk"
#: How long (s of simulation time) a person that does not loop stands at its last row: the script is
#: written looping, with this hold as its last leg (see _sdf_actor).
HOLD_SECONDS = 86400.0

def to_sdf(scene: Scene, version: str = "1.9", name: str = "default") -> bytes:
    """The SDFormat world of ``scene``: UTF-8 bytes, pretty-printed (see the module docstring).

    ``name`` is the world's name; SDFormat 1.8+ reserves ``world`` and names
    starting with ``__``, so the default is Gazebo's usual ``default``. The
    skeleton is filled with lxml; the models and actors are written as text
    (:class:`~worldgen.export.xml.XmlText`).
    """
    scene = ground_scene(scene)  # the terrain as one mesh; the scene itself on flat ground
    if version not in SDF_VERSIONS:
        raise ParameterError(f"parameter 'sdf_version' must be one of {', '.join(SDF_VERSIONS)}, got {version!r}")
    if not name or name == "world" or name.startswith("__"):
        raise ParameterError(f"parameter 'name' must be a non-empty SDF world name other than 'world' "
                             f"and not starting with '__', got {name!r}")
    if "world" in {n.name for n in scene.nodes}:
        raise WorldgenError("no node may be named 'world': SDFormat reserves that name for the world frame")
    tree = load_template(TEMPLATE)
    root = tree.getroot()
    root.set("version", version)
    world = root.find("world")
    world.set("name", name)
    _fill_physics(world, scene)
    out = XmlText(depth=2)
    writer = _ModelWriter(scene, version)
    for node in scene.nodes:
        if node.parent is None:
            writer.write(out, node)
    _write_actors(out, scene)
    return fill(tree, world, out)


def _fill_physics(world, scene: Scene) -> None:
    physics = scene.physics
    block = world.find("physics")
    block.find("max_step_size").text = fmt(physics.step_size)
    block.find("real_time_factor").text = fmt(physics.real_time_factor)
    block.find("real_time_update_rate").text = fmt(physics.real_time_factor / physics.step_size)
    world.find("gravity").text = fmt_seq(physics.gravity)


class _ModelWriter:
    """Writes one model per root node; holds the lookups every model needs, built once."""

    def __init__(self, scene: Scene, version: str):
        self.scene = scene
        self.frames = version != "1.6"  # pose relative_to exists from SDF 1.8 on
        self.children: dict[str, list[Node]] = {}
        for node in scene.nodes:
            if node.parent is not None:
                self.children.setdefault(node.parent, []).append(node)
        self.joint_of: dict[str, Joint] = {}
        for joint in scene.joints:
            if joint.child in self.joint_of:
                raise WorldgenError(f"node {joint.child!r} is the child of two joints; SDF allows one")
            self.joint_of[joint.child] = joint
        # Every name a generated joint must avoid: links and joints share a model's name scope.
        self.taken = {n.name for n in scene.nodes} | {j.name for j in scene.joints}

    def subtree(self, root: Node) -> list[Node]:
        """``root`` and its descendants, depth first, children in scene order."""
        out, stack = [], [root]
        while stack:
            node = stack.pop()
            out.append(node)
            stack.extend(reversed(self.children.get(node.name, ())))
        return out

    def write(self, out: XmlText, root: Node) -> None:
        nodes = self.subtree(root)
        static = all(n.static for n in nodes)
        out.open("model", f' name="{root.name}"')
        out.leaf("static", "true" if static else "false")
        _pose(out, root.pose)
        names = {n.name for n in nodes}
        for node in nodes:
            self._link(out, node, root, with_inertial=not static)
        for node in nodes:
            joint = self.joint_of.get(node.name)
            if node is root:
                if joint is not None:
                    self._joint(out, joint, names)
                elif not static and root.static:
                    # The root stays put while its descendants move: weld it to the world.
                    self._fixed(out, self._fresh(f"{root.name}_world"), "world", root.name)
            elif joint is not None:
                if joint.parent != node.parent:
                    raise WorldgenError(
                        f"joint {joint.name!r} joins {joint.child!r} to {joint.parent!r}, "
                        f"but that node's parent is {node.parent!r}")
                self._joint(out, joint, names)
            else:
                assert node.parent is not None, "every node but the root has a parent"
                self._fixed(out, self._fresh(f"{node.name}_fixed"), node.parent, node.name)
        out.close("model")

    def _fresh(self, base: str) -> str:
        name, k = base, 1
        while name in self.taken:
            name, k = f"{base}_{k}", k + 1
        self.taken.add(name)
        return name

    def _link(self, out: XmlText, node: Node, root: Node, with_inertial: bool) -> None:
        out.open("link", f' name="{node.name}"')
        if node is not root:
            if self.frames:
                _pose(out, node.pose, relative_to=node.parent)
            else:
                in_model = np.linalg.inv(self.scene.world_matrix(root.name)) @ self.scene.world_matrix(node.name)
                _pose(out, matrix_to_pose(in_model))
        if with_inertial:
            _inertial(out, node)
        if node.shape is not None:
            geometry = _geometry(node.shape)
            rgba = node.material.rgba
            if node.collision:
                mu = fmt(node.material.friction)
                out.open("collision", ' name="collision"')
                _write_geometry(out, geometry)
                out.open("surface")
                out.open("friction")
                out.open("ode")
                out.leaf("mu", mu)
                out.leaf("mu2", mu)
                out.close("ode")
                out.close("friction")
                out.close("surface")
                out.close("collision")
            out.open("visual", ' name="visual"')
            _write_geometry(out, geometry)
            _write_material(out, rgba)
            if rgba[3] < 1.0:
                out.leaf("transparency", fmt(1.0 - rgba[3]))
            out.close("visual")
        out.close("link")

    def _joint(self, out: XmlText, joint: Joint, names: set[str]) -> None:
        if joint.parent != "world" and joint.parent not in names:
            raise WorldgenError(
                f"joint {joint.name!r}: parent {joint.parent!r} is not in the model of {joint.child!r}; "
                "SDF joints stay inside one model")
        if joint.kind == "fixed":
            self._fixed(out, joint.name, joint.parent, joint.child,
                        pose=None if _is_identity(joint.pose) else joint.pose)
            return
        out.open("joint", f' name="{joint.name}" type="revolute"')
        if not _is_identity(joint.pose):
            _pose(out, joint.pose)
        out.leaf("parent", joint.parent)
        out.leaf("child", joint.child)
        out.open("axis")
        out.leaf("xyz", fmt_seq(joint.axis))
        out.open("dynamics")
        out.leaf("damping", fmt(joint.damping))
        out.close("dynamics")
        out.open("limit")
        # The written poses are the joint's zero: measure the limits from the initial angle.
        out.leaf("lower", fmt(joint.limits[0] - joint.initial))
        out.leaf("upper", fmt(joint.limits[1] - joint.initial))
        out.leaf("effort", fmt(joint.effort))
        out.leaf("velocity", fmt(joint.velocity))
        out.close("limit")
        out.close("axis")
        out.close("joint")

    @staticmethod
    def _fixed(out: XmlText, name: str, parent: str, child: str, pose: Optional[Pose] = None) -> None:
        out.open("joint", f' name="{name}" type="fixed"')
        if pose is not None:
            _pose(out, pose)
        out.leaf("parent", parent)
        out.leaf("child", child)
        out.close("joint")


def _is_identity(pose: Pose) -> bool:
    return all(fmt(v) == "0" for v in pose.as_list())


def _pose(out: XmlText, pose: Pose, relative_to: Optional[str] = None) -> None:
    out.leaf("pose", fmt_seq(pose.as_list()), "" if relative_to is None else f' relative_to="{relative_to}"')


def _inertial(out: XmlText, node: Node) -> None:
    out.open("inertial")
    if isinstance(node.shape, Mesh):
        # The moments are those of the mesh's bounding box, about the box's centre.
        v = node.shape.scaled_vertices()
        centre = (v.min(axis=0) + v.max(axis=0)) / 2.0
        if any(fmt(c) != "0" for c in centre):
            _pose(out, Pose(*centre))
    out.leaf("mass", fmt(node.mass))
    ixx, iyy, izz = (max(i, MIN_MOMENT) for i in node.inertia)
    out.open("inertia")
    for tag, value in (("ixx", ixx), ("ixy", 0.0), ("ixz", 0.0), ("iyy", iyy), ("iyz", 0.0), ("izz", izz)):
        out.leaf(tag, fmt(value))
    out.close("inertia")
    out.close("inertial")


def _geometry(shape) -> tuple[str, tuple[tuple[str, str], ...]]:
    """``(shape element, ((child, text), ...))`` inside ``<geometry>`` (SDF sizes: full extents, radius, length)."""
    if isinstance(shape, Box):
        return "box", (("size", fmt_seq(shape.size)),)
    if isinstance(shape, Cylinder):
        return "cylinder", (("radius", fmt(shape.radius)), ("length", fmt(shape.length)))
    if isinstance(shape, Sphere):
        return "sphere", (("radius", fmt(shape.radius)),)
    if isinstance(shape, Mesh):
        return "mesh", (("uri", escape_text(shape.uri)), ("scale", fmt_seq(shape.scale)))
    raise WorldgenError(f"the SDF exporter has no geometry for shape {shape!r}")


def _write_material(out: XmlText, rgba) -> None:
    colour = fmt_seq(rgba)
    out.open("material")
    out.leaf("ambient", colour)
    out.leaf("diffuse", colour)
    out.close("material")


def _write_geometry(out: XmlText, geometry) -> None:
    kind, fields = geometry
    out.open("geometry")
    out.open(kind)
    for tag, content in fields:
        out.leaf(tag, content)
    out.close(kind)
    out.close("geometry")


# -- movers: one <actor> each ------------------------------------------------

def script_rows(trajectory, loop: bool) -> np.ndarray:
    """The (k, 3) ``t, x, y`` rows an actor's script plays: a looping mover's own, or a non-looping one's
    followed by a stay of :data:`HOLD_SECONDS` at its last row (see :func:`_sdf_actor`)."""
    rows = np.asarray(trajectory, dtype=float)
    if loop:
        return rows
    return np.vstack([rows, [rows[-1, 0] + HOLD_SECONDS, rows[-1, 1], rows[-1, 2]]])


def _write_actors(out: XmlText, scene: Scene) -> None:
    """Write one ``<actor>`` per mover at the end of the SDF ``<world>`` (``out`` is at its children's depth)."""
    for mover in scene.movers:
        _sdf_actor(out, mover)


def _sdf_actor(out: XmlText, mover: Mover) -> None:
    out.open("actor", f' name="{mover.name}"')
    out.open("link", ' name="body"')
    out.leaf("pose", fmt_seq((0.0, 0.0, mover.height / 2.0, 0.0, 0.0, 0.0)))
    cylinder = ("cylinder", (("radius", fmt(mover.radius)), ("length", fmt(mover.height))))
    out.open("collision", ' name="collision"')
    _write_geometry(out, cylinder)
    out.close("collision")
    out.open("visual", ' name="visual"')
    _write_geometry(out, cylinder)
    _write_material(out, MOVER_RGBA)
    out.close("visual")
    out.close("link")
    # A script that does not loop hangs Gazebo Sim (Fortress to Harmonic) once a rendering sensor plays it:
    # the placeholder that marks "no loop" gets the delay as its start and end, not the trajectory's end,
    # so SceneManager's ActorTrajectoryAt sees a script of total time 0, treats it as looping and wraps
    # time by 0 for ever (docs/gazebo.md). So every script loops, and one that should not ends with the
    # mover standing at its last row for HOLD_SECONDS, a stay the waypoints keep to like any other.
    rows = script_rows(mover.trajectory, mover.loop)
    out.open("script")
    out.leaf("loop", "true")
    out.leaf("delay_start", "0")
    out.leaf("auto_start", "true")
    out.open("trajectory", f' id="0" type="{TRAJECTORY_TYPE}" tension="{fmt(TENSION)}"')
    # One line per waypoint (a person has thousands: a third of the bytes of one element per line).
    pad = "  " * out.depth
    out.parts.extend(f"{pad}<waypoint><time>{fmt(t)}</time><pose>{fmt(x)} {fmt(y)} 0 0 0 0</pose></waypoint>\n"
                     for t, x, y in actor_waypoints(rows, loop=mover.loop).tolist())
    out.close("trajectory")
    out.close("script")
    out.close("actor")
