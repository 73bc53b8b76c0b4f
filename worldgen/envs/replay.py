"""An adaptive level sampler after Prioritized Level Replay (Jiang et al. 2021) with ACCEL's edits
(Parker-Holder et al. 2022): ``NavigationEnv(curriculum="replay")`` or ``curriculum=LevelReplay(...)``.

A *level* is a record (generator, parameters, seed, edits) with the proven world it gives
(:class:`LevelRecord`). The environment keeps up to ``buffer_size`` of them, each with a score. Before
each episode, from the environment's curriculum stream (:func:`worldgen.seeding.curriculum_rng`):

- with probability ``replay_prob`` (buffer not empty) a buffered level is **replayed**, drawn by the PLR
  mix ``P = (1 - staleness) P_S + staleness P_C``: ``P_S`` ranks the levels by score, highest first
  (ties in buffer order), and weighs rank ``r`` by ``(1 / r) ** (1 / temperature)``; ``P_C`` weighs each
  level by the episodes since it was last played, ``(c - C_i) / sum_j (c - C_j)`` (uniform when all are 0);
- else, with probability ``edit_prob`` (buffer not empty), a level drawn by the same ``P`` is **edited**
  (:func:`worldgen.verify.edits.edit_world`: move, resize, add or remove an obstacle, or move the goal) and
  the edit, re-proved by the exact checker, is played; when no proposal passes, a new level instead;
- else a **new** level: the source's next world (the seed a plain environment would draw).

The score is the signal the learner reports for the level just played (``env.unwrapped.report_score(v)``,
e.g. PLR's mean absolute GAE or a regret estimate; the last report stands), else its *learnability*
``p (1 - p)`` with ``p = (successes + 1) / (plays + 2)`` (the success rate with one success and one
failure added, so a level played once is not scored 0). A finished level enters the buffer at the next
reset (after any score reported for it); when the buffer is full, in place of the lowest-scored level
(the first of equals) if it scores higher. Only proven worlds are ever made (generated or edited, then
checked): every buffered level has a certificate and a reference path. The bookkeeping
(:meth:`LevelReplay.probabilities`, :meth:`LevelReplay.admit`) needs no environment.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Any, Optional

import numpy as np

from worldgen.errors import ParameterError, quoted
from worldgen.seeding import curriculum_rng, draw_seed
from worldgen.verify.edits import EDITS, edit_world, replay_edits

__all__ = ["LevelReplay", "LevelRecord", "learnability", "check_generator_source"]


def learnability(successes: int, plays: int) -> float:
    """``p (1 - p)`` with ``p = (successes + 1) / (plays + 2)``: highest for a level solved half the time."""
    p = (successes + 1) / (plays + 2)
    return p * (1.0 - p)


@dataclass(eq=False)
class LevelRecord:
    """One level: its proven ``world`` (generated, or an :class:`~worldgen.verify.edits.EditedWorld`) and its
    history. ``generator``, ``params``, ``seed`` and ``edits`` rebuild it (:meth:`rebuild`)."""

    world: Any
    kind: str = "new"
    score: float = math.nan
    reported: bool = False
    plays: int = 0
    successes: int = 0
    last_played: int = 0
    finished: bool = field(default=False, repr=False)

    @property
    def generator(self) -> str:
        return self.world.generator

    @property
    def params(self) -> dict:
        return self.world.params

    @property
    def seed(self) -> int:
        return self.world.seed

    @property
    def edits(self) -> tuple:
        return tuple(getattr(self.world, "edits", ()))

    @property
    def certificate(self):
        """The world's feasibility report (every check passed, the checker named)."""
        return self.world.feasibility

    @property
    def path(self):
        """The proven reference path of the task the environment drives (the first)."""
        return self.world.feasibility.paths[0]

    def record(self) -> dict:
        return {"generator": self.generator, "params": dict(self.params), "seed": self.seed, "edits": list(self.edits)}

    def rebuild(self):
        """The world regenerated from the record and, when edited, its edits re-applied and re-proved."""
        from worldgen.api import generate

        world = generate(self.generator, self.seed, **self.params)
        return replay_edits(world, self.edits) if self.edits else world


def check_generator_source(source, what: str) -> None:
    """One-line ParameterError unless ``source`` makes worlds from a generator (a curriculum makes its own)."""
    from worldgen.envs.source import GeneratorSource

    if not isinstance(source, GeneratorSource):
        raise ParameterError(f"parameter 'curriculum' ({what}) needs worlds from a generator or preset, "
                             "not a pack (a pack's worlds are fixed)")


def _probability(name: str, value: Any, lo: float = 0.0, hi: float = 1.0, low_open: bool = False) -> float:
    if isinstance(value, bool) or not isinstance(value, (int, float, np.integer, np.floating)) \
            or not (lo < value if low_open else lo <= value) or not value <= hi:
        raise ParameterError(f"parameter '{name}' must be a number in {'(' if low_open else '['}{lo:g}, {hi:g}], "
                             f"got {quoted(value)}")
    return float(value)


class LevelReplay:
    """The adaptive sampler (see the module). Defaults: ``buffer_size`` 64, ``replay_prob`` 0.5,
    ``edit_prob`` 0.5, ``temperature`` 0.1 and ``staleness`` 0.1 (PLR's beta and rho), every edit."""

    name = "replay"

    def __init__(self, buffer_size: int = 64, replay_prob: float = 0.5, edit_prob: float = 0.5,
                 temperature: float = 0.1, staleness: float = 0.1, edits: tuple = EDITS):
        if isinstance(buffer_size, bool) or not isinstance(buffer_size, (int, np.integer)) or not 1 <= buffer_size <= 100000:
            raise ParameterError(f"parameter 'buffer_size' must be an integer in [1, 100000], got {quoted(buffer_size)}")
        self.buffer_size = int(buffer_size)
        self.replay_prob = _probability("replay_prob", replay_prob)
        self.edit_prob = _probability("edit_prob", edit_prob)
        self.temperature = _probability("temperature", temperature, 0.0, 100.0, low_open=True)
        self.staleness = _probability("staleness", staleness)
        if not isinstance(edits, (tuple, list)) or not edits or any(e not in EDITS for e in edits):
            raise ParameterError(f"parameter 'edits' must name some of {', '.join(EDITS)}, got {quoted(edits)}")
        self.edits = tuple(edits)
        self.buffer: list[LevelRecord] = []
        #: Episodes started so far (the clock of the staleness term).
        self.clock = 0
        self.kinds = {"new": 0, "replay": 0, "edit": 0}
        self._rng: Optional[np.random.Generator] = None
        self._current: Optional[LevelRecord] = None

    def __repr__(self) -> str:
        return (f"LevelReplay(buffer_size={self.buffer_size}, replay_prob={self.replay_prob:g}, "
                f"edit_prob={self.edit_prob:g}, temperature={self.temperature:g}, staleness={self.staleness:g}) "
                f"holding {len(self.buffer)} levels")

    # -- bookkeeping ----------------------------------------------------------------------------------------
    @property
    def current(self) -> Optional[LevelRecord]:
        """The level of the episode under way or just finished (None before the first)."""
        return self._current

    def reseed(self, entropy: int) -> None:
        """Take the curriculum stream of a reset's seed (the buffer stays)."""
        self._rng = curriculum_rng(entropy)

    @property
    def rng(self) -> np.random.Generator:
        if self._rng is None:
            self.reseed(0)
        assert self._rng is not None
        return self._rng

    def probabilities(self) -> np.ndarray:
        """(len(buffer),) the PLR mix of rank prioritisation and staleness over the buffered levels."""
        n = len(self.buffer)
        if n == 0:
            return np.zeros(0)
        scores = np.array([r.score for r in self.buffer], dtype=float)
        order = np.argsort(-scores, kind="stable")  # highest first, ties in buffer order
        ranks = np.empty(n)
        ranks[order] = np.arange(1, n + 1)
        weights = (1.0 / ranks) ** (1.0 / self.temperature)
        p_score = weights / weights.sum()
        stale = np.array([self.clock - r.last_played for r in self.buffer], dtype=float)
        p_stale = stale / stale.sum() if stale.sum() > 0 else np.full(n, 1.0 / n)
        return (1.0 - self.staleness) * p_score + self.staleness * p_stale

    def admit(self, record: LevelRecord) -> bool:
        """Put a scored level in the buffer (see the module); True when it is there afterwards."""
        if any(r is record for r in self.buffer):
            return True
        if len(self.buffer) < self.buffer_size:
            self.buffer.append(record)
            return True
        scores = [r.score for r in self.buffer]
        lowest = int(np.argmin(scores))
        if record.score > scores[lowest]:
            self.buffer[lowest] = record
            return True
        return False

    def finish(self, record: LevelRecord, success: bool) -> None:
        """Count a finished episode on ``record`` and score it (unless the learner reported); it is admitted
        at the next reset (:meth:`next_world`), so that a score reported after the episode's end counts."""
        record.plays += 1
        record.successes += bool(success)
        record.finished = True
        if not record.reported:
            record.score = learnability(record.successes, record.plays)

    def report_score(self, value: float) -> None:
        """The learner's score for the level of the episode under way or just finished (it replaces any
        earlier one, and the learnability default, for that level)."""
        if isinstance(value, bool) or not isinstance(value, (int, float, np.integer, np.floating)) or not math.isfinite(value):
            raise ParameterError(f"parameter 'score' must be a finite number, got {quoted(value)}")
        if self._current is None:
            raise ParameterError("report_score needs a level: call reset() first")
        self._current.score, self._current.reported = float(value), True

    def stats(self) -> dict:
        """For logging: episodes, levels made by kind, the buffer's size, scores and success counts."""
        return {"episodes": self.clock, "kinds": dict(self.kinds), "buffer_size": len(self.buffer),
                "scores": [r.score for r in self.buffer], "plays": [r.plays for r in self.buffer],
                "successes": [r.successes for r in self.buffer], "edited": sum(bool(r.edits) for r in self.buffer)}

    # -- in the environment ---------------------------------------------------------------------------------
    def check(self, source) -> None:
        check_generator_source(source, "replay")

    def choose(self, source, world_rng: np.random.Generator) -> LevelRecord:
        """The next episode's level: replayed, edited or new (see the module)."""
        rng = self.rng
        if self.buffer and rng.random() < self.replay_prob:
            record = self.buffer[int(rng.choice(len(self.buffer), p=self.probabilities()))]
            record.kind = "replay"
            return record
        if self.buffer and rng.random() < self.edit_prob:
            parent = self.buffer[int(rng.choice(len(self.buffer), p=self.probabilities()))]
            child = edit_world(parent.world, draw_seed(rng), self.edits)
            if child is not None:
                return LevelRecord(child, kind="edit")
        return LevelRecord(source.generated(draw_seed(world_rng)), kind="new")

    def next_world(self, source, world_rng: np.random.Generator):
        from worldgen.envs.source import episode_world

        if self._current is not None and self._current.finished:
            self.admit(self._current)  # the level just played, with its final score
        record = self.choose(source, world_rng)
        self.kinds[record.kind] += 1
        record.last_played = self.clock
        self.clock += 1
        self._current = record
        record.finished = False
        return episode_world(record.world), {
            "world_seed": record.seed, "level_kind": record.kind, "level_edits": len(record.edits),
            "level_score": record.score, "buffer_size": len(self.buffer)}

    def leave(self) -> None:
        if self._current is not None and self._current.finished:
            self.admit(self._current)
        self._current = None

    def episode_end(self, figures: dict) -> dict:
        record = self._current
        if record is None or record.finished:
            return {}
        self.finish(record, bool(figures.get("success")))
        return {"level_kind": record.kind, "level_score": record.score, "level_plays": record.plays,
                "buffer_size": len(self.buffer)}
