"""Same generator, parameters, seed and version: byte-identical files, in any process.

Each run happens in a fresh interpreter with its own PYTHONHASHSEED, so any
output that depends on set or dict-hash order, on a timestamp or on global
random state shows up as a byte difference.
"""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

import pytest

import worldgen

_SCRIPT = Path(sys.executable).with_name("worldgen")
WORLDGEN = [str(_SCRIPT)] if _SCRIPT.exists() else [sys.executable, "-m", "worldgen"]

CASES = {
    "seed 0, defaults": ["--seed", "0"],
    "two seeds, three tasks, boxes only, SDF 1.6": [
        "--seed", "12", "--count", "2", "--set", "n_tasks=3", "--set", "obstacle_shapes=box",
        "--set", "size=12,8", "--sdf-version", "1.6"],
    "20 x 20 m, 50 obstacles, no walls": [
        "--seed", "3", "--set", "size=20,20", "--set", "n_obstacles=50", "--set", "walls=false"],
}


def snapshot(folder: Path) -> dict[str, bytes]:
    """Every file under ``folder``: relative path -> bytes."""
    return {str(p.relative_to(folder)): p.read_bytes() for p in sorted(folder.rglob("*")) if p.is_file()}


def generate_in_fresh_process(out: Path, args, hash_seed: str) -> dict[str, bytes]:
    env = dict(os.environ, PYTHONHASHSEED=hash_seed)
    r = subprocess.run(WORLDGEN + ["generate", "cluttered", *args, "--out", str(out)],
                       capture_output=True, text=True, env=env, timeout=120)
    assert r.returncode == 0, r.stderr
    return snapshot(out)


@pytest.mark.parametrize("case", sorted(CASES))
def test_two_fresh_processes_write_identical_bytes(tmp_path, case):
    first = generate_in_fresh_process(tmp_path / "a", CASES[case], "1")
    second = generate_in_fresh_process(tmp_path / "b", CASES[case], "4242")
    assert first, "nothing was written"
    assert sorted(first) == sorted(second)
    differing = [name for name in first if first[name] != second[name]]
    assert differing == []
    assert any(name.endswith("world.json") for name in first)


def test_api_and_cli_write_the_same_world(tmp_path):
    cli = generate_in_fresh_process(tmp_path / "cli", ["--seed", "0"], "7")
    folder = worldgen.generate("cluttered", seed=0).write(tmp_path / "api")
    assert snapshot(tmp_path / "api") == cli
    assert folder.parent == tmp_path / "api"


def test_different_seeds_give_different_worlds():
    worlds = [worldgen.generate("cluttered", seed=s, n_obstacles=5, size=[6, 6]) for s in range(8)]
    hashes = [w.content_hash for w in worlds]
    assert len(set(hashes)) == len(hashes)
    assert len({w.world_id for w in worlds}) == len(worlds)


def test_same_seed_same_world_in_one_process_whatever_the_budget():
    a = worldgen.generate("cluttered", seed=9, n_obstacles=30)
    b = worldgen.generate("cluttered", seed=9, n_obstacles=30, max_attempts=500)
    assert a.scene.content_hash() == b.scene.content_hash() and a.attempts == b.attempts
    assert a.tasks == b.tasks
    # max_attempts is a parameter like any other: world.json records it, so it is another world id.
    assert a.world_id != b.world_id
    ma, mb = dict(a.metadata), dict(b.metadata)
    assert ma.pop("params") != mb.pop("params")
    for key in ("world_id", "content_hash", "files"):
        ma.pop(key), mb.pop(key)
    assert ma == mb
