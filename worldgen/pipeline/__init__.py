"""Drawing one world: a request's attempts, each a draft drawn, proven and (with people) certified.

``worldgen.generate`` and a level request (worldgen.leveling) both call it: :func:`prepare` a request, then
:func:`first_feasible` (attempts until one is kept) or :func:`attempt` (one attempt by its number).
"""

from worldgen.pipeline.attempt import Attempt, Request, attempt, first_feasible, prepare

__all__ = ["Attempt", "Request", "attempt", "first_feasible", "prepare"]
