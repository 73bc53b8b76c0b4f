"""The strategies that choose where a campaign looks next, each an Optuna study driven by ask and tell.

- ``random``: Optuna's ``RandomSampler``, uniform over the space: the baseline.
- ``adaptive``: Optuna's ``TPESampler`` (multivariate, grouped for the space's conditional dimensions,
  the constant liar for runs still out), maximising failure: it spends runs where failures were found.
- ``coverage``: the same sampler, but a failure is worth ``1 / (1 + failures already found in its cell)``,
  the cell being the point's descriptors (:func:`worldgen.campaign.space.cell`: generator, level, people,
  door state, narrowest passage band), so the search keeps moving on to failures it has not seen instead of
  finding one failure many times.

The study owns the search state (its trials, each with its parameters, distributions and value) and writes
it out (:meth:`Strategy.state`, Optuna's own JSON for distributions). Before point ``k`` is asked, the study
is given a sampler seeded with point ``k``'s own seed (:func:`worldgen.seeding.campaign_seeds`), so a proposal
depends only on the results told so far and its number: a sequential campaign is the same for a seed, and
one resumed from its records (:meth:`Strategy.restore`, Optuna's ``add_trial``) asks what it would have asked.
A point whose world does not exist, or whose runs were all unjudged, is told as a failed trial (Optuna's
``FAIL`` state), which the samplers leave out: it is neither a pass nor a failure of the robot.
"""

from __future__ import annotations

import warnings
from collections import Counter
from typing import Any, Mapping, Optional, Sequence

from worldgen.campaign.recipe import STRATEGIES, Entry
from worldgen.campaign.space import Point, point_of, suggest
from worldgen.errors import ParameterError, require_optional
from worldgen.seeding import campaign_seeds

__all__ = ["Strategy", "value_of", "STARTUP_TRIALS"]

#: Points TPE draws at random before it models anything (Optuna's default is 10).
STARTUP_TRIALS = 10


def value_of(verdict: Optional[str], earlier_in_cell: int, strategy: str) -> Optional[float]:
    """What a point's result is worth to ``strategy``: None (not told as a value) unless it was judged."""
    if verdict not in ("passed", "failed"):
        return None
    if verdict == "passed":
        return 0.0
    return 1.0 / (1 + earlier_in_cell) if strategy == "coverage" else 1.0


class Strategy:
    """One campaign's search: ``ask`` a point, ``tell`` its result; ``state`` for the output folder."""

    def __init__(self, name: str, seed: int, entries: Sequence[Entry]):
        if name not in STRATEGIES:
            raise ParameterError(f"parameter 'strategy' must be one of {', '.join(STRATEGIES)}, got {name!r}")
        self.optuna = require_optional("optuna", "campaign", "worldgen.campaign's strategies need Optuna")
        self.optuna.logging.set_verbosity(self.optuna.logging.WARNING)
        self.name, self.seed, self.entries = name, seed, tuple(entries)
        self.study = self.optuna.create_study(direction="maximize", sampler=self._sampler(0))
        self.asked: dict[int, Any] = {}  # point index -> its live Optuna trial
        self.failures_in: Counter = Counter()  # coverage cell -> failures found there
        self.next_index = 0

    def _sampler(self, seed: int):
        samplers = self.optuna.samplers
        if self.name == "random":
            return samplers.RandomSampler(seed=seed)
        with warnings.catch_warnings():  # multivariate, group and constant_liar are marked experimental
            warnings.simplefilter("ignore")
            return samplers.TPESampler(seed=seed, n_startup_trials=STARTUP_TRIALS, multivariate=True, group=True,
                                       constant_liar=True)

    def ask(self) -> tuple[Point, dict[str, Any]]:
        """The next point and its record of the search: {"answers": ..., "distributions": ...}."""
        index = self.next_index
        self.next_index += 1
        world_seed, sampler_seed = campaign_seeds(self.seed, index)
        self.study.sampler = self._sampler(sampler_seed)
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            trial = self.study.ask()
            answers = suggest(trial, self.entries)
        self.asked[index] = trial
        dists = {k: self.optuna.distributions.distribution_to_json(d) for k, d in trial.distributions.items()}
        return point_of(self.entries, answers, index, world_seed), {"answers": answers, "distributions": dists}

    def tell(self, index: int, search: Mapping[str, Any], verdict: Optional[str], cell: tuple) -> Optional[float]:
        """Tell the study point ``index``'s result (its worst verdict; None: no world); returns the value told."""
        value = value_of(verdict, self.failures_in[cell], self.name)
        if verdict == "failed":
            self.failures_in[cell] += 1
        state = self.optuna.trial.TrialState
        trial = self.asked.pop(index, None)
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            if trial is not None:
                if value is None:
                    self.study.tell(trial, state=state.FAIL)
                else:
                    self.study.tell(trial, value)
            else:  # a point of an earlier process (a resume): added as the finished trial it was
                dists = {k: self.optuna.distributions.json_to_distribution(d) for k, d in search["distributions"].items()}
                params = {k: v for k, v in search["answers"].items() if k in dists}
                made = self.optuna.trial.create_trial(params=params, distributions=dists, value=value,
                                                      state=state.COMPLETE if value is not None else state.FAIL)
                self.study.add_trial(made)
        return value

    def restore(self, finished: Sequence[Mapping[str, Any]], next_index: int) -> None:
        """Tell the records of an earlier process (in point order), then ask from ``next_index`` on."""
        for rec in finished:
            self.tell(rec["point"]["index"], rec["search"], rec.get("verdict"), tuple(rec["cell"]))
        self.next_index = max(self.next_index, next_index)

    def state(self) -> dict[str, Any]:
        """The study as plain data: the strategy, its seed, every trial (parameters, distributions, value, state)."""
        dist_json = self.optuna.distributions.distribution_to_json
        trials = [{"number": t.number, "state": t.state.name, "value": t.value, "params": t.params,
                   "distributions": {k: dist_json(d) for k, d in t.distributions.items()}}
                  for t in self.study.get_trials(deepcopy=False)]
        return {"strategy": self.name, "seed": self.seed, "sampler": type(self.study.sampler).__name__,
                "optuna_version": self.optuna.__version__, "failures_per_cell": len(self.failures_in),
                "trials": trials}
