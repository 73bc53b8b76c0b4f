"""MuJoCo as a reference tool: load a world (MJCF or URDF), run it, and insist on no warnings.

MuJoCo counts problems it recovers from (bad accelerations, full contact
buffers, inertia it had to fix, ...) in ``data.warning`` instead of raising,
so a test that only loads a file would miss them.
"""

from __future__ import annotations

import os
from pathlib import Path
from typing import Mapping, Optional, Union

import mujoco

__all__ = ["load", "load_and_step", "assert_no_warnings"]


def load(xml_or_path: Union[str, bytes, os.PathLike], assets: Optional[Mapping[str, bytes]] = None) -> mujoco.MjModel:
    """Compile a model from XML text (str/bytes starting with '<') or from a file path.

    ``assets`` maps the file names the XML refers to (e.g. ``meshes/rock.stl``)
    to their bytes, for in-memory loading.
    """
    if isinstance(xml_or_path, bytes):
        xml_or_path = xml_or_path.decode()
    if isinstance(xml_or_path, str) and xml_or_path.lstrip().startswith("<"):
        return mujoco.MjModel.from_xml_string(xml_or_path, dict(assets or {}))
    path = Path(xml_or_path)
    return mujoco.MjModel.from_xml_path(str(path), dict(assets or {}))


def assert_no_warnings(model: mujoco.MjModel, data: mujoco.MjData, what: str = "model") -> None:
    bad = {mujoco.mjtWarning(i).name: int(w.number) for i, w in enumerate(data.warning) if w.number}
    assert not bad, f"MuJoCo warnings for {what}: {bad}"


def load_and_step(xml_or_path, steps: int = 500, assets: Optional[Mapping[str, bytes]] = None):
    """Load, ``mj_forward``, then ``steps`` x ``mj_step``; assert no warning. Returns (model, data)."""
    model = load(xml_or_path, assets)
    data = mujoco.MjData(model)
    mujoco.mj_forward(model, data)
    assert_no_warnings(model, data, "mj_forward")
    for _ in range(steps):
        mujoco.mj_step(model, data)
    assert_no_warnings(model, data, f"{steps} steps")
    return model, data
