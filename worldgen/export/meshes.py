"""Mesh files of a scene: one binary STL per distinct ``Mesh.uri``, with stable bytes.

SDF and URDF refer to meshes by ``uri`` (relative to the world folder) and apply
``scale`` themselves, so a file holds the *unscaled* vertices. MJCF inlines its
meshes instead (see :mod:`worldgen.export.mjcf`) and needs no file.

Determinism: trimesh's binary STL writer puts 80 zero bytes in the header (no
name, no date), the vertex and face order is kept (``process=False``), and
every vertex and normal is rounded to :data:`worldgen.floats.DECIMALS` with
negative zero folded to zero before it is cast to float32.
"""

from __future__ import annotations

import numpy as np

from worldgen.errors import SceneError
from worldgen.floats import DECIMALS
from worldgen.scene import Mesh, Scene
from worldgen.scene.ground import ground_scene

__all__ = ["mesh_files", "stl_bytes"]


def _clean(values: np.ndarray) -> np.ndarray:
    """Round to the shared precision; ``+ 0.0`` turns -0.0 into 0.0 (IEEE 754)."""
    return np.round(np.asarray(values, dtype=float), DECIMALS) + 0.0


def stl_bytes(mesh: Mesh) -> bytes:
    """Binary STL of ``mesh``'s unscaled vertices and faces (file order as given)."""
    import trimesh  # heavy import, only paid when a scene has meshes

    tm = trimesh.Trimesh(_clean(mesh.vertices), np.asarray(mesh.faces), process=False)
    # Normals are derived data, but they are written too: round them like every other float.
    tm.face_normals = _clean(tm.face_normals)
    return trimesh.exchange.stl.export_stl(tm)


def mesh_files(scene: Scene) -> dict[str, bytes]:
    """``{uri: STL bytes}`` for every mesh in ``scene``, in node order.

    Two nodes may share a uri only when they share the geometry (their scales
    may differ); anything else would make one file stand for two shapes.
    """
    scene = ground_scene(scene)  # the terrain's mesh, where there is terrain
    files: dict[str, bytes] = {}
    owners: dict[str, tuple[str, Mesh]] = {}
    for node in scene.nodes:
        shape = node.shape
        if not isinstance(shape, Mesh):
            continue
        seen = owners.get(shape.uri)
        if seen is not None:
            other_name, other = seen
            same = np.array_equal(other.vertices, shape.vertices) and np.array_equal(other.faces, shape.faces)
            if not same:
                raise SceneError(
                    f"mesh uri {shape.uri!r} is used by nodes {other_name!r} and {node.name!r} with different geometry"
                )
            continue
        owners[shape.uri] = (node.name, shape)
        files[shape.uri] = stl_bytes(shape)
    return files
