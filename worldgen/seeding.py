"""Every random stream worldgen uses comes from a seed through this module, and only this one.

A stream is ``SeedSequence(entropy, spawn_key=key)``: the seed is the entropy, and the key names
what the stream is for, so adding a kind of random thing never reshuffles another. The keys:

==============================  ============================  =====================================
stream                          key                           used by
==============================  ============================  =====================================
draw ``k`` of a world           ``(k,)``                      ``pipeline.attempt``, every generator
its movers                      ``(k, MOVER_STREAM)``         ``generators.movers``
its people                      ``(k, PEOPLE_STREAM)``        ``people.places``
an environment's worlds         ``(WORLD_STREAM,)``           ``envs.navigation`` (reset's seed)
an environment's sensor noise   ``(NOISE_STREAM,)``           ``envs.navigation`` (reset's seed)
draw ``k`` towards a level      ``(LEVEL_STREAM, k)``         ``leveling`` (a world asked for at a level)
an environment's curriculum     ``(CURRICULUM_STREAM,)``      ``envs.curriculum``, ``envs.replay`` (reset's seed)
an edit of a level              ``(EDIT_STREAM,)``            ``verify.edits`` (the edit's own seed)
a recipe's sampled parameter    ``[seed, entry, tag(name)]``  ``pack.recipe`` (entropy, no key)
a baseline policy's actions     ``()``                        ``envs.policies`` (the policy's seed)
point ``k`` of a campaign       ``(CAMPAIGN_STREAM, k)``      ``campaign.strategies`` (the strategy's seed)
==============================  ============================  =====================================

>>> float(attempt_rng(7, 0).random()) == float(attempt_rng(7, 0).random())
True
>>> check_seed(-1)
Traceback (most recent call last):
...
worldgen.errors.ParameterError: parameter 'seed' must be an integer in [0, 9223372036854775807], got -1
"""

from __future__ import annotations

import hashlib
from typing import Any

import numpy as np

from worldgen.errors import ParameterError

__all__ = ["MAX_SEED", "MOVER_STREAM", "PEOPLE_STREAM", "WORLD_STREAM", "NOISE_STREAM", "LEVEL_STREAM", "CURRICULUM_STREAM",
           "EDIT_STREAM", "CAMPAIGN_STREAM", "level_seed", "campaign_seeds", "curriculum_rng", "edit_rng", "policy_rng",
           "check_seed", "attempt_rng", "mover_rng", "people_rng", "env_rngs", "draw_seed", "recipe_rng"]

#: The largest seed anywhere (numpy's ``integers`` draws below 2**63 without overflow).
MAX_SEED = 2**63 - 1
#: Key of the movers' stream, beside the draw number (an arbitrary tag far from the small integers
#: generators use for their own ``rng.spawn()`` children).
MOVER_STREAM = 0x6D6F76
#: Key of the people's stream ("pep"), beside the draw number: people never move a mover or an obstacle.
PEOPLE_STREAM = 0x706570
#: Keys of the two streams an environment derives from a reset's seed.
WORLD_STREAM, NOISE_STREAM = 0, 1
#: Key of the seeds of the draws towards a difficulty level ("lvl").
LEVEL_STREAM = 0x6C766C
#: Key of an environment's curriculum stream (levels it jumps to, levels it replays or edits), beside the
#: world and noise streams of a reset's seed: a curriculum never moves a plain environment's worlds.
CURRICULUM_STREAM = 2
#: Key of an edit's stream ("edt"), beside the edit's own seed (worldgen.verify.edits).
EDIT_STREAM = 0x656474
#: Key of a campaign's points ("cam"), beside the point's number: its world's seed and its sampler's seed.
CAMPAIGN_STREAM = 0x63616D


def check_seed(seed: Any, what: str = "parameter 'seed'") -> int:
    """``seed`` as an int, or a one-line :class:`ParameterError` naming ``what`` and the range."""
    if isinstance(seed, bool) or not isinstance(seed, (int, np.integer)) or not 0 <= int(seed) <= MAX_SEED:
        raise ParameterError(f"{what} must be an integer in [0, {MAX_SEED}], got {seed!r}")
    return int(seed)


def _stream(entropy, *key: int) -> np.random.Generator:
    return np.random.default_rng(np.random.SeedSequence(entropy, spawn_key=key))


def attempt_rng(seed: int, attempt: int) -> np.random.Generator:
    """The RNG of draw number ``attempt`` (0-based) for ``seed``: a world never depends on how many
    attempts a caller allowed, only on which one succeeded."""
    return _stream(seed, attempt)


def mover_rng(seed: int, attempt: int) -> np.random.Generator:
    """The movers' own RNG for draw ``attempt`` of ``seed`` (independent of the generator's)."""
    return _stream(seed, attempt, MOVER_STREAM)


def people_rng(seed: int, attempt: int) -> np.random.Generator:
    """The people's own RNG for draw ``attempt`` of ``seed`` (independent of the generator's and the movers')."""
    return _stream(seed, attempt, PEOPLE_STREAM)


def env_rngs(entropy: int) -> tuple[np.random.Generator, np.random.Generator]:
    """An environment's (world seeds, sensor noise) streams for a reset's seed."""
    return _stream(entropy, WORLD_STREAM), _stream(entropy, NOISE_STREAM)


def curriculum_rng(entropy: int) -> np.random.Generator:
    """An environment's curriculum stream for a reset's seed (independent of its worlds and noise)."""
    return _stream(entropy, CURRICULUM_STREAM)


def policy_rng(seed: int) -> np.random.Generator:
    """A baseline policy's own stream (worldgen.envs.policies), from the seed it was made with. No key: the same
    numbers as ``numpy.random.default_rng(seed)``, which the policies used before this module held them."""
    return _stream(seed)


def edit_rng(seed: int) -> np.random.Generator:
    """The stream of one edit of a level, from the edit's seed (worldgen.verify.edits)."""
    return _stream(seed, EDIT_STREAM)


def level_seed(seed: int, draw: int) -> int:
    """The world seed of draw ``draw`` of a request for a level with ``seed`` (worldgen.leveling)."""
    return draw_seed(_stream(seed, LEVEL_STREAM, draw))


def campaign_seeds(seed: int, point: int) -> tuple[int, int]:
    """(world seed, sampler seed) of point number ``point`` of a campaign whose strategy has ``seed``: a point's
    world and its proposal never depend on how many points came before it, only on its number."""
    rng = _stream(seed, CAMPAIGN_STREAM, point)
    return draw_seed(rng), int(rng.integers(0, 2**32))


def draw_seed(rng: np.random.Generator) -> int:
    """A fresh seed in [0, MAX_SEED) drawn from ``rng``."""
    return int(rng.integers(0, MAX_SEED))


def recipe_rng(seed: int, entry: int, name: str) -> np.random.Generator:
    """The stream of one sampled parameter of a recipe: the world's seed, the recipe entry and the
    parameter's name (hashed, so renaming another parameter leaves this one's values alone)."""
    tag = int.from_bytes(hashlib.sha256(name.encode()).digest()[:4], "big")
    return np.random.default_rng(np.random.SeedSequence([seed, entry, tag]))
