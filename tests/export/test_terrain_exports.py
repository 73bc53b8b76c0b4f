"""The terrain in the exported files: MuJoCo's ground under sampled points is world.json's height there
(within 1 cm; mj_ray straight down), on every kind of element and on the floor between them; a world with
terrain steps in MuJoCo without warnings; a flat world's MJCF has no trace of it."""

import json
import math

import numpy as np
import pytest
from support.reftools_mujoco import load_and_step

import worldgen
from worldgen.export.mjcf import to_mjcf
from worldgen.scene.terrain import Ramp, Rough, Step

mujoco = pytest.importorskip("mujoco")

#: The agreement the issue asks for between an engine's ground and the model's, m.
TOLERANCE = 0.01


def ground_heights(model, points: np.ndarray, top: float = 5.0) -> np.ndarray:
    """The height of the first thing a ray straight down from ``top`` meets above each point."""
    data = mujoco.MjData(model)
    mujoco.mj_forward(model, data)
    geom = np.zeros(1, dtype=np.int32)
    down = np.array([0.0, 0.0, -1.0])
    return np.array([top - mujoco.mj_ray(model, data, np.array([x, y, top]), down, None, 1, -1, geom)
                     for x, y in points])


@pytest.mark.parametrize("seed", [0, 4])
def test_mujoco_ground_is_world_json_height_at_sampled_points(seed):
    world = worldgen.generate("terrain", seed, size=[12, 12], n_ramps=2, n_kerbs=4, pothole_share=0.5, n_rough=2,
                              rough_amplitude=0.03, n_obstacles=0)
    terrain = world.scene.terrain
    assert {type(e) for e in terrain.elements} == {Ramp, Step, Rough}
    assert any(isinstance(e, Step) and e.height < 0 for e in terrain.elements)  # a pothole cut in the floor
    rng = np.random.default_rng(seed)
    points = [e.to_world(rng.uniform([-e.length / 2, -e.width / 2], [e.length / 2, e.width / 2], (150, 2)))
              for e in terrain.elements]
    points = np.vstack(points + [rng.uniform(-5.8, 5.8, (300, 2))])
    model = mujoco.MjModel.from_xml_string(to_mjcf(world.scene).decode())
    got = ground_heights(model, points)
    want = terrain.heights(points)
    assert np.abs(got - want).max() < TOLERANCE, points[np.argmax(np.abs(got - want))]


def test_a_terrain_world_steps_in_mujoco_without_warnings():
    world = worldgen.generate("terrain", 1, size=[10, 10], n_kerbs=3, pothole_share=1.0)
    load_and_step(world.folder_blobs(formats=["mjcf"])["world.mjcf.xml"], steps=50)


def test_a_flat_world_has_no_terrain_in_its_mjcf():
    xml = to_mjcf(worldgen.generate("cluttered", 0, size=[6, 6], n_obstacles=3).scene).decode()
    assert "terrain_" not in xml and "hfield" not in xml


def mesh_top(triangles: np.ndarray, points: np.ndarray) -> np.ndarray:
    """The highest point of the (k, 3, 3) triangles straight above or below each (x, y) point (nan where none
    covers it): what a ray cast straight down onto the mesh meets first."""
    a, b, c = triangles[:, 0], triangles[:, 1], triangles[:, 2]
    e1, e2 = b[:, :2] - a[:, :2], c[:, :2] - a[:, :2]
    det = e1[:, 0] * e2[:, 1] - e1[:, 1] * e2[:, 0]
    flat = np.abs(det) < 1e-12  # upright faces (walls) are met edge-on by a vertical ray
    out = np.full(len(points), np.nan)
    for k, p in enumerate(points):
        d = p - a[:, :2]
        with np.errstate(divide="ignore", invalid="ignore"):
            s = (d[:, 0] * e2[:, 1] - d[:, 1] * e2[:, 0]) / det
            t = (e1[:, 0] * d[:, 1] - e1[:, 1] * d[:, 0]) / det
            inside = ~flat & (s >= -1e-9) & (t >= -1e-9) & (s + t <= 1 + 1e-9)
            if inside.any():
                out[k] = (a[:, 2] + s * (b[:, 2] - a[:, 2]) + t * (c[:, 2] - a[:, 2]))[inside].max()
    return out


def test_the_sdf_and_urdf_terrain_mesh_is_world_json_height_and_both_files_load(tmp_path):
    import io

    import trimesh
    from support.reftools_sdf import check_sdf, dump_sdf
    from support.reftools_urdf import check_urdf

    from worldgen.files import SDF_NAME, TERRAIN_MESH_NAME, URDF_NAME

    world = worldgen.generate("terrain", 4, size=[12, 12], n_ramps=2, n_kerbs=4, pothole_share=0.5, n_rough=2,
                              rough_amplitude=0.03, n_obstacles=3)
    folder = world.write(tmp_path)
    ok, messages = check_sdf(folder / SDF_NAME)
    assert ok, messages
    collisions = dump_sdf(folder / SDF_NAME)["collisions"]
    # Potholes: the cut slab is in the mesh, which stands in the floor's place under its name.
    assert [v[0] for k, v in collisions.items() if k.startswith("floor::")] == ["mesh"]
    assert not any(k.startswith("terrain::") for k in collisions)
    check_urdf(folder / URDF_NAME)
    assert TERRAIN_MESH_NAME in (folder / URDF_NAME).read_text()
    mesh = trimesh.load(io.BytesIO((folder / TERRAIN_MESH_NAME).read_bytes()), file_type="stl")
    meta = json.loads((folder / "world.json").read_text())
    assert meta["files"][f"mesh:{TERRAIN_MESH_NAME}"]["path"] == TERRAIN_MESH_NAME
    terrain = world.scene.terrain
    rng = np.random.default_rng(1)
    points = np.vstack([e.to_world(rng.uniform([-e.length / 2, -e.width / 2], [e.length / 2, e.width / 2], (60, 2)))
                        for e in terrain.elements] + [rng.uniform(-5.8, 5.8, (150, 2))])
    got = mesh_top(np.asarray(mesh.triangles), points)
    assert not np.isnan(got).any()
    assert np.abs(got - terrain.heights(points)).max() < TOLERANCE


def test_the_lidar_truth_over_terrain_is_mujocos_ray_casts_and_marks_the_ground_it_meets():
    """A ramp higher than the scan plane reads as a wall where it rises through it: world.json's ranges agree
    with MuJoCo's horizontal rays from the lidar's pose within 1 cm, and the rays that meet the ground are
    marked."""
    world = worldgen.generate("terrain", 3, size=[10, 10], n_ramps=3, ramp_rise=[0.25, 0.3], ramp_incline=[8, 9],
                              n_kerbs=2, kerb_height=[0.15, 0.2], pothole_share=0.0, n_rough=0, n_obstacles=4,
                              lidar_height=0.1, robot_max_incline=20, robot_max_step_up=0.3, robot_max_step_down=0.3,
                              robot_ground_clearance=0.2)
    lidar = json.loads(world.folder_blobs(formats=["mjcf"])["world.json"])["sensors"]["lidar"]
    assert lidar["terrain_returns"], "no ray met the ground: the test would prove nothing"
    model = mujoco.MjModel.from_xml_string(to_mjcf(world.scene).decode())
    data = mujoco.MjData(model)
    mujoco.mj_forward(model, data)
    x, y, z, _, _, yaw = lidar["pose"]
    n = lidar["samples"]
    geom = np.zeros(1, dtype=np.int32)
    step = (lidar["angle_max"] - lidar["angle_min"]) / (n - 1)
    got, met = [], []
    for i in range(n):
        a = yaw + lidar["angle_min"] + i * step
        d = np.array([math.cos(a), math.sin(a), 0.0])
        start = np.array([x, y, z]) + lidar["range_min"] * d
        hit = mujoco.mj_ray(model, data, start, d, None, 1, -1, geom)
        got.append(lidar["range_max"] if hit < 0 else min(hit + lidar["range_min"], lidar["range_max"]))
        met.append(hit >= 0 and mujoco.mj_id2name(model, mujoco.mjtObj.mjOBJ_GEOM, int(geom[0])).startswith("terrain_"))
    assert np.abs(np.array(got) - np.array(lidar["ranges"])).max() < TOLERANCE
    # The marked rays are exactly those whose first hit in MuJoCo is a piece of the terrain.
    assert lidar["terrain_returns"] == np.flatnonzero(met).tolist()


def test_the_usd_stage_carries_the_terrain_as_a_static_triangle_mesh_collider_at_world_json_height():
    pytest.importorskip("pxr")
    from pxr import Usd, UsdGeom, UsdPhysics

    from worldgen.export.usd import to_usd

    world = worldgen.generate("terrain", 4, size=[12, 12], n_ramps=2, n_kerbs=4, pothole_share=0.5, n_rough=2,
                              rough_amplitude=0.03, n_obstacles=3)
    stage = Usd.Stage.CreateInMemory()
    stage.GetRootLayer().ImportFromString(to_usd(world.scene).decode())
    (mesh,) = [c for c in stage.GetPrimAtPath("/World/floor").GetChildren() if c.GetTypeName() == "Mesh"]
    assert mesh.HasAPI(UsdPhysics.CollisionAPI) and mesh.HasAPI(UsdPhysics.MeshCollisionAPI)
    assert mesh.GetAttribute("physics:approximation").Get() == "none"  # the triangles, not a hull
    points = np.array(mesh.GetAttribute("points").Get(), dtype=float)
    faces = np.array(mesh.GetAttribute("faceVertexIndices").Get()).reshape(-1, 3)
    xform = np.array(UsdGeom.Xformable(mesh).ComputeLocalToWorldTransform(Usd.TimeCode.Default())).T
    points = points @ xform[:3, :3].T + xform[:3, 3]
    rng = np.random.default_rng(2)
    terrain = world.scene.terrain
    samples = np.vstack([e.to_world(rng.uniform([-e.length / 2, -e.width / 2], [e.length / 2, e.width / 2], (40, 2)))
                         for e in terrain.elements] + [rng.uniform(-5.8, 5.8, (100, 2))])
    got = mesh_top(points[faces], samples)
    assert np.abs(got - terrain.heights(samples)).max() < TOLERANCE


def test_the_preview_draws_the_terrain_and_its_undrivable_ground_as_no_go():
    from worldgen.export.preview import draw
    from worldgen.export.preview_frame import layout
    from worldgen.export.topdown import COLOURS
    from worldgen.scene.drivable import terrain_footprints

    world = worldgen.generate("terrain", 2, size=[12, 12], n_kerbs=4, kerb_height=[0.01, 0.08], n_ramps=2,
                              ramp_incline=[8, 14], n_rough=1)
    meta = json.loads(world.folder_blobs(formats=["mjcf"])["world.json"])
    image = draw(meta)
    lay = layout(meta, image.width)
    forbidden = {f.name.split("_edge")[0] for f in terrain_footprints(world.scene, world.robot)}
    drivable = [e for k, e in enumerate(world.scene.terrain.elements) if f"terrain_{k}" not in forbidden]
    undrivable = [e for k, e in enumerate(world.scene.terrain.elements) if f"terrain_{k}" in forbidden]
    assert drivable and undrivable
    for e in drivable:
        assert image.getpixel(tuple(round(v) for v in lay.px(e.cx, e.cy))) == COLOURS["terrain"]
    for e in undrivable:  # the whole element, or the ring round its edges, is tinted as a no-go zone
        u, v = lay.px(*e.to_world(np.array([[e.length / 2 - 0.01, 0.0]]))[0])
        assert image.getpixel((round(u), round(v))) != COLOURS["terrain"]
    flat = dict(meta)
    flat.pop("terrain")
    assert np.asarray(draw(flat)).tobytes() != np.asarray(image).tobytes()
