"""Curricula of the navigation environment: which world each episode gets, from how the learner did.

``NavigationEnv(curriculum=...)`` takes ``"levels"`` (a :class:`LevelCurriculum` with its defaults),
``"replay"`` (a :class:`~worldgen.envs.replay.LevelReplay` with its defaults), or an instance of either
(each environment keeps its own copy: environments of a vector env never share one).

:class:`LevelCurriculum`: every episode's world is drawn at the environment's current difficulty level
(1..10, :mod:`worldgen.leveling`). After each finished episode the success rate over the last ``window``
episodes at that level decides: at least ``promote`` moves the environment one level up, at most ``demote``
one level down (never below the lowest); the window starts afresh at every change, so each decision is on
``window`` episodes of one level. An environment that is promoted from the top level is sent to a level
drawn uniformly from all of them (the environment's curriculum stream, :func:`worldgen.seeding.curriculum_rng`),
so that the top is not overfitted. The levels are those the generator reaches
(:func:`worldgen.leveling.reachable`: 2..10 for ``door``), and the first is the lowest of them unless
``start`` says otherwise. The bookkeeping (:meth:`LevelCurriculum.record`) needs no environment.
"""

from __future__ import annotations

import copy
from collections import deque
from typing import Any, Optional

import numpy as np

from worldgen.errors import ParameterError, quoted
from worldgen.seeding import curriculum_rng, draw_seed

__all__ = ["LevelCurriculum", "make_curriculum", "CURRICULA"]

#: The names ``curriculum=`` takes.
CURRICULA = ("levels", "replay")


def _number(name: str, value: Any, lo: float, hi: float, integer: bool = False):
    ok = isinstance(value, (int, np.integer) if integer else (int, float, np.integer, np.floating)) \
        and not isinstance(value, bool) and lo <= value <= hi
    if not ok:
        kind = "an integer" if integer else "a number"
        raise ParameterError(f"parameter '{name}' must be {kind} in [{lo:g}, {hi:g}], got {quoted(value)}")
    return int(value) if integer else float(value)


class LevelCurriculum:
    """Levels with promotion and demotion by a windowed success rate (see the module).

    ``start`` the first level (default: the generator's lowest); ``window`` finished episodes per decision
    (default 20); ``promote`` the rate at or above which the level goes up (default 0.8); ``demote`` the rate
    at or below which it goes down (default 0.4); ``levels`` how many there are (10, world.json's
    ``difficulty_level``).
    """

    name = "levels"

    def __init__(self, start: Optional[int] = None, window: int = 20, promote: float = 0.8, demote: float = 0.4,
                 levels: int = 10):
        self.levels = _number("levels", levels, 1, 10, integer=True)
        self.start = None if start is None else _number("start", start, 1, self.levels, integer=True)
        self.window = _number("window", window, 1, 100000, integer=True)
        self.promote = _number("promote", promote, 0.0, 1.0)
        self.demote = _number("demote", demote, 0.0, 1.0)
        if not self.demote < self.promote:
            raise ParameterError(f"parameter 'demote' must be below promote = {self.promote:g}, got {self.demote:g}")
        #: The levels played, lowest first: 1..levels until :meth:`check` learns which the generator reaches.
        self.ladder: tuple[int, ...] = tuple(range(1, self.levels + 1))
        #: The level the next episode is played at.
        self.level = self.start if self.start is not None else 1
        self._recent: deque = deque(maxlen=self.window)
        self.episodes = np.zeros(self.levels, dtype=np.int64)
        self.successes = np.zeros(self.levels, dtype=np.int64)
        self._rng: Optional[np.random.Generator] = None
        self._playing: Optional[int] = None  # the level of the episode under way, None when none is
        self._changed = False

    def __repr__(self) -> str:
        return (f"LevelCurriculum(start={self.start}, window={self.window}, promote={self.promote:g}, "
                f"demote={self.demote:g}, levels={self.levels}) at level {self.level}")

    # -- bookkeeping ----------------------------------------------------------------------------------------
    def reseed(self, entropy: int) -> None:
        """Take the curriculum stream of a reset's seed (the level and the counts stay)."""
        self._rng = curriculum_rng(entropy)

    def record(self, success: bool) -> dict:
        """Count one finished episode at the current level and decide; returns what ``info`` reports:
        ``curriculum_level`` (the episode's), ``curriculum_next_level``, ``curriculum_level_changed``,
        ``curriculum_success_rates`` (per level 1..10, NaN where none was played)."""
        played = self.level
        k = played - 1
        self.episodes[k] += 1
        self.successes[k] += bool(success)
        self._recent.append(bool(success))
        moved = False
        if len(self._recent) == self.window:
            rate = sum(self._recent) / self.window
            higher = [v for v in self.ladder if v > played]
            lower = [v for v in self.ladder if v < played]
            if rate >= self.promote:
                moved, self.level = True, higher[0] if higher else self._above_top()
            elif rate <= self.demote and lower:
                moved, self.level = True, lower[-1]
        if moved:  # a fresh window after every move (a jump from the top that lands on it again included)
            self._recent.clear()
        self._changed = self.level != played
        return {"curriculum_level": played, "curriculum_next_level": self.level,
                "curriculum_level_changed": self._changed, "curriculum_success_rates": self.success_rates()}

    def _above_top(self) -> int:
        if self._rng is None:
            self.reseed(0)
        assert self._rng is not None
        return self.ladder[int(self._rng.integers(len(self.ladder)))]

    def success_rates(self) -> np.ndarray:
        """(levels,) float: successes / episodes per level 1..10 (NaN where none was played)."""
        with np.errstate(invalid="ignore", divide="ignore"):
            return np.where(self.episodes > 0, self.successes / np.maximum(self.episodes, 1), np.nan)

    def stats(self) -> dict:
        """For logging: the level now, and per level 1..10 the episodes, successes and success rate."""
        return {"level": self.level, "episodes": self.episodes.tolist(), "successes": self.successes.tolist(),
                "success_rates": self.success_rates().tolist()}

    # -- in the environment ---------------------------------------------------------------------------------
    def check(self, source) -> None:
        """ParameterError unless the source can be asked for levels (:func:`worldgen.leveling.check_request`)."""
        from worldgen.envs.replay import check_generator_source
        from worldgen.leveling import check_request, reachable

        check_generator_source(source, "levels")
        if source.difficulty is not None:
            raise ParameterError("parameter 'curriculum' sets each episode's level itself; leave out 'difficulty' "
                                 f"(got difficulty={quoted(source.difficulty)})")
        ladder = tuple(v for v in reachable(source.generator) if v <= self.levels)
        start = self.start if self.start is not None else (ladder[0] if ladder else 1)
        try:
            check_request(source.generator, start, source.params)
        except ParameterError as e:  # said for curriculum='levels', which sets the difficulty of every episode
            raise ParameterError(f"parameter 'curriculum' draws worlds at a level: {e}") from None
        if not self.episodes.any():  # a fresh curriculum starts at its first level of this generator
            self.level = start
        self.ladder = ladder

    def next_world(self, source, world_rng: np.random.Generator):
        """The next episode's world at the current level: (EpisodeWorld, what reset's ``info`` adds)."""
        from worldgen.envs.source import episode_world

        seed = draw_seed(world_rng)
        world = episode_world(source.generated(seed, difficulty=self.level))
        self._playing = self.level
        changed, self._changed = self._changed, False  # said once, at the first reset at the new level
        return world, {"world_seed": seed, "curriculum_level": self.level, "curriculum_level_changed": changed}

    def leave(self) -> None:
        """The environment picked this episode's world itself (reset's ``world_seed``): it does not count."""
        self._playing = None

    def episode_end(self, figures: dict) -> dict:
        """Count a finished episode the curriculum chose; nothing for one it did not."""
        if self._playing is None:
            return {}
        self._playing = None
        return self.record(bool(figures.get("success")))

    def report_score(self, value: float) -> None:
        raise ParameterError("report_score is for curriculum='replay'; the level curriculum reads each "
                             "episode's success")


def make_curriculum(value: Any, source) -> Any:
    """The environment's own curriculum for ``curriculum=value`` (None, a name, or an instance, copied),
    checked against its source."""
    from worldgen.envs.replay import LevelReplay

    if value is None:
        return None
    if isinstance(value, str) and value in CURRICULA:
        made = LevelCurriculum() if value == "levels" else LevelReplay()
    elif isinstance(value, (LevelCurriculum, LevelReplay)):
        made = copy.deepcopy(value)
    else:
        raise ParameterError(f"parameter 'curriculum' must be one of {', '.join(CURRICULA)}, a LevelCurriculum "
                             f"or a LevelReplay, got {quoted(value)}")
    made.check(source)
    return made
