"""Campaigns: searching the world space for where a robot fails (issue 36). The systems under test, one
interface and three kinds (a policy in the environment, ``worldgen drive``, a command leaving a bag), are
:mod:`~worldgen.campaign.systems`."""

from worldgen.campaign.systems import SYSTEM_KEYS, Outcome, System, system_from_spec

__all__ = ["Outcome", "System", "SYSTEM_KEYS", "system_from_spec"]
