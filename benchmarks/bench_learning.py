"""Does worldgen/Navigation-v0 learn out of the box? PPO (stable-baselines3) on one core, fixed protocol.

    make bench-learning        # or: .venv/bin/python benchmarks/bench_learning.py [--steps N] [--reward R ...]

Needs the ``train`` extra (``pip install 'worldgen[train]'``: stable-baselines3 and PyTorch). Not part of
``make test`` or CI: hours of CPU at the default budget.

Protocol (the same for every reward; all of it recorded in the JSON):

- environment: ``preset="drl_arena"``, 360 beams binned into 20 ``lidar_sectors``, everything else at the
  environment's defaults except ``reward``; 8 environments in a DummyVecEnv, observations normalised by
  VecNormalize (returns too), seeded 0..7;
- training worlds: each environment draws its world seeds from its own seeded stream (uniform over 63-bit
  seeds); held-out worlds: world seeds 10^9 + i for i < ``--eval-worlds`` (100), which the training draws
  hit with probability below 1e-10 over the whole run;
- PPO: ``n_steps`` 256 per env (2,048 a rollout), batch 256, 10 epochs, lr 3e-4, gamma 0.99, GAE 0.95,
  clip 0.2, MLP 64 x 64, one torch thread, the process pinned to one core;
- evaluation every ``--eval-every`` steps (50,000): the deterministic policy drives each held-out world
  once; success rate and mean SPL (the environment's own episode figures, under the oracles' rules);
- baselines on the same held-out worlds: random actions, :class:`GapHeuristic` (observation only) and
  :class:`PathFollower` (the true pose and the exact path: an upper bound).

Each run writes ``benchmarks/results/learning_<reward>.json`` (its curve); ``--report`` gathers them with the
baselines into ``benchmarks/results/learning.json``, prints the table and draws ``docs/img/learning.png``.
Target (issue 22): >= 90 % success and mean SPL >= 0.8 within 1 M steps with the default reward.
"""

from __future__ import annotations

import argparse
import json
import os
import platform
import sys
import time
from pathlib import Path

import numpy as np

RESULTS = Path(__file__).resolve().parent / "results"
PICTURE = Path(__file__).resolve().parent.parent / "docs" / "img" / "learning.png"
PRESET = "drl_arena"
ENV_KW = {"preset": PRESET, "lidar_beams": 360, "lidar_sectors": 20}
HELD_OUT = 10**9
PPO_KW = {"n_steps": 256, "batch_size": 256, "n_epochs": 10, "learning_rate": 3e-4, "gamma": 0.99, "gae_lambda": 0.95,
          "clip_range": 0.2}
N_ENVS = 8


def _write(path: Path, data: dict) -> None:
    path.parent.mkdir(parents=True, exist_ok=True)
    tmp = path.with_name(path.name + ".tmp")
    tmp.write_text(json.dumps(data, indent=2, sort_keys=True) + "\n")
    tmp.replace(path)


def _make_env(reward: str, seed: int = 0):
    import gymnasium

    import worldgen.envs  # noqa: F401  (registers worldgen/Navigation-v0)

    env = gymnasium.make("worldgen/Navigation-v0", reward=reward, **ENV_KW)
    env.reset(seed=seed)
    return env


def evaluate(act, reward: str, worlds: int) -> dict:
    """Drive each held-out world once with ``act(obs, env) -> action``; success rate and mean SPL."""
    env = _make_env(reward)
    success, spl, steps = [], [], []
    for i in range(worlds):
        obs, _ = env.reset(seed=i, options={"world_seed": HELD_OUT + i})
        n = 0
        while True:
            obs, _, terminated, truncated, info = env.step(act(obs, env))
            n += 1
            if terminated or truncated:
                break
        success.append(bool(info["success"]))
        spl.append(float(info["spl"]))
        steps.append(n)
    env.close()
    return {"success": float(np.mean(success)), "spl": float(np.mean(spl)), "mean_steps": float(np.mean(steps)),
            "episodes": worlds}


def baselines(worlds: int) -> dict:
    from worldgen.envs.policies import GapHeuristic, PathFollower, RandomPolicy

    out = {}
    state: dict = {}

    def random_act(obs, env):
        if "random" not in state:
            state["random"] = RandomPolicy(env.action_space, seed=0)
        return state["random"].action()

    def heuristic(obs, env):
        return GapHeuristic.for_env(env).action(obs)

    def follower(obs, env):
        u = env.unwrapped
        if state.get("follower_world") is not u.world:
            state["follower_world"], state["follower"] = u.world, PathFollower.for_env(env)
        return state["follower"].action(*u.robot_pose)

    for name, act in (("random", random_act), ("heuristic", heuristic), ("path_follower", follower)):
        t0 = time.perf_counter()
        out[name] = evaluate(act, "geodesic", worlds)
        print(f"{name:<14} success {out[name]['success']:.2f}  SPL {out[name]['spl']:.3f}  "
              f"({time.perf_counter() - t0:.0f} s)", flush=True)
    return out


def train(reward: str, steps: int, eval_every: int, worlds: int, net: tuple = (64, 64), label: str = "") -> dict:
    import torch
    from stable_baselines3 import PPO
    from stable_baselines3.common.callbacks import BaseCallback
    from stable_baselines3.common.vec_env import DummyVecEnv, VecNormalize

    torch.set_num_threads(1)
    venv = VecNormalize(DummyVecEnv([lambda k=k: _make_env(reward, k) for k in range(N_ENVS)]), gamma=PPO_KW["gamma"])
    model = PPO("MlpPolicy", venv, seed=0, verbose=0, device="cpu", policy_kwargs={"net_arch": list(net)}, **PPO_KW)
    curve: list[dict] = []
    label = label or (reward if tuple(net) == (64, 64) else f"{reward}, MLP {' x '.join(map(str, net))}")
    out = {"reward": reward, "label": label, "net_arch": list(net), "env": ENV_KW, "ppo": PPO_KW, "n_envs": N_ENVS,
           "eval_every": eval_every, "eval_worlds": worlds, "curve": curve,
           "held_out_world_seeds": f"{HELD_OUT} + i, i < {worlds}",
           "steps_target": steps, "python": platform.python_version(), "machine": platform.machine()}
    path = RESULTS / f"learning_{label.replace(', ', '_').replace(' ', '')}.json"
    start = time.perf_counter()

    def act(obs, env):
        norm = venv.normalize_obs(obs[None].astype(np.float32))
        return model.predict(norm, deterministic=True)[0][0]

    def point(n: int) -> None:
        t0 = time.perf_counter()
        figures = evaluate(act, reward, worlds)
        curve.append({"steps": n, **figures, "train_seconds": round(t0 - start - sum(c["eval_seconds"] for c in curve), 1),
                      "eval_seconds": round(time.perf_counter() - t0, 1)})
        out["steps_done"] = n
        out["steps_per_s"] = round(n / max(curve[-1]["train_seconds"], 1e-9), 1)
        _write(path, out)
        print(f"{label:<12} {n:>9} steps  success {figures['success']:.2f}  SPL {figures['spl']:.3f}  "
              f"({out['steps_per_s']} train steps/s)", flush=True)

    class Every(BaseCallback):
        def _on_step(self) -> bool:
            if self.num_timesteps // eval_every > (self.num_timesteps - N_ENVS) // eval_every:
                point(self.num_timesteps)
            return True

    point(0)
    model.learn(total_timesteps=steps, callback=Every())
    if curve[-1]["steps"] != model.num_timesteps:
        point(model.num_timesteps)
    return out


def report(worlds: int) -> int:
    runs = {}
    for path in sorted(RESULTS.glob("learning_*.json")):
        data = json.loads(path.read_text())
        if "curve" in data:  # a training run (learning_baselines.json is not one)
            runs[data.get("label", data["reward"])] = data
    base_path = RESULTS / "learning_baselines.json"
    base = json.loads(base_path.read_text()) if base_path.exists() else baselines(worlds)
    _write(base_path, base)
    print(f"\nheld-out worlds: {worlds} ({PRESET}, world seeds {HELD_OUT} + i)")
    print(f"{'policy':<46} {'steps':>9} {'success':>8} {'SPL':>6}")
    for name, fig in base.items():
        print(f"{name:<46} {'-':>9} {fig['success']:>8.2f} {fig['spl']:>6.3f}")
    for label, data in runs.items():
        last = data["curve"][-1]
        best = max(data["curve"], key=lambda c: (c["success"], c["spl"]))
        print(f"{'PPO ' + label:<46} {last['steps']:>9} {last['success']:>8.2f} {last['spl']:>6.3f}   "
              f"(best {best['success']:.2f} / {best['spl']:.3f} at {best['steps']})")
    _write(RESULTS / "learning.json", {"baselines": base, "runs": runs})
    _plot(runs, base)
    print(f"\nfigures written to {RESULTS / 'learning.json'}, picture to {PICTURE}")
    return 0


def _plot(runs: dict, base: dict) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    from matplotlib.ticker import FuncFormatter

    fig, axes = plt.subplots(1, 2, figsize=(11, 4.8))
    for ax, key, label in ((axes[0], "success", "success rate"), (axes[1], "spl", "mean SPL")):
        for name, data in runs.items():
            xs = [c["steps"] for c in data["curve"]]
            ax.plot(xs, [c[key] for c in data["curve"]], marker="o", ms=3, label=f"PPO, {name}")
        ax.xaxis.set_major_formatter(FuncFormatter(lambda x, _: f"{x / 1000:.0f}k"))
        for (name, fig_), style in zip(base.items(), (":", "--", "-.")):
            ax.axhline(fig_[key], color="grey", ls=style, lw=1, label=name)
        ax.set_xlabel("environment steps")
        ax.set_ylabel(label)
        ax.set_ylim(-0.02, 1.02)
        ax.grid(alpha=0.3)
    handles, labels = axes[0].get_legend_handles_labels()
    fig.suptitle(f"worldgen/Navigation-v0 ({PRESET}): PPO on one core, evaluated on held-out worlds")
    fig.legend(handles, labels, loc="lower center", ncol=4, fontsize=8, frameon=False)
    fig.tight_layout(rect=(0, 0.14, 1, 1))
    PICTURE.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(PICTURE, dpi=90)


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--reward", action="append", choices=("geodesic", "walkthrough", "euclidean_progress"),
                    help="train with this reward (repeatable; default: geodesic and walkthrough, one after the other)")
    ap.add_argument("--steps", type=int, default=1_000_000, help="training steps per reward (default 1,000,000)")
    ap.add_argument("--eval-every", type=int, default=50_000, help="steps between evaluations (default 50,000)")
    ap.add_argument("--eval-worlds", type=int, default=100, help="held-out worlds per evaluation (default 100)")
    ap.add_argument("--net", type=int, nargs="+", default=[64, 64], help="the MLP's hidden layers (default 64 64)")
    ap.add_argument("--core", type=int, default=None, help="pin to this core (default: the first allowed)")
    ap.add_argument("--report", action="store_true", help="only gather the runs' JSON, run the baselines, print, draw")
    args = ap.parse_args(argv)
    if hasattr(os, "sched_setaffinity"):
        allowed = sorted(os.sched_getaffinity(0))
        os.sched_setaffinity(0, {args.core if args.core is not None else allowed[0]})
    try:
        import stable_baselines3  # noqa: F401
    except ImportError:
        print("bench_learning needs stable-baselines3 and PyTorch: pip install 'worldgen[train]'", file=sys.stderr)
        return 2
    if not args.report:
        for reward in args.reward or ["geodesic", "walkthrough"]:
            train(reward, args.steps, args.eval_every, args.eval_worlds, tuple(args.net))
    return report(args.eval_worlds)


if __name__ == "__main__":
    sys.exit(main())
