"""The door generator and articulated doors end to end.

Every figure here is re-derived from world.json alone with plain geometry
(axis-aligned boxes and the leaf as a rectangle turned about its hinge), not
through worldgen.scene.doors or the feasibility code; simulators are the real ones.
"""

from __future__ import annotations

import math

import mujoco
import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st
from lxml import etree
from support.reftools_mujoco import load, load_and_step
from support.reftools_sdf import check_sdf, dump_sdf
from support.reftools_urdf import check_urdf

import worldgen
from worldgen.errors import InfeasibleError, ParameterError
from worldgen.export.metadata import validate
from worldgen.export.xml import safe_parser

SPACING_FRACTION = 0.25  # path samples every robot radius / 4, as docs/world-json.md asks


# -- independent geometry ------------------------------------------------------

def _rect_distance(p: np.ndarray, corner: np.ndarray, u: np.ndarray, v: np.ndarray, lu: float, lv: float) -> np.ndarray:
    """Distance from points p (n, 2) to the rectangle corner + [0, lu] u + [0, lv] v (u, v orthonormal)."""
    rel = p - corner
    a, b = rel @ u, rel @ v
    da = np.maximum(np.maximum(-a, a - lu), 0.0)
    db = np.maximum(np.maximum(-b, b - lv), 0.0)
    return np.hypot(da, db)


def _turn(vec: np.ndarray, angle: float) -> np.ndarray:
    c, s = math.cos(angle), math.sin(angle)
    return np.array([c * vec[0] - s * vec[1], s * vec[0] + c * vec[1]])


def leaf_rectangle(meta: dict, door: dict, angle: float):
    """(corner, u, v, lu, lv) of the leaf's floor shadow at ``angle``, from world.json alone.

    The hinge is the leaf's corner on the face of the side it opens into: closed,
    the leaf runs from the hinge across the doorway (towards its centre) and
    its thickness goes back into the wall (against the passage normal).
    """
    leaf = next(e for e in meta["entities"] if e["name"] == door["name"])
    lw, lt, _ = leaf["shape"]["size"]
    hinge = np.array(door["hinge"][:2])
    n = np.array(door["passage"]["normal"])
    along = np.array([-n[1], n[0]])
    if (np.array(door["passage"]["center"]) - hinge) @ along < 0:
        along = -along
    turn = angle * door["axis"][2]
    return hinge, _turn(along, turn), _turn(-n, turn), lw, lt


def open_limit(door: dict) -> float:
    lo, hi = door["limits"]
    return lo if abs(lo) > abs(hi) else hi


def obstacle_distance(meta: dict, pts: np.ndarray, doors_open: bool) -> np.ndarray:
    """Distance from each point to the nearest collider shadow below the robot's top (+ clearance)."""
    top = meta["robot"]["height"] + meta["robot"]["clearance"]
    best = np.full(len(pts), np.inf)
    leaves = {d["name"]: d for d in meta["doors"]}
    for e in meta["entities"]:
        if e["role"] in ("floor", "marker") or e["aabb"][0][2] >= top:
            continue
        if e["name"] in leaves:
            door = leaves[e["name"]]
            rect = leaf_rectangle(meta, door, open_limit(door) if doors_open else door["angle"])
            d = _rect_distance(pts, *rect)
        else:  # walls, jambs, heads: boxes turned by multiples of 90 degrees, so the aabb is exact
            assert abs(math.sin(2 * e["pose"][5])) < 1e-9, e["name"]
            (x0, y0, _), (x1, y1, _) = e["aabb"]
            d = _rect_distance(pts, np.array([x0, y0]), np.array([1.0, 0]), np.array([0, 1.0]), x1 - x0, y1 - y0)
        best = np.minimum(best, d)
    return best


def sample(waypoints, spacing: float) -> np.ndarray:
    w = np.asarray(waypoints, dtype=float)
    out = [w[:1]]
    for a, b in zip(w[:-1], w[1:]):
        n = max(1, math.ceil(np.hypot(*(b - a)) / spacing))
        out.append(a + (b - a) * (np.arange(1, n + 1) / n)[:, None])
    return np.vstack(out)


def recheck(meta: dict) -> None:
    """Spawn, goal and the whole path keep robot.clearance, with every door at its open limit."""
    robot = meta["robot"]
    need = robot["radius"] + robot["clearance"] - 1e-6
    for task in meta["tasks"]:
        pts = sample(task["path"]["waypoints"], robot["radius"] * SPACING_FRACTION)
        assert np.allclose(pts[0], task["spawn"][:2]) and np.allclose(pts[-1], task["goal"][:2])
        d = obstacle_distance(meta, pts, doors_open=True)
        assert d.min() >= need, (task["id"], float(d.min()), pts[int(np.argmin(d))].tolist())
        lo, hi = np.array(meta["bounds"]["min"]), np.array(meta["bounds"]["max"])
        assert np.all(pts - lo >= need) and np.all(hi - pts >= need)
        # The robot starts among the doors as they are: its ends are free then too.
        ends = np.array([task["spawn"][:2], task["goal"][:2]])
        assert obstacle_distance(meta, ends, doors_open=False).min() >= need


def crosses_wall(waypoints, x: float) -> bool:
    xs = np.asarray(waypoints, dtype=float)[:, 0]
    return bool(np.any((xs[:-1] - x) * (xs[1:] - x) < 0))


def check_doors(meta: dict, params: dict) -> None:
    """doors[] against the entities: passage in the wall gap, normal across the wall, widths, hinge on the frame."""
    ents = {e["name"]: e for e in meta["entities"]}
    assert len(meta["doors"]) == params.get("n_doors", 1)
    for k, door in enumerate(meta["doors"]):
        assert door["name"] == f"door_{k}" and door["joint"] == f"door_{k}_hinge"
        jamb_s, jamb_n = ents[f"door_{k}_jamb_s"]["aabb"], ents[f"door_{k}_jamb_n"]["aabb"]
        wall_x = (jamb_s[0][0] + jamb_s[1][0]) / 2
        gap = (jamb_s[1][1], jamb_n[0][1])  # between the jambs' inner faces
        p = door["passage"]
        assert p["center"][0] == pytest.approx(wall_x, abs=1e-6)
        assert gap[0] < p["center"][1] < gap[1]
        assert p["center"][1] == pytest.approx(sum(gap) / 2, abs=1e-6)
        assert p["width"] == pytest.approx(gap[1] - gap[0], abs=1e-6) == params.get("door_width", 0.9)
        assert door["width"] == pytest.approx(p["width"])
        # The walls run along y: the normal is along x (perpendicular), a unit vector.
        assert abs(p["normal"][1]) < 1e-9 and abs(abs(p["normal"][0]) - 1) < 1e-9
        assert door["axis"][:2] == [0.0, 0.0] and abs(door["axis"][2]) == 1.0
        # Hinge on the face the leaf opens into, at a doorway edge, on the floor.
        t = jamb_s[1][0] - jamb_s[0][0]
        assert door["hinge"][0] == pytest.approx(wall_x + p["normal"][0] * t / 2, abs=1e-6)
        assert min(abs(door["hinge"][1] - gap[0]), abs(door["hinge"][1] - gap[1])) < 0.02
        assert door["hinge"][2] == 0.0
        lo, hi = door["limits"]
        assert lo <= door["angle"] <= hi
        expected_state = "closed" if door["angle"] == 0 else "open" if door["angle"] == open_limit(door) else "ajar"
        assert door["state"] == expected_state
        # The leaf entity sits where the rectangle model says, at its initial angle.
        corner, u, v, lw, lt = leaf_rectangle(meta, door, door["angle"])
        centre = corner + u * lw / 2 + v * lt / 2
        assert ents[door["name"]]["pose"][:2] == pytest.approx(centre.tolist(), abs=1e-5)
        assert ents[door["name"]]["role"] == "door" and ents[door["name"]]["static"] is False
    for task in meta["tasks"]:
        closed_on_path = any(d["state"] == "closed" and crosses_wall(task["path"]["waypoints"], d["passage"]["center"][0])
                             for d in meta["doors"])
        if closed_on_path:  # a closed leaf in the way; ajar ones are judged by tests/feasibility/test_requires_door_open.py
            assert task["requires_door_open"] is True


# -- generated worlds through every reference tool ------------------------------

door_params = st.fixed_dictionaries({
    "n_doors": st.integers(1, 3),
    "door_width": st.sampled_from([0.8, 0.9, 1.1]),
    "leaf_thickness": st.sampled_from([0.03, 0.05, 0.08]),
    "hinge_side": st.sampled_from(["left", "right", "random"]),
    "swing": st.sampled_from(["push", "pull", "random"]),
    "state": st.sampled_from(["closed", "open", "ajar", "random"]),
    "limits": st.sampled_from([[0.0, 1.4], [0.0, math.pi / 2], [0.0, 2.5]]),
    "angle": st.sampled_from([0.3, 0.7]),
    "size": st.sampled_from([[8.0, 4.0], [12.0, 5.0], [9.0, 3.0]]),
    "n_tasks": st.integers(1, 2),
})


@settings(max_examples=12, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(params=door_params, seed=st.integers(0, 2**32))
def test_door_worlds_pass_reference_tools_and_recheck(tmp_path_factory, params, seed):
    world = worldgen.generate("door", seed=seed, **params)
    meta = world.metadata
    validate(meta)
    assert meta["feasibility"]["feasible"]
    check_doors(meta, params)
    recheck(meta)
    info = {c["name"]: c for c in meta["feasibility"]["informational"]}
    assert "reachable_initial_state" in info
    if any(d["state"] == "closed" for d in meta["doors"]):
        assert info["reachable_initial_state"]["ok"] is False  # a closed door is in the only way through
    if info["reachable_initial_state"]["ok"]:  # the longest path with the leaves held, never shorter than opened
        assert info["reachable_initial_state"]["value"] >= max(t["path"]["length"] for t in meta["tasks"]) - 1e-6
    folder = world.write(tmp_path_factory.mktemp("door"), preview=False)
    ok, messages = check_sdf(folder / "world.sdf")
    assert ok, messages
    check_urdf(folder / "world.urdf")
    load_and_step(world.to_mjcf(), steps=300)
    load_and_step(folder / "world.urdf", steps=300)


def test_axis_limits_and_initial_angle_agree_across_formats(tmp_path):
    world = worldgen.generate("door", seed=4, n_doors=2, state="ajar", angle=0.6, hinge_side="random",
                              swing="random", limits=[0.0, 2.0])
    meta = world.metadata
    folder = world.write(tmp_path, preview=False)
    mj = load(world.to_mjcf())
    ur = load(folder / "world.urdf")
    sdf = dump_sdf(folder / "world.sdf")
    for model, shifted in ((mj, False), (ur, True)):
        data = mujoco.MjData(model)
        mujoco.mj_forward(model, data)
        for door in meta["doors"]:
            j = model.joint(door["joint"])
            lo, hi = door["limits"]
            offset = door["angle"] if shifted else 0.0  # URDF has no initial angle: its zero is the initial pose
            assert j.range.tolist() == pytest.approx([lo - offset, hi - offset], abs=1e-6)
            assert model.qpos0[j.qposadr[0]] == pytest.approx(door["angle"] - offset, abs=1e-6)
            assert data.xaxis[j.id].tolist() == pytest.approx(door["axis"], abs=1e-6)
            assert data.xanchor[j.id][:2].tolist() == pytest.approx(door["hinge"][:2], abs=1e-6)
            assert model.dof_damping[j.dofadr[0]] == pytest.approx(door["damping"])
            # The leaf where world.json has it (its geom: URDF's link frame is the hinge's).
            assert data.geom_xpos[model.geom(door["name"]).id][:2].tolist() == pytest.approx(
                next(e["pose"][:2] for e in meta["entities"] if e["name"] == door["name"]), abs=1e-5)
    for door in meta["doors"]:
        joint = next(v for k, v in sdf["joints"].items() if k.endswith("::" + door["joint"]))
        assert joint["type"] == "revolute" and joint["child"] == door["name"]
        lo, hi = door["limits"]
        assert joint["limits"] == pytest.approx([lo - door["angle"], hi - door["angle"]], abs=1e-6)
        assert joint["damping"] == pytest.approx(door["damping"])
        # The axis is given in the joint frame, which is not turned: it is the world axis.
        assert joint["axis"] == pytest.approx(door["axis"], abs=1e-6)


# -- a closed door blocks, an opened one lets through (MuJoCo) --------------------

def _with_probe(mjcf: str, start, radius: float = 0.1) -> str:
    """The MJCF with a free, weightless sphere (gravity compensated) added at ``start``."""
    root = etree.fromstring(mjcf.encode(), safe_parser())
    body = etree.SubElement(root.find("worldbody"), "body", name="probe", pos=" ".join(map(str, start)), gravcomp="1")
    etree.SubElement(body, "freejoint", name="probe")
    etree.SubElement(body, "geom", name="probe", type="sphere", size=str(radius), mass="1")
    return etree.tostring(root).decode()


def test_closed_door_blocks_a_probe_and_an_opened_one_lets_it_through():
    # A pull door seen from the spawn side: pushing it only drives it into its closed stop.
    world = worldgen.generate("door", seed=0, state="closed", swing="pull", door_y=0.0, size=[8.0, 4.0])
    door = world.metadata["doors"][0]
    n = np.array(door["passage"]["normal"])  # points back to the spawn side for a pull door
    centre = np.array(door["passage"]["center"])
    start = [*(centre + 1.0 * n), 0.8]
    model = load(_with_probe(world.to_mjcf(), start))
    leaf = model.geom(door["name"]).id

    def run(opened: bool) -> tuple[float, int]:
        data = mujoco.MjData(model)
        hinge = model.joint(door["joint"])
        if opened:
            data.qpos[hinge.qposadr[0]] = open_limit(door)
        mujoco.mj_forward(model, data)
        # A ray along the doorway's axis at probe height: what does it meet first?
        hit = np.array([-1], dtype=np.int32)
        mujoco.mj_ray(model, data, np.array(start, dtype=float), np.array([*(-n), 0.0]), None, 1,
                       model.body("probe").id, hit)
        probe = model.joint("probe")
        data.qvel[probe.dofadr[0]:probe.dofadr[0] + 2] = -2.0 * n
        for _ in range(1000):  # 2 s at 2 m/s: far past the wall if nothing stops it
            mujoco.mj_step(model, data)
        travelled = float((data.qpos[probe.qposadr[0]:probe.qposadr[0] + 2] - centre) @ -n)
        return travelled, int(hit[0])

    blocked, ray_closed = run(opened=False)
    passed, ray_open = run(opened=True)
    assert ray_closed == leaf and ray_open != leaf
    assert blocked < 0.0  # still on the spawn side of the wall's centre line
    assert passed > 1.0  # well through the doorway


# -- presets, requires_door_open, errors ------------------------------------------

def test_door_crossing_scenario_is_expressible():
    """"A closed door at x = 3 m, waypoint beyond it at (6, 0)": door_x, door_y, spawn and goal."""
    world = worldgen.generate("door", seed=0, size=[14.0, 4.0], door_x=3.0, door_y=0.0, state="closed",
                              spawn=[0.0, 0.0, 0.0], goal=[6.0, 0.0])
    meta = world.metadata
    task = meta["tasks"][0]
    assert task["spawn"][:2] == [0.0, 0.0] and task["goal"][:2] == [6.0, 0.0]
    assert meta["doors"][0]["passage"]["center"] == [3.0, 0.0]
    assert crosses_wall(task["path"]["waypoints"], 3.0)
    assert task["requires_door_open"] is True
    assert meta["feasibility"]["informational"][0]["ok"] is False
    # Straight through the doorway's centre: the shortest path is the straight line.
    assert task["path"]["length"] == pytest.approx(6.0, rel=1e-3)
    recheck(meta)


def test_open_doors_need_no_opening():
    meta = worldgen.generate("door", seed=1, state="open", n_doors=2).metadata
    assert not any(t["requires_door_open"] for t in meta["tasks"])
    info = meta["feasibility"]["informational"][0]
    assert info["name"] == "reachable_initial_state" and info["ok"] is True
    # Nothing to open: the check with the leaves held finds the reference path's own length.
    assert info["value"] == max(t["path"]["length"] for t in meta["tasks"])


def test_a_door_that_cannot_open_far_enough_is_infeasible():
    # Opening 0.3 rad leaves a slit no robot passes: the world cannot be driven, and says which check.
    with pytest.raises(InfeasibleError, match="path_exists"):
        worldgen.generate("door", seed=0, limits=[0.0, 0.3], max_attempts=3)


def test_same_parameters_same_world():
    a = worldgen.generate("door", seed=9, n_doors=3, state="random", hinge_side="random", swing="random")
    b = worldgen.generate("door", seed=9, n_doors=3, state="random", hinge_side="random", swing="random")
    assert a.to_sdf() == b.to_sdf() and a.to_mjcf() == b.to_mjcf() and a.to_json() == b.to_json()


@pytest.mark.parametrize("params, message", [
    ({"door_width": 5.0}, "parameter 'door_width' must be in (0.02, 3.9] m"),
    ({"door_width": 0.0}, "parameter 'door_width' must be in [0.1, 20]"),
    ({"limits": [0.0, 3.5]}, "parameter 'limits' must be in [0, 3], got 3.5"),
    ({"limits": [0.5, 1.5]}, "parameter 'limits' must start at 0 (closed) for state closed"),
    ({"limits": [1.0, 1.0], "state": "open"}, "parameter 'limits' must be [lo, hi] with lo < hi"),
    ({"state": "ajar", "angle": 2.0}, "parameter 'angle' must lie strictly inside limits"),
    ({"state": "half"}, "parameter 'state' must be one of closed, open, ajar, random"),
    ({"hinge_side": "top"}, "parameter 'hinge_side' must be one of left, right, random"),
    ({"swing": 2}, "parameter 'swing' must be one of push, pull, random"),
    ({"door_height": 2.6}, "parameter 'door_height' must be in [0.1, 2.45] m"),
    ({"door_y": 1.9}, "parameter 'door_y' must be in [-1.5, 1.5] m"),
    ({"door_x": 4.0}, "parameter 'door_x' must be in (-4, 4) m"),
    ({"door_x": 3.5}, "parameter 'door_x' leaves room 1"),
    ({"n_doors": 9}, "parameter 'size' leaves room 0"),
    ({"n_doors": 0}, "parameter 'n_doors' must be in [1, 16]"),
    ({"spawn": [9.0, 0.0, 0.0]}, "parameter 'spawn' must keep the robot's 0.25 m disc on the floor"),
    ({"leaf_thickness": -1}, "parameter 'leaf_thickness' must be in [0.005, 1]"),
    ({"robot_height": 1.96}, "parameter 'robot_height' must be at most door_height - clearance = 1.95 m"),
    # Found by `make fuzz`: touching the head is a contact for every checker, so exactly as tall is refused.
    ({"robot_height": 2.0, "clearance": 0.0}, "parameter 'robot_height' must be below door_height = 2 m"),
])
def test_bad_parameters_get_one_line_errors(params, message):
    with pytest.raises(ParameterError) as err:
        worldgen.generate("door", seed=0, **params)
    text = str(err.value)
    assert "\n" not in text
    assert text.startswith(message), text


def leaf_contacts_at(model, data, angle_of) -> list[tuple[str, str]]:
    """(leaf, wall or frame) geom names in contact with every hinge at ``angle_of(joint)``, after mj_forward."""
    for j in range(model.njnt):
        data.qpos[model.jnt_qposadr[j]] = angle_of(j)
    mujoco.mj_forward(model, data)
    out = []
    for c in data.contact[: data.ncon]:
        names = sorted((model.geom(c.geom1).name, model.geom(c.geom2).name))
        leaves = [n for n in names if n.startswith("door_") and n.count("_") == 1]
        # Leaf against wall or frame; two leaves opening into one room may meet (not a wall: left to the doors).
        if c.dist <= 0 and len(leaves) == 1:
            out.append(tuple(names))
    return out


@settings(max_examples=60, suppress_health_check=[HealthCheck.too_slow], deadline=None)
@given(
    seed=st.integers(0, 10_000),
    hi=st.floats(0.2, 3.0),
    leaf_thickness=st.sampled_from([0.02, 0.04, 0.3, 1.0]),
    door_width=st.floats(0.4, 2.0),
    n_doors=st.integers(1, 3),
    hinge_side=st.sampled_from(["left", "right", "random"]),
    swing=st.sampled_from(["push", "pull", "random"]),
    sy=st.floats(2.2, 6.0),
)
def test_every_leaf_at_both_limits_touches_no_wall_or_frame(seed, hi, leaf_thickness, door_width, n_doors,
                                                            hinge_side, swing, sy):
    """MuJoCo's own collision detection, every hinge at its lower and at its upper limit."""
    try:
        world = worldgen.generate("door", seed=seed, state="open", limits=[0.0, round(hi, 3)], size=[5.0 * n_doors, sy],
                                  n_doors=n_doors, leaf_thickness=leaf_thickness, door_width=round(door_width, 3),
                                  hinge_side=hinge_side, swing=swing, max_attempts=3)
    except (ParameterError, InfeasibleError):
        return
    model = mujoco.MjModel.from_xml_string(world.to_mjcf())
    data = mujoco.MjData(model)
    for end in (0, 1):
        touching = leaf_contacts_at(model, data, lambda j: model.jnt_range[j][end])
        assert not touching, f"limit {end}: {touching}"
    for door in world.metadata["doors"]:
        assert door["limits"][1] <= round(hi, 3) + 1e-9


def test_limits_past_the_room_stop_at_the_wall_issue_reproducer():
    # limits 0..3.0 rad with the doorway near the outer wall: the leaf used to start 0.12 m inside it.
    world = worldgen.generate("door", seed=0, state="open", limits=[0.0, 3.0])
    (door,) = world.metadata["doors"]
    assert 1.5708 < door["limits"][1] < 3.0 and door["angle"] == door["limits"][1]
    model = mujoco.MjModel.from_xml_string(world.to_mjcf())
    assert not leaf_contacts_at(model, mujoco.MjData(model), lambda j: model.jnt_range[j][1])
    # The stop is tight: a little further and the leaf is in the wall.
    assert leaf_contacts_at(model, mujoco.MjData(model), lambda j: model.jnt_range[j][1] + 0.05)


def test_swing_stop_exact_references():
    from worldgen.generators.door import LEAF_GAP, swing_stop

    # Room enough beside and ahead: the leaf may open until it lies on the wall face.
    assert swing_stop(0.88, 0.04, beside=5.0, ahead=5.0) == math.floor(math.pi * 1e6) / 1e6
    # Only 0.44 m + gap of wall beside the hinge: -0.88 cos a = 0.44 -> a = 2 pi / 3.
    assert swing_stop(0.88, 0.0, beside=0.44 + LEAF_GAP, ahead=5.0) == pytest.approx(2 * math.pi / 3, abs=1e-6)
    # A room just as long as the leaf ahead, thick leaf: stops where the far corner meets the wall.
    a = swing_stop(0.88, 0.3, beside=5.0, ahead=0.88 + LEAF_GAP)
    assert 0.88 * math.sin(a) - 0.3 * math.cos(a) == pytest.approx(0.88, abs=1e-5)


@pytest.mark.parametrize("height,clearance", [(1.95, 0.05), (1.999, 0.0)])
def test_a_robot_as_tall_as_the_doorway_allows_drives_under_its_head_without_touching(height, clearance):
    from worldgen import oracles

    world = worldgen.generate("door", seed=3, robot_height=height, clearance=clearance, state="open")
    assert world.feasibility.feasible
    task = world.metadata["tasks"][0]
    assert task["path"]["min_clearance"] >= clearance - 1e-6
    assert not task["requires_door_open"]  # the path goes through the open doorway, under its head
    xy = np.asarray(task["path"]["waypoints"], dtype=float)
    assert oracles.collisions(np.column_stack([np.arange(len(xy), dtype=float), xy]), world) == []


def _sweep(door: dict, leaf: dict):
    """The floor a leaf sweeps from its initial angle to its open limit, from world.json alone: its box as
    ``entities`` has it (at the initial angle), turned about the hinge in 1/400ths of the way, each two
    positions joined by their convex hull."""
    import shapely

    (cx, cy, _, _, _, yaw), (lx, ly, _) = leaf["pose"], leaf["shape"]["size"]
    local = np.array([[-lx, -ly], [lx, -ly], [lx, ly], [-lx, ly]]) / 2
    c, s_ = math.cos(yaw), math.sin(yaw)
    corners = local @ np.array([[c, s_], [-s_, c]]) + [cx, cy]
    hinge = np.asarray(door["hinge"][:2], dtype=float)
    lo, hi = door["limits"]
    opened = hi if abs(hi) >= abs(lo) else lo
    turns = (np.linspace(door["angle"], opened, 401) - door["angle"]) * float(door["axis"][2])
    at = [(corners - hinge) @ np.array([[math.cos(t), math.sin(t)], [-math.sin(t), math.cos(t)]]) + hinge
          for t in turns]
    return shapely.union_all([shapely.MultiPoint(np.vstack([p, q])).convex_hull for p, q in zip(at, at[1:])])


@settings(max_examples=25, deadline=None)
@given(seed=st.integers(0, 10_000))
def test_no_spawn_or_goal_lies_where_a_leaf_opening_would_push_the_robot(seed):
    # Door seed 171 of benchmarks/bench_drive_dynamic.py spawned 0.68 m from the hinge of a 0.9 m pull leaf:
    # opened, it pressed the robot into the wall (stuck).
    import shapely

    world = worldgen.generate("door", seed=seed, state="random", swing="random", n_doors=2, n_tasks=2)
    meta = world.metadata
    inflation = meta["robot"]["radius"] + meta["robot"]["clearance"]
    for door in meta["doors"]:
        sweep = _sweep(door, next(e for e in meta["entities"] if e["name"] == door["name"]))
        for task in meta["tasks"]:
            for where in ("spawn", "goal"):
                assert shapely.Point(task[where][:2]).distance(sweep) >= inflation - 1e-3, (seed, door["name"], where)
