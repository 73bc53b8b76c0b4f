"""Campaigns: search the world space for where a robot fails (docs/campaigns.md).

The systems under test, one interface and three kinds (a policy in the environment, ``worldgen drive``, a
command leaving a bag), are :mod:`~worldgen.campaign.systems` (``Outcome``, ``System``, ``SYSTEM_KEYS``,
``system_from_spec``, also importable from here).

``worldgen.campaign.run(recipe, out)`` runs a campaign recipe (:mod:`~worldgen.campaign.recipe`) with its
strategy (:mod:`~worldgen.campaign.strategies`, on Optuna) into an output folder
(:mod:`~worldgen.campaign.output`), and writes its failure map and report (:mod:`~worldgen.campaign.report`).
The names load on first use, so importing the package costs nothing and imports none of its modules.
"""

from __future__ import annotations

from typing import Any

__all__ = ["run", "load_campaign", "parse_campaign", "write_report", "expect_no_failures", "CampaignSummary",
           "CampaignInterrupted", "Outcome", "System", "SYSTEM_KEYS", "system_from_spec"]

_HOMES = {"run": "runner", "CampaignSummary": "runner", "CampaignInterrupted": "runner", "load_campaign": "recipe",
          "parse_campaign": "recipe", "write_report": "report", "expect_no_failures": "expect",
          "Outcome": "systems", "System": "systems", "SYSTEM_KEYS": "systems", "system_from_spec": "systems"}


def __getattr__(name: str) -> Any:
    import importlib

    if name not in _HOMES:
        raise AttributeError(f"module 'worldgen.campaign' has no attribute {name!r}")
    return getattr(importlib.import_module(f"worldgen.campaign.{_HOMES[name]}"), name)
