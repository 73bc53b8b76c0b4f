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
