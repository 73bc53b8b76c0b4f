"""preview.png: a valid, deterministic PNG whose pixels show the world where world.json says it is."""

from __future__ import annotations

import copy
import hashlib
import json
import math
import subprocess
import sys

import numpy as np
import pytest
from PIL import Image

import worldgen
from worldgen.cli import main
from worldgen.errors import ParameterError
from worldgen.export.preview import COLOURS, NOGO_ALPHA, draw, layout, render
from worldgen.files import PREVIEW_NAME


@pytest.fixture(scope="module")
def folder(tmp_path_factory):
    world = worldgen.generate("cluttered", seed=5)
    return world.write(tmp_path_factory.mktemp("preview"))


@pytest.fixture(scope="module")
def meta(folder):
    return json.loads((folder / "world.json").read_text())


@pytest.fixture(scope="module")
def image(folder):
    return Image.open(folder / PREVIEW_NAME).convert("RGB")


def _pixel_of(meta, x, y, width=800):
    """World (x, y) -> integer pixel, from the layout's published numbers, with +y up."""
    lay = layout(meta, width)
    return int(lay.left + (x - lay.x0) * lay.scale), int(lay.top + (lay.y1 - y) * lay.scale)


def _close(a, b, tol=3):
    return all(abs(int(p) - int(q)) <= tol for p, q in zip(a, b))


def _chunks(data: bytes) -> list[bytes]:
    out, at = [], 8
    while at < len(data):
        n = int.from_bytes(data[at:at + 4], "big")
        out.append(data[at + 4:at + 8])
        at += 12 + n
    return out


def test_png_is_valid_with_the_expected_size_and_no_varying_chunks(folder, meta):
    data = (folder / PREVIEW_NAME).read_bytes()
    with Image.open(folder / PREVIEW_NAME) as im:
        im.verify()
    with Image.open(folder / PREVIEW_NAME) as im:
        assert im.format == "PNG" and im.mode == "RGB"
        # A square 10 x 10 m room: the map is 800 - 2 x 16 px square, plus 46 px title and 40 px footer.
        assert im.size == (800, 46 + 768 + 40)
    assert set(_chunks(data)) <= {b"IHDR", b"IDAT", b"IEND"}  # no tIME, no text: nothing that varies


def test_render_is_deterministic_across_processes(folder):
    code = ("import hashlib, json, sys; from worldgen.export.preview import render; "
            "print(hashlib.sha256(render(json.load(open(sys.argv[1])))).hexdigest())")
    digests = {subprocess.run([sys.executable, "-c", code, str(folder / "world.json")], check=True,
                              capture_output=True, text=True).stdout.strip() for _ in range(2)}
    assert digests == {hashlib.sha256((folder / PREVIEW_NAME).read_bytes()).hexdigest()}


def test_layout_keeps_the_world_inside_the_map_with_y_up(meta):
    lay = layout(meta)
    (x0, y0), (x1, y1) = meta["bounds"]["min"], meta["bounds"]["max"]
    u0, v0 = lay.px(x0, y0)
    u1, v1 = lay.px(x1, y1)
    assert 16 <= u0 < u1 <= 800 - 16 and 46 <= v1 < v0 <= lay.height - 40  # +y is up the image
    assert math.isclose((u1 - u0) / (x1 - x0), (v0 - v1) / (y1 - y0))   # one scale for both axes


def test_obstacles_and_walls_have_their_colour_at_their_centres(meta, image):
    seen = {"obstacle": 0, "wall": 0}
    for e in meta["entities"]:
        if e["role"] in seen:
            x, y = e["pose"][:2]
            assert _close(image.getpixel(_pixel_of(meta, x, y)), COLOURS[e["role"]]), e["name"]
            seen[e["role"]] += 1
    assert seen["obstacle"] == meta["metrics"]["obstacle_count"] > 0 and seen["wall"] == 4


def test_spawn_and_goal_are_drawn_as_footprints(meta, image):
    r = meta["robot"]["radius"]
    for task in meta["tasks"]:
        for kind in ("spawn", "goal"):
            x, y, yaw = task[kind][0], task[kind][1], task[kind][5]
            # Inside the footprint, off the heading arrow (at right angles to it), the marker's fill.
            inside = (x + 0.55 * r * math.cos(yaw - math.pi / 2), y + 0.55 * r * math.sin(yaw - math.pi / 2))
            assert _close(image.getpixel(_pixel_of(meta, *inside)), COLOURS[kind + "_fill"]), kind
            # On the heading arrow, beyond the rim: the marker's colour.
            tip = (x + 1.5 * r * math.cos(yaw), y + 1.5 * r * math.sin(yaw))
            assert _close(image.getpixel(_pixel_of(meta, *tip)), COLOURS[kind], tol=40), kind


def test_the_no_go_zone_and_the_path_are_where_they_belong(meta, image):
    import shapely

    grow = meta["robot"]["radius"] + meta["robot"]["clearance"]
    # The zone over usable floor, or over floor no footprint from the spawn reaches (drawn muted).
    zone_colours = [tuple(round(f + (n - f) * NOGO_ALPHA) for f, n in zip(COLOURS[under], COLOURS["nogo"]))
                    for under in ("floor", "unreachable")]
    lay = layout(meta)
    path = shapely.LineString(meta["tasks"][0]["path"]["waypoints"])
    shadows = [shapely.Point(e["pose"][:2]).buffer(e["shape"]["radius"]) if e["shape"]["type"] == "cylinder"
               else shapely.box(*e["aabb"][0][:2], *e["aabb"][1][:2])
               for e in meta["entities"] if e["role"] in ("obstacle", "wall")]
    near_grid = 3 / lay.scale  # metres within 3 px of a 1 m grid line
    checked = 0
    for e in meta["entities"]:
        if e["role"] != "obstacle" or e["shape"]["type"] != "cylinder":
            continue
        cx, cy = e["pose"][:2]
        for a in np.linspace(0, 2 * np.pi, 16, endpoint=False):
            d = e["shape"]["radius"] + 0.5 * grow
            x, y = cx + d * math.cos(a), cy + d * math.sin(a)
            p = shapely.Point(x, y)
            if (min(abs(x - round(x)), abs(y - round(y))) < near_grid or path.distance(p) < 0.1
                    or min(s.distance(p) for s in shadows) < 0.3 * grow):
                continue
            assert any(_close(image.getpixel(_pixel_of(meta, x, y)), c) for c in zone_colours), (e["name"], x, y)
            checked += 1
    assert checked >= 5
    # The path's straight stretches, away from the markers: path orange.
    w = np.asarray(meta["tasks"][0]["path"]["waypoints"])
    longest = int(np.argmax(np.hypot(*np.diff(w, axis=0).T)))
    mid = (w[longest] + w[longest + 1]) / 2
    assert _close(image.getpixel(_pixel_of(meta, *mid)), COLOURS["path"], tol=40)


def test_doors_and_movers_are_drawn(meta):
    m = copy.deepcopy(meta)
    plain = np.asarray(draw(m))
    hinge, angle = (-1.0, 0.0), 1.0
    centre = (hinge[0] + 0.45 * math.cos(angle), hinge[1] + 0.45 * math.sin(angle))
    m["entities"].append({"name": "leaf", "role": "door", "static": False,
                          "pose": [centre[0], centre[1], 1.0, 0.0, 0.0, angle],
                          "shape": {"type": "box", "size": [0.9, 0.2, 2.0]},
                          "aabb": [[-1.1, -0.1, 0.0], [-0.4, 0.9, 2.0]]})
    m["doors"] = [{"name": "leaf", "hinge": [*hinge, 0.0], "axis": [0.0, 0.0, 1.0], "width": 0.9,
                   "state": "ajar", "angle": angle, "limits": [0.0, 1.5],
                   "passage": {"center": [-0.55, 0.0], "width": 0.9, "normal": [0.0, 1.0]}}]
    m["dynamic_obstacles"] = [{"name": "walker", "radius": 0.25, "height": 1.7, "loop": True,
                               "trajectory": [[0.0, -3.0, 3.0], [4.0, 0.0, 3.5], [8.0, 2.0, 1.5]]}]
    drawn = np.asarray(draw(m))
    assert _close(tuple(drawn[_pixel_of(m, *centre)[::-1]]), COLOURS["door"])

    lay = layout(m)
    rows = slice(int(lay.top), lay.height - 40 * lay.legend_rows)  # the map only, not the legend

    def count(img, colour):
        return int(np.sum(np.all(np.abs(img[rows].astype(int) - colour) <= 25, axis=-1)))

    for colour in (COLOURS["mover"], COLOURS["door"]):
        assert count(plain, colour) == 0 < 150 <= count(drawn, colour)


def test_width_is_checked_and_narrow_images_still_fit(meta):
    with pytest.raises(ParameterError, match="parameter 'width' must be an integer in \\[400, 4000\\]"):
        render(meta, 100)
    narrow = draw(meta, 400)
    assert narrow.size[0] == 400 and narrow.size[1] == layout(meta, 400).height


def test_cli_preview_redraws_the_same_picture_and_leaves_world_json_alone(folder, tmp_path, capsys):
    import shutil

    copy_dir = tmp_path / folder.name
    shutil.copytree(folder, copy_dir)
    before = (copy_dir / "world.json").read_bytes()
    original = (copy_dir / PREVIEW_NAME).read_bytes()
    (copy_dir / PREVIEW_NAME).unlink()
    assert main(["preview", str(copy_dir)]) == 0
    assert capsys.readouterr().out.strip() == str(copy_dir / PREVIEW_NAME)
    assert (copy_dir / PREVIEW_NAME).read_bytes() == original
    assert (copy_dir / "world.json").read_bytes() == before
    assert sorted(p.name for p in copy_dir.iterdir()) == sorted(p.name for p in folder.iterdir())
    assert main(["preview", "--width", "640", str(copy_dir)]) == 0
    with Image.open(copy_dir / PREVIEW_NAME) as im:
        assert im.size[0] == 640


def test_cli_preview_mistakes_are_one_line_and_status_2(tmp_path, capsys):
    assert main(["preview", str(tmp_path)]) == 2
    err = capsys.readouterr().err
    assert err.startswith("error: argument WORLD_DIR") and "is not a world folder (no world.json)" in err and err.count("\n") == 1
    (tmp_path / "world.json").write_text("{not json")
    assert main(["preview", str(tmp_path)]) == 2
    assert "cannot be read as JSON" in capsys.readouterr().err


def test_write_without_preview(tmp_path):
    folder = worldgen.generate("cluttered", seed=5).write(tmp_path, preview=False)
    assert not (folder / PREVIEW_NAME).exists()


def test_the_legend_lists_what_the_world_has():
    from worldgen.export.preview_frame import legend

    def names(world):
        return [text for text, _, _ in legend(world.metadata, unreachable=False)]

    plain = names(worldgen.generate("cluttered", 0, size=[6, 6], n_obstacles=3))
    assert "door" not in plain and "mover" not in plain and "path (opens a door)" not in plain and "path" in plain
    moving = names(worldgen.generate("cluttered", 0, size=[8, 8], n_obstacles=3, n_movers=1))
    assert "mover" in moving and "door" not in moving
    people = names(worldgen.generate("cluttered", 1, size=[8, 8], n_obstacles=3, n_people=2))
    assert "people (a colour each, dot every 5 s)" in people and "mover" not in people
    door = worldgen.generate("door", 2)
    assert door.metadata["tasks"][0]["requires_door_open"]
    assert {"door", "path (opens a door)"} <= set(names(door)) and "path" not in names(door)


def test_floor_no_footprint_reaches_is_muted_and_the_corridor_is_not(tmp_path):
    world = worldgen.generate("corridor", 1, shape="L")
    meta = world.metadata
    image = Image.open(world.write(tmp_path) / PREVIEW_NAME).convert("RGB")
    (x0, y0), (x1, y1) = meta["bounds"]["min"], meta["bounds"]["max"]
    # The L runs along two sides of its bounds: the middle of the square is floor inside no corridor.
    centre = _pixel_of(meta, (x0 + x1) / 2 + 0.3, (y0 + y1) / 2 + 0.3)
    assert _close(image.getpixel(centre), COLOURS["unreachable"], tol=12)
    # Along the reference path, the usable floor keeps its colour.
    wp = np.asarray(meta["tasks"][0]["path"]["waypoints"])
    a, b = wp[0], wp[1]
    off = a + 0.25 * (b - a) + np.array([0.0, 0.25])
    assert _close(image.getpixel(_pixel_of(meta, *off)), COLOURS["floor"], tol=12)


def test_many_people_each_in_a_colour_and_the_title_names_preset_and_level():
    """preview.png of 10 people was a tangle of one-colour tracks; its title named neither preset nor level."""
    from worldgen.export.preview_frame import title_lines
    from worldgen.export.topdown import PERSON_COLOURS
    from worldgen.presets import generate_preset

    crowd = worldgen.generate("cluttered", 3, size=[12, 12], n_obstacles=6, n_people=10, people_duration=20.0)
    colours = {c for _, c in draw(crowd.metadata).getcolors(1 << 20)}
    assert set(PERSON_COLOURS) <= colours  # a colour per person, each drawn solid somewhere (its start ring)
    head, parts = title_lines(crowd.metadata)
    assert head == crowd.world_id and parts[:2] == [f"level {crowd.metadata['metrics']['difficulty_level']}/10",
                                                     "10 people"]
    preset = generate_preset("person_head_on")
    assert title_lines(preset.metadata)[0] == f"person_head_on--{preset.world_id}"
    asked = worldgen.generate("cluttered", 3, size=[8, 8], difficulty="4/10")
    assert title_lines(asked.metadata)[1][0] == "level 4/10 (request seed 3)"
