"""The one reader of a written world (worldgen.groundtruth.folder): a World, a pack's world (folder and
archive) and a world folder read the same; mistakes are one line that says what is wrong."""

import json

import pytest

import worldgen
from worldgen.errors import ParameterError
from worldgen.groundtruth.folder import WorldFolder, is_world_folder, open_world
from worldgen.groundtruth.ground import load


@pytest.fixture(scope="module")
def three(tmp_path_factory):
    """The same world (minimal, seed 0) as an in-memory World, a written folder, and a pack's world in a pack
    folder and in its archive."""
    from worldgen.pack import Pack, build_pack, parse_recipe
    from worldgen.pack.archive import write_archive

    root = tmp_path_factory.mktemp("reader")
    world = worldgen.generate("minimal", seed=0)
    folder = worldgen.generate("minimal", seed=0).write(root / "worlds", preview=False)
    build_pack(parse_recipe("name: one\nseeds: 1\nworlds:\n  - generator: minimal\n"), root / "pack")
    pack, archived = Pack.open(root / "pack"), Pack.open(write_archive(root / "pack"))
    yield {"world": world, "folder": folder, "pack": pack[0], "archive": archived[0]}
    pack.close()
    archived.close()


def _plain(meta: dict) -> dict:
    return json.loads(json.dumps(meta))  # a built World's metadata holds tuples where a read one holds lists


@pytest.mark.parametrize("kind", ["folder", "pack", "archive"])
def test_a_world_a_pack_world_and_a_folder_read_the_same(three, kind):
    mine, other = open_world(three["world"]), open_world(three[kind])
    assert _plain(other.metadata) == _plain(mine.metadata)
    assert other.world_id == mine.world_id == three["world"].world_id
    assert (other.generator, other.seed, other.params) == ("minimal", 0, _plain(three["world"].params))
    assert other.robot == mine.robot == three["world"].robot
    assert other.task_ids == mine.task_ids == tuple(t.id for t in three["world"].tasks)
    for task in (None, *mine.task_ids):
        assert _plain(other.task(task)) == _plain(mine.task(task))
    assert other.file_bytes("mjcf") == mine.file_bytes("mjcf") == three["world"].export_bytes("mjcf")
    # The ground truth of any of them is the same world.json.
    assert _plain(load(three[kind]).meta) == _plain(load(three["world"]).meta)


def test_a_pack_world_answers_as_its_reader(three):
    pw = three["pack"]
    assert open_world(pw) is pw.reader and pw.metadata is pw.reader.metadata
    assert pw.robot == pw.reader.robot and pw.task() == pw.reader.task()
    assert pw.file("sdf") == pw.path / "world.sdf" and pw.file("sdf").is_file()


def test_files_by_format_key_and_where_a_world_has_no_folder(three):
    folder = open_world(three["folder"])
    assert folder.path == three["folder"] and folder.file("mjcf") == three["folder"] / "world.mjcf.xml"
    assert folder.file("json") == three["folder"] / "world.json"
    assert folder.file_name("sdf") == "world.sdf"
    with pytest.raises(ParameterError, match=r"has no usd file \(it has map_pgm, map_yaml, mjcf, scenario, sdf, "
                                             r"urdf\); write the world with that format$"):
        folder.file("usd")
    for kind in ("world", "archive"):  # an unwritten World, a world inside a pack archive: bytes yes, paths no
        with pytest.raises(ParameterError, match="has no folder on disk"):
            open_world(three[kind]).file("sdf")
    written = worldgen.generate("minimal", seed=0)
    written.write(three["folder"].parent.parent / "written", preview=False)
    assert open_world(written).file("sdf") == written.file("sdf")


def test_a_missing_task_names_the_ids_there_are(three):
    for kind in ("world", "folder", "pack", "archive"):
        with pytest.raises(ParameterError) as err:
            open_world(three[kind]).task("task_9")
        assert str(err.value) == "parameter 'task' must be one of task_0, got 'task_9'"
    with pytest.raises(ParameterError, match=r"^option '--task' must be one of task_0, got 'x'$"):
        open_world(three["folder"]).task("x", "option '--task'")


def test_a_folder_that_is_not_a_world_says_so_in_one_line(tmp_path):
    assert not is_world_folder(tmp_path)
    with pytest.raises(ParameterError) as err:
        open_world(tmp_path, "--world")
    assert str(err.value) == f"--world '{tmp_path}' is not a world folder (no world.json)"
    with pytest.raises(ParameterError, match="is not a world folder"):
        open_world(tmp_path / "nowhere")
    (tmp_path / "world.json").write_text("{not json")
    assert is_world_folder(tmp_path)
    with pytest.raises(ParameterError) as err:
        WorldFolder.open(tmp_path)
    assert "world.json cannot be read as JSON" in str(err.value) and "\n" not in str(err.value)
    (tmp_path / "world.json").write_text('["a list"]')
    with pytest.raises(ParameterError, match="world.json is not a world's metadata"):
        open_world(tmp_path)
    with pytest.raises(ParameterError, match=r"^parameter 'world' must be a World, a PackWorld or a world folder, "
                                             r"got int$"):
        open_world(3)


def test_a_world_json_naming_a_file_outside_its_folder_is_refused(three, tmp_path):
    import shutil

    copy = tmp_path / "copy"
    shutil.copytree(three["folder"], copy)
    meta = json.loads((copy / "world.json").read_text())
    meta["files"]["mjcf"]["path"] = "../secret.xml"
    (tmp_path / "secret.xml").write_text("<mujoco/>")
    (copy / "world.json").write_text(json.dumps(meta))
    with pytest.raises(ParameterError, match="not a file inside the world folder"):
        open_world(copy).file_bytes("mjcf")
    with pytest.raises(ParameterError, match="not a file inside the world folder"):
        open_world(copy).file("mjcf")


def test_a_folder_is_opened_by_its_world_json_too(three):
    assert open_world(three["folder"] / "world.json").path == three["folder"]


def test_a_folder_reader_pickles_and_a_world_is_not_rendered_to_be_recognised(three):
    import pickle

    again = pickle.loads(pickle.dumps(open_world(three["folder"])))
    assert again.metadata == open_world(three["folder"]).metadata and again.file("sdf").is_file()
    fresh = worldgen.generate("minimal", seed=0)
    opened = open_world(fresh)
    assert "metadata" not in vars(fresh)  # nothing rendered until the metadata is asked for
    assert opened.world_id == fresh.world_id and "metadata" in vars(fresh)
