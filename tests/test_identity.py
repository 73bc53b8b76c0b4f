"""A world's identity (content_hash, world_id) covers everything written, and no write replaces another world."""

from __future__ import annotations

import json
import subprocess
import sys

import pytest

import worldgen
from worldgen.errors import OutputError, WorldgenError
from worldgen.generators import get, names


def _other_value(p, default):
    """A valid value of ``p`` other than ``default`` (None where no such value is cheap to name)."""
    if p.kind == "bool":
        return not default
    if p.kind == "choice":
        return next(c for c in p.choices if c != default)
    if p.kind in ("float", "int") and default is not None:
        step = 1 if p.kind == "int" else 0.01
        up = default + step
        return up if p.high is None or up <= p.high else default - step
    if p.kind in ("pair", "range") and default is not None:
        return [default[0], default[1] + 0.01] if p.high is None or default[1] + 0.01 <= p.high else None
    return None


@pytest.mark.parametrize("generator", names())
def test_every_parameter_that_changes_a_file_changes_the_world_id(generator):
    base = worldgen.generate(generator, seed=3)
    seen = {base.world_id: "defaults"}
    for p in get(generator).all_params:
        value = _other_value(p, base.params.get(p.name, p.default))  # people's params: recorded only with people
        if value is None:
            continue
        try:
            world = worldgen.generate(generator, seed=3, **{p.name: value})
        except WorldgenError:
            continue  # that value is refused here; the identity of refused requests does not matter
        if world.params == base.params:
            continue  # normalised to the same request (e.g. density replaced by n_obstacles)
        # world.json records every resolved parameter, so each of these changes a written file.
        assert world.world_id not in seen, f"{p.name}={value!r} kept the id of {seen.get(world.world_id)}"
        seen[world.world_id] = f"{p.name}={value!r}"
    assert len(seen) > 10


def test_seed_and_allow_infeasible_are_part_of_the_identity():
    a = worldgen.generate("minimal", seed=1)
    assert worldgen.generate("minimal", seed=2).content_hash != a.content_hash
    assert worldgen.generate("minimal", seed=1, allow_infeasible=True).content_hash != a.content_hash
    assert worldgen.generate("minimal", seed=1).content_hash == a.content_hash


def test_a_folder_holding_another_world_is_never_replaced_silently(tmp_path):
    world = worldgen.generate("minimal", seed=0)
    folder = world.write(tmp_path)
    world.write(tmp_path)  # the same world again: fine
    meta = json.loads((folder / "world.json").read_text())
    meta["content_hash"] = "sha256:" + "0" * 64  # as if another world had landed under this name
    (folder / "world.json").write_text(json.dumps(meta))
    with pytest.raises(OutputError, match=r"already holds another world; remove it, or pass overwrite=True to World.write \(--overwrite on the command line\)"):
        world.write(tmp_path)
    assert json.loads((folder / "world.json").read_text())["content_hash"] == "sha256:" + "0" * 64
    (folder / "world.json").unlink()
    with pytest.raises(OutputError, match="not a world folder"):
        world.write(tmp_path)
    world.write(tmp_path, overwrite=True)
    assert json.loads((folder / "world.json").read_text())["content_hash"] == world.content_hash


def test_cli_refuses_to_replace_another_world_and_overwrite_replaces_it(tmp_path):
    def gen(*extra):
        return subprocess.run([sys.executable, "-m", "worldgen.cli", "generate", "minimal", "--seed", "0",
                               "--out", str(tmp_path), *extra], capture_output=True, text=True)

    assert gen().returncode == 0
    (folder,) = tmp_path.iterdir()
    (folder / "world.json").write_text("{}")
    refused = gen()
    assert refused.returncode == 2
    assert refused.stderr.strip().count("\n") == 0 and "--overwrite" in refused.stderr
    assert (folder / "world.json").read_text() == "{}"
    assert gen("--overwrite").returncode == 0
    assert json.loads((folder / "world.json").read_text())["world_id"] == folder.name


def test_issue_reproducer_two_worlds_of_one_seed_both_kept(tmp_path):
    a = worldgen.generate("cluttered", seed=5).write(tmp_path)
    b = worldgen.generate("cluttered", seed=5, robot_radius=0.4, n_tasks=3, lidar_samples=7).write(tmp_path)
    assert a != b and a.is_dir() and b.is_dir()


def test_check_regenerates_with_the_flags_the_world_was_made_with(tmp_path):
    from worldgen.verify import check_folder

    # Refused without the flag (the generator cannot promise a path), yet the draw turns out drivable.
    world = worldgen.generate("corridor", seed=0, allow_infeasible=True, width=0.7)
    assert world.feasibility.feasible
    folder = world.write(tmp_path)
    assert json.loads((folder / "world.json").read_text())["feasibility"]["allow_infeasible"] is True
    outcome = check_folder(folder)
    assert outcome.ok, outcome.line()
