"""Speed of the navigation environment (worldgen/Navigation-v0) in the drl_arena preset.

    make bench                      # or: .venv/bin/python benchmarks/bench_env.py [--steps N] [--resets N]

Pinned to one core (os.sched_setaffinity; --all-cores to not pin). Timed with
time.perf_counter, reported as medians (these machines are shared and noisy):

  step         one env.step: 360 lidar beams, 0.1 s control period (50 MuJoCo steps at 0.002 s),
               uniform random actions, the default reward (geodesic shaping); steps/s = 1 / median, and
               also over the whole run (every step, episode ends included, resets not)
  step_walkthrough  the same with reward="walkthrough" (no geodesic field: the step as it was before
               issue 22), measured in the same run for a like-for-like comparison
  episode_end  the step that ends an episode, which adds the oracles' figures (FCL min_clearance)
  reset        env.reset(): a new world, checked, with the robot added and compiled into MuJoCo, first scan;
               split into  generate   worldgen.generate alone, for the same seeds (the feasibility
                                      planner's cost lives here)
                           export     the world's MJCF tree and its task (world - generate)
                           compile    robot added to the MJCF, MjModel + MjData
                           geodesic   the geodesic distance field (worldgen.envs.geodesic)
                           rest       everything else (first scan, bookkeeping)
  inject_*     MJCF, robot added, compiled, MjData: through lxml (the environment's way: the
               exporter's tree, a body appended, from_xml_string) and through mujoco.MjSpec (MJCF text,
               the body added through its API, compiled), on the same worlds, alternating which goes
               first: which is faster

Targets (issue 11): >= 1,000 steps/s; reset median <= 25 ms. Issue 22: a step with the default reward
within 20 % of the walkthrough reward's. The table goes to stdout, the figures
to benchmarks/results/env.json.
"""

from __future__ import annotations

import argparse
import json
import os
import platform
import statistics
import sys
import time
from pathlib import Path

import numpy as np

RESULTS = Path(__file__).resolve().parent / "results" / "env.json"
PRESET = "drl_arena"


def _ms(seconds: float) -> float:
    return round(seconds * 1e3, 3)


def bench_steps(env, steps: int) -> dict:
    rng = np.random.default_rng(0)
    actions = rng.uniform(env.action_space.low, env.action_space.high, size=(steps, 2)).astype(np.float32)
    env.reset(seed=0)
    times, ends = [], []
    start = time.perf_counter()
    resetting = 0.0
    for a in actions:
        t0 = time.perf_counter()
        _, _, terminated, truncated, _ = env.step(a)
        dt = time.perf_counter() - t0
        if terminated or truncated:
            ends.append(dt)
            t1 = time.perf_counter()
            env.reset()
            resetting += time.perf_counter() - t1
        else:
            times.append(dt)
    wall = time.perf_counter() - start - resetting
    median = statistics.median(times)
    return {"step_median_us": round(median * 1e6, 1), "steps_per_s_median": round(1.0 / median),
            "steps_per_s_overall": round(steps / wall), "episodes": len(ends),
            "episode_end_median_ms": _ms(statistics.median(ends)) if ends else None, "steps": steps}


def bench_resets(env, resets: int) -> dict:
    import worldgen
    from worldgen.presets import load

    params = load(PRESET).params
    env.reset(seed=123)  # warm-up
    seeds = [1000 + i for i in range(resets)]
    total, world, compile_, geodesic = [], [], [], []
    for s in seeds:
        env.reset(options={"world_seed": s})
        t = env.unwrapped.reset_timings
        total.append(t["total"])
        world.append(t["world"])
        compile_.append(t["compile"])
        geodesic.append(t["geodesic"])
    generate = []
    for s in seeds:
        t0 = time.perf_counter()
        worldgen.generate("cluttered", s, **params)
        generate.append(time.perf_counter() - t0)
    med = {k: statistics.median(v) for k, v in
           (("total", total), ("world", world), ("compile", compile_), ("generate", generate), ("geodesic", geodesic))}
    rest = [t - w - c - g for t, w, c, g in zip(total, world, compile_, geodesic)]
    return {"reset_median_ms": _ms(med["total"]), "generate_median_ms": _ms(med["generate"]),
            "export_median_ms": _ms(max(0.0, med["world"] - med["generate"])),
            "compile_median_ms": _ms(med["compile"]), "geodesic_median_ms": _ms(med["geodesic"]),
            "rest_median_ms": _ms(statistics.median(rest)),
            "reset_p90_ms": _ms(float(np.percentile(total, 90))), "resets": resets}


def _mjspec_robot(mjcf_text: str, radius: float, height: float):
    """The same robot as worldgen.envs.robot.add_robot adds, through mujoco.MjSpec instead; the compiled model."""
    import mujoco

    from worldgen.envs.robot import FLOOR_GAP, ROBOT, ROBOT_MASS, TIME_CONSTANT

    spec = mujoco.MjSpec.from_string(mjcf_text)
    half = (height - FLOOR_GAP) / 2.0
    body = spec.worldbody.add_body(name=ROBOT, pos=[0.0, 0.0, FLOOR_GAP + half])
    for suffix, kind, axis in (("x", mujoco.mjtJoint.mjJNT_SLIDE, [1, 0, 0]), ("y", mujoco.mjtJoint.mjJNT_SLIDE, [0, 1, 0]),
                               ("yaw", mujoco.mjtJoint.mjJNT_HINGE, [0, 0, 1])):
        body.add_joint(name=f"{ROBOT}_{suffix}", type=kind, axis=axis)
    body.add_geom(name=ROBOT, type=mujoco.mjtGeom.mjGEOM_CYLINDER, size=[radius, half, 0.0], mass=ROBOT_MASS)
    body.add_site(name=f"{ROBOT}_base")
    for suffix, gear, kv, limits in (("forward", [1, 0, 0, 0, 0, 0], ROBOT_MASS / TIME_CONSTANT, (0.0, 1.0)),
                                     ("lateral", [0, 1, 0, 0, 0, 0], ROBOT_MASS / TIME_CONSTANT, None),
                                     ("turn", [0, 0, 0, 0, 0, 1], ROBOT_MASS * radius * radius / 2 / TIME_CONSTANT,
                                      (-1.0, 1.0))):
        act = spec.add_actuator(name=f"{ROBOT}_{suffix}", trntype=mujoco.mjtTrn.mjTRN_SITE, target=f"{ROBOT}_base",
                                gear=gear)
        act.gainprm[0] = kv
        act.biastype = mujoco.mjtBias.mjBIAS_AFFINE
        act.biasprm[2] = -kv
        if limits is not None:
            act.ctrllimited = mujoco.mjtLimited.mjLIMITED_TRUE
            act.ctrlrange = list(limits)
    return spec.compile()


def bench_injection(worlds: int) -> dict:
    """The robot added and compiled through lxml (what the environment does) and through mujoco.MjSpec."""
    import mujoco

    import worldgen
    from worldgen.envs.robot import ROBOT, add_robot, compile_world
    from worldgen.export import mjcf
    from worldgen.export.xml import parse_bytes
    from worldgen.presets import load

    params = load(PRESET).params
    made = [worldgen.generate("cluttered", s, **params) for s in range(worlds)]

    def through_lxml(w):
        root = parse_bytes(mjcf.to_mjcf(w.scene, name=w.world_id)).getroot()
        add_robot(root, w.robot.radius, w.robot.height, (0.0, 1.0), 1.0)
        compile_world(root, (0.0, 0.0, 0.0), ["floor"], [])

    def through_mjspec(w):
        model = _mjspec_robot(w.to_mjcf(), w.robot.radius, w.robot.height)
        data = mujoco.MjData(model)
        data.qpos[[model.joint(f"{ROBOT}_{k}").qposadr[0] for k in ("x", "y", "yaw")]] = 0.0

    lx, sp = [], []
    for rnd in range(4):  # whole passes, alternating which goes first: no order or cache advantage
        for way, out in ((through_lxml, lx), (through_mjspec, sp))[:: 1 if rnd % 2 else -1]:
            for w in made:
                t0 = time.perf_counter()
                way(w)
                out.append(time.perf_counter() - t0)
    return {"inject_lxml_median_ms": _ms(statistics.median(lx)), "inject_mjspec_median_ms": _ms(statistics.median(sp)),
            "worlds": worlds}


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--steps", type=int, default=20000, help="env steps timed (default 20000)")
    ap.add_argument("--resets", type=int, default=200, help="resets timed (default 200)")
    ap.add_argument("--all-cores", action="store_true", help="do not pin the process to one core")
    args = ap.parse_args(argv)
    if not args.all_cores and hasattr(os, "sched_setaffinity"):
        os.sched_setaffinity(0, {sorted(os.sched_getaffinity(0))[0]})  # the targets are per core
    import gymnasium

    import worldgen
    import worldgen.envs  # noqa: F401  (registers worldgen/Navigation-v0)

    env = gymnasium.make("worldgen/Navigation-v0", preset=PRESET, lidar_beams=360, control_period=0.1)
    results = {"worldgen_version": worldgen.__version__, "python": platform.python_version(),
               "machine": platform.machine(), "cpus": os.cpu_count(), "preset": PRESET, "lidar_beams": 360,
               "control_period_s": 0.1, "pinned_to_one_core": not args.all_cores}
    results["step"] = bench_steps(env, args.steps)
    walk = gymnasium.make("worldgen/Navigation-v0", preset=PRESET, lidar_beams=360, control_period=0.1, reward="walkthrough")
    results["step_walkthrough"] = bench_steps(walk, args.steps)
    walk.close()
    results["reset"] = bench_resets(env, args.resets)
    results["injection"] = bench_injection(min(args.resets, 100))
    env.close()
    s, r, i = results["step"], results["reset"], results["injection"]
    print(f"worldgen/Navigation-v0, preset {PRESET}, 360 beams, 0.1 s control period, "
          f"{'one core' if not args.all_cores else 'all cores'}")
    print(f"{'step':<12} median {s['step_median_us']:>8.1f} us  -> {s['steps_per_s_median']:>6} steps/s "
          f"(overall {s['steps_per_s_overall']} steps/s over {s['steps']} steps, {s['episodes']} episodes; target >= 1000)")
    sw = results["step_walkthrough"]
    ratio = s["step_median_us"] / sw["step_median_us"]
    print(f"{'  walkthrough':<12} median {sw['step_median_us']:>8.1f} us  -> {sw['steps_per_s_median']:>6} steps/s "
          f"(default / walkthrough = {ratio:.3f}; target <= 1.2)")
    results["step_ratio_default_to_walkthrough"] = round(ratio, 4)
    print(f"{'episode_end':<12} median {s['episode_end_median_ms']} ms (the ending step, with the oracles' figures)")
    print(f"{'reset':<12} median {r['reset_median_ms']:>8.2f} ms  (p90 {r['reset_p90_ms']:.2f} ms over {r['resets']}; "
          f"target <= 25 ms)")
    for part in ("generate", "export", "compile", "geodesic", "rest"):
        print(f"  {part:<10} median {r[part + '_median_ms']:>8.2f} ms")
    print(f"{'inject':<12} lxml {i['inject_lxml_median_ms']:.3f} ms, MjSpec {i['inject_mjspec_median_ms']:.3f} ms "
          f"(export + robot + compile, median over {i['worlds']} worlds)")
    RESULTS.parent.mkdir(parents=True, exist_ok=True)
    RESULTS.write_text(json.dumps(results, indent=2, sort_keys=True) + "\n")
    print(f"\nfigures written to {RESULTS}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
