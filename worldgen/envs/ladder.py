"""The difficulty ladder: a reference probe's success at each level of generated worlds.

:func:`success_by_level` asks a generator for worlds at each level (one request per
seed, :mod:`worldgen.leveling`) and drives the probe (:mod:`worldgen.envs.probes`)
through each world's first task in ``worldgen/Navigation-v0`` with default settings (but a reward that
needs no geodesic field: the probes read no reward, and the speeds of :data:`SPEEDS`);
:func:`ladder_figures` reads the table the way issue 19 asks for a ladder: Spearman's
rank correlation of success with level, and a 95 % Wilson interval per level
(tests/envs/test_ladder.py, benchmarks/bench_ladder.py, docs/metrics.md).
"""

from __future__ import annotations

from typing import Any, Mapping, Optional, Sequence

__all__ = ["SPEEDS", "success_by_level", "ladder_figures"]

#: The probe's speeds: the environment's defaults when the ladder's figures were measured (docs/metrics.md),
#: before its robot became each world's (issue 37: 0.5 m/s by default). The probe's success depends on
#: them, so the ladder keeps them.
SPEEDS: dict[str, Any] = {"linear_velocity": [0.0, 1.0], "angular_velocity": 1.0}


def success_by_level(generator: str, levels: Sequence[int], seeds: Sequence[int],
                     params: Optional[Mapping[str, Any]] = None, probe: str = "reactive") -> dict[int, list[bool]]:
    """``{level: [success of the probe in the world asked for with each seed]}``; a request that does not land
    (InfeasibleError) counts as no world, so a level's list can be shorter than ``seeds``."""
    import gymnasium

    import worldgen
    import worldgen.envs  # noqa: F401  (registers the environment)
    from worldgen.envs.navigation import NavigationEnv
    from worldgen.envs.probes import run_episode
    from worldgen.envs.source import OneWorldSource
    from worldgen.errors import InfeasibleError

    # The probes read neither the reward nor the geodesic field; the straight-line reward keeps the reset from
    # building the field (about 20-40 ms of each episode's 0.1-0.3 s), and success is the same whatever the reward.
    env = gymnasium.make("worldgen/Navigation-v0", generator="minimal", reward="euclidean_progress", **SPEEDS).unwrapped
    assert isinstance(env, NavigationEnv)
    out: dict[int, list[bool]] = {}
    try:
        for level in levels:
            out[level] = []
            for seed in seeds:
                try:
                    world = worldgen.generate(generator, seed, difficulty=level, **dict(params or {}))
                except InfeasibleError:
                    continue
                env.source = OneWorldSource(world)
                out[level].append(bool(run_episode(env, probe, seed=0)["success"]))
    finally:
        env.close()
    return out


def ladder_figures(table: Mapping[int, Sequence[bool]]) -> dict:
    """Spearman's rho of per-level success against level, and per level: worlds, successes, rate, Wilson 95 %."""
    from worldgen.judge.stats import require_scipy, wilson_interval

    levels = sorted(table)
    rows = {}
    for level in levels:
        k, n = sum(table[level]), len(table[level])
        lo, hi = wilson_interval(k, n)
        rows[level] = {"worlds": n, "successes": k, "rate": k / n if n else None, "wilson": (lo, hi)}
    rates = [rows[level]["rate"] for level in levels]
    rho = float(require_scipy().spearmanr(levels, rates).statistic) if None not in rates else None
    return {"spearman": rho, "levels": rows}
