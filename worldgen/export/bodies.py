"""What the writers of a body tree (MJCF and URDF) share: the reserved root name, the joints checked
against the node tree, and mass properties as both write them."""

from __future__ import annotations

from worldgen.errors import SceneError
from worldgen.floats import fmt, round_float
from worldgen.scene import Joint, Node, Scene

__all__ = ["RESERVED_NAME", "SMALLEST", "mass_properties", "joints_by_child"]

#: MuJoCo's world body, and URDF's conventional fixed root, are called this.
RESERVED_NAME = "world"
#: The smallest positive number that survives 6-decimal output: a tiny body's mass or
#: moment rounded to 0 would be rejected by MuJoCo, so it is written as this instead.
SMALLEST = 1e-6


def mass_properties(node: Node) -> tuple[str, tuple[str, str, str]]:
    """(mass, (ixx, iyy, izz)) as written in MJCF and URDF, each at least :data:`SMALLEST`."""
    def text(x: float) -> str:
        return fmt(max(round_float(x), SMALLEST))
    ixx, iyy, izz = node.inertia
    return text(node.mass), (text(ixx), text(iyy), text(izz))


def joints_by_child(scene: Scene) -> dict[str, Joint]:
    """``{child node name: Joint}``, after checking each joint fits the node tree.

    A joint must connect a node to that node's parent (``"world"`` for a root
    node), and a node hangs on at most one joint.
    """
    found: dict[str, Joint] = {}
    names: set[str] = set()
    for joint in scene.joints:
        if joint.name in names:
            raise SceneError(f"joint name {joint.name!r} is used twice; joint names must be unique")
        names.add(joint.name)
        if joint.child == RESERVED_NAME:
            raise SceneError(f"joint {joint.name!r}: the world cannot be a joint's child")
        if joint.child in found:
            raise SceneError(f"node {joint.child!r} is the child of joints {found[joint.child].name!r} and {joint.name!r}")
        parent = scene.node(joint.child).parent or RESERVED_NAME
        if joint.parent != parent:
            raise SceneError(
                f"joint {joint.name!r} connects {joint.parent!r} to {joint.child!r}, "
                f"but the node's parent is {parent!r}"
            )
        found[joint.child] = joint
    for node in scene.nodes:
        if node.name == RESERVED_NAME:
            raise SceneError(f"node name {RESERVED_NAME!r} is reserved for the world frame in MJCF and URDF")
    return found
