"""The reference consumer of world.usda: Pixar's usd-core (``pxr``), its stage and its validators.

``validation_issues`` runs every validator that usd-core registers (``pxr.UsdValidation``, as
``usdchecker`` does from USD 25 on: UsdGeom's stage metadata, UsdShade's bindings, UsdPhysics'
rigid body, collider, joint and articulation checks, composition errors, ...). A usd-core older
than that framework has only ``UsdUtils.ComplianceChecker``; the helper falls back to it and says so
in each issue it reports (the test extra asks for a usd-core that has the framework).
"""

from __future__ import annotations

import pytest

from support import missing_tool

__all__ = ["pxr_modules", "open_stage", "validation_issues", "world_matrix"]


def pxr_modules():
    """(Usd, UsdGeom, UsdPhysics, Sdf, Gf), or skip / fail (CI) where usd-core is not installed."""
    try:
        from pxr import Gf, Sdf, Usd, UsdGeom, UsdPhysics
    except ImportError:
        missing_tool("usd-core (pip install 'worldgen[usd]')")
        raise
    return Usd, UsdGeom, UsdPhysics, Sdf, Gf


def open_stage(text: str):
    """The stage of a ``.usda`` text, read the way a file is (a layer imported from the text)."""
    Usd, _, _, Sdf, _ = pxr_modules()
    layer = Sdf.Layer.CreateAnonymous("world.usda")
    assert layer.ImportFromString(text), "usd-core could not parse the text"
    stage = Usd.Stage.Open(layer)
    assert stage is not None
    return stage


def validation_issues(stage) -> list[str]:
    """Every issue usd-core's validators find on ``stage`` (any type: errors, warnings, infos)."""
    try:
        from pxr import UsdValidation
    except ImportError:
        UsdValidation = None
    if UsdValidation is not None:
        validators = UsdValidation.ValidationRegistry().GetOrLoadAllValidators()
        assert len(validators) > 10, "usd-core registered almost no validators"
        errors = UsdValidation.ValidationContext(validators).Validate(stage)
        return [f"{e.GetType()} {e.GetName()}: {e.GetMessage()}" for e in errors]
    from pxr import UsdUtils  # pragma: no cover - a usd-core before the validation framework

    checker = UsdUtils.ComplianceChecker()
    checker.CheckCompliance(stage.GetRootLayer().identifier)
    return [f"ComplianceChecker (no UsdValidation here): {m}" for m in checker.GetErrors() + checker.GetFailedChecks()]


def world_matrix(prim, time=None):
    """(4, 4) numpy transform of ``prim`` in the stage's world, column vectors (USD's row form transposed)."""
    import numpy as np

    Usd, UsdGeom, *_ = pxr_modules()
    cache = UsdGeom.XformCache(Usd.TimeCode.Default() if time is None else Usd.TimeCode(time))
    if not prim.IsValid():
        pytest.fail(f"no prim {prim}")
    return np.array(cache.GetLocalToWorldTransform(prim), dtype=float).T
