"""`--executor dask`: the same manifest bytes as the local pool, on a LocalCluster.

dask.distributed is an optional extra (worldgen[dask]): without it these tests skip,
on CI too, since the default build never needs it.
"""

from __future__ import annotations

import pytest

from worldgen.cli import main
from worldgen.pack import build_pack, parse_recipe

RECIPE = """\
seeds: 3
worlds:
  - generator: cluttered
    params: {size: [6, 6], n_obstacles: [3, 5], max_attempts: 2}
"""


def test_dask_needs_a_scheduler_address(tmp_path, capsys):
    (tmp_path / "r.yaml").write_text(RECIPE)
    assert main(["pack", "build", str(tmp_path / "r.yaml"), "--out", str(tmp_path / "p"), "--executor", "dask"]) == 2
    assert "--scheduler" in capsys.readouterr().err


def test_dask_build_gives_the_local_manifest_bytes(tmp_path, capsys):
    distributed = pytest.importorskip("distributed")
    (tmp_path / "r.yaml").write_text(RECIPE)
    build_pack(parse_recipe(RECIPE, "r.yaml", "r"), tmp_path / "local", jobs=1)
    with distributed.LocalCluster(n_workers=2, threads_per_worker=1, processes=True, dashboard_address=None) as cluster:
        args = ["pack", "build", str(tmp_path / "r.yaml"), "--out", str(tmp_path / "dask"),
                "--executor", "dask", "--scheduler", cluster.scheduler_address]
        assert main(args) == 0
    assert (tmp_path / "dask" / "manifest.json").read_bytes() == (tmp_path / "local" / "manifest.json").read_bytes()
    assert (tmp_path / "dask" / "index.csv").read_bytes() == (tmp_path / "local" / "index.csv").read_bytes()
    assert main(["pack", "verify", str(tmp_path / "dask")]) == 0
