"""worldgen.files: a world folder appears whole, also when several writers make the same one at once."""

from __future__ import annotations

import threading

from worldgen.files import write_folder_atomically


def test_writers_racing_for_one_world_folder_all_succeed_and_leave_it_whole(tmp_path):
    """Two workers of a pack that make the same world rename their folders into one place at the same
    moment; before, the second rename failed with "Directory not empty" and the build reported that
    instead of the duplicate jobs."""
    blobs = {"world.json": b"{}\n", "sub/a.txt": b"a" * 1000}
    errors: list[BaseException] = []
    start = threading.Barrier(8)

    def writer() -> None:
        start.wait()
        try:
            for _ in range(25):
                write_folder_atomically(tmp_path, "w", blobs)
        except BaseException as exc:  # noqa: BLE001 - the test reports whatever a writer raised
            errors.append(exc)

    threads = [threading.Thread(target=writer) for _ in range(8)]
    for t in threads:
        t.start()
    for t in threads:
        t.join()
    assert errors == []
    assert sorted(p.name for p in tmp_path.iterdir()) == ["w"]  # no temporary folder left behind
    assert (tmp_path / "w" / "sub" / "a.txt").read_bytes() == b"a" * 1000


def test_an_atomic_folder_replaces_the_old_one_whole_or_leaves_it(tmp_path):
    import pytest

    from worldgen.errors import OutputError
    from worldgen.files import atomic_folder

    with atomic_folder(tmp_path, "report", "report folder") as tmp:
        assert tmp.parent == tmp_path and tmp.name != "report"
        (tmp / "a.txt").write_text("first")
    with pytest.raises(ZeroDivisionError), atomic_folder(tmp_path, "report") as tmp:
        (tmp / "a.txt").write_text("second")
        1 / 0
    assert (tmp_path / "report" / "a.txt").read_text() == "first"
    with pytest.raises(OutputError, match="^cannot write report folder '.*report': "), \
            atomic_folder(tmp_path, "report", "report folder") as tmp:
        (tmp / "missing" / "a.txt").write_text("third")  # an OSError in the block
    assert sorted(p.name for p in tmp_path.iterdir()) == ["report"]
    with atomic_folder(tmp_path, "report") as tmp:
        (tmp / "b.txt").write_text("fourth")
    assert sorted(p.name for p in (tmp_path / "report").iterdir()) == ["b.txt"]
    assert sorted(p.name for p in tmp_path.iterdir()) == ["report"]


def test_a_file_another_program_made_is_moved_into_place(tmp_path):
    from worldgen.files import move_into_place

    made = tmp_path / "made"
    made.write_bytes(b"\x7fELF")
    made.chmod(0o755)
    move_into_place(made, tmp_path / "exe")
    assert not made.exists() and (tmp_path / "exe").read_bytes() == b"\x7fELF"
    assert (tmp_path / "exe").stat().st_mode & 0o111
