"""The systems a campaign tests, one interface and three kinds, each run judged as ``worldgen judge`` judges a bag.

    >>> import worldgen
    >>> from worldgen.campaign import system_from_spec
    >>> folder = worldgen.generate("minimal", seed=2).write("worlds", preview=False)
    >>> system = system_from_spec({"drive": {"sim": "mujoco"}})
    >>> outcome = system.run(folder, "task_0", "run0", "work")
    >>> outcome.verdict, outcome.reason, outcome.row["run"], outcome.row["collisions"]
    ('passed', '', 'minimal-s2-...__task_0__run0', [])

A recipe's ``system:`` block names exactly one (:func:`system_from_spec`):

- ``{"policy": "module:factory", "env": {...}}``: the factory, called with the environment
  ``worldgen/Navigation-v0`` once it is reset on the campaign's world and task, returns an object whose
  ``action`` takes the observation (Gymnasium's convention), ``(x, y, yaw)`` or ``(x, y, yaw, t)`` (the
  shipped followers', :mod:`worldgen.envs.policies`); ``env`` holds the environment's settings
  (:data:`worldgen.envs.config.SETTINGS`; unless it says otherwise the episode lasts the task's own
  ``time_limit``, the one the judge holds the run to);
- ``{"drive": {"sim": "mujoco" | "gazebo"}}``: ``worldgen drive``, the reference robot;
- ``{"command": "my_stack {world} {task} {run} {bag}", "timeout": 600}``: a program run per world and
  task (no shell: the template is split as a shell would split it, then each word filled in) that leaves a
  rosbag2 bag at ``{bag}``.

Every run ends as a bag in ``workdir/bags/<world id>__<task>__<run>`` judged by
:func:`worldgen.judge.judge` against the world's truth: the policy's episode is recorded with
:func:`worldgen.campaign.judging.record` (the topics ``worldgen drive`` records), the drive's bag is ``worldgen
drive``'s, the command's is the command's. A command that exits
non-zero, outlives its timeout (its whole process group is killed) or leaves no readable bag is
``unjudged`` with the reason, never a failure of the robot; so is a policy that raises. A policy's run among
people who react to the robot is judged against where they walked in the episode
(:func:`~worldgen.campaign.judging.as_walked`).
"""

from __future__ import annotations

import importlib
import inspect
import math
import shutil
import tempfile
import time
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Callable, Mapping, Optional, Protocol

from worldgen.campaign.command import DEFAULT_TIMEOUT, PLACEHOLDERS, CommandSystem, check_template, check_timeout
from worldgen.campaign.judging import Outcome, as_walked, bag_of, judged, said, unjudged
from worldgen.errors import ParameterError, SimulatorError, quoted

__all__ = ["Outcome", "System", "PolicySystem", "DriveSystem", "CommandSystem", "SYSTEM_KEYS", "PLACEHOLDERS",
           "DEFAULT_TIMEOUT", "system_from_spec"]

#: The kinds, each with the keys that may go with it in a recipe's ``system:`` block.
_KINDS: dict[str, frozenset[str]] = {"policy": frozenset({"env"}), "drive": frozenset(),
                                     "command": frozenset({"timeout"})}
#: The keys a recipe's ``system:`` block may hold.
SYSTEM_KEYS: frozenset[str] = frozenset(_KINDS).union(*_KINDS.values())
#: Environment settings a campaign decides itself: the world is the campaign's.
_ENV_FIXED = ("generator", "params", "preset", "pack", "difficulty", "curriculum", "render_mode", "reward_fn")


class System(Protocol):
    """What a campaign runs: ``run`` drives ``task`` of the world folder ``world`` as run ``run``, writing
    into ``workdir``. Every kind is a frozen dataclass: picklable, sent to Dask workers."""

    @property
    def kind(self) -> str: ...

    def run(self, world: Path, task: str, run: str, workdir: Path) -> Outcome: ...


# -- policy ------------------------------------------------------------------------------------------------

def _factory(name: str) -> Callable:
    """The callable ``module:attr.attr`` names; a one-line ParameterError when it cannot be had."""
    module, sep, attrs = name.partition(":")
    if not sep or not module or not attrs:
        raise ParameterError(f"system.policy must be 'module:factory' (e.g. 'worldgen.envs.policies:GapHeuristic.for_env'), "
                             f"got {quoted(name)}")
    try:
        found: Any = importlib.import_module(module)
    except Exception as exc:  # any error of the user's module on import is the recipe's mistake to report
        raise ParameterError(f"system.policy: cannot import module {module!r} ({said(exc)})") from None
    for attr in attrs.split("."):
        if not hasattr(found, attr):
            raise ParameterError(f"system.policy: module {module!r} has no {attrs!r}")
        found = getattr(found, attr)
    if not callable(found):
        raise ParameterError(f"system.policy: {name!r} is not callable (a factory returning the policy)")
    return found


def _positional(fn: Callable) -> tuple[int, bool]:
    """(required positional parameters, takes *args) of ``fn``."""
    try:
        params = inspect.signature(fn).parameters.values()
    except (TypeError, ValueError):
        return 1, False
    kinds = (inspect.Parameter.POSITIONAL_ONLY, inspect.Parameter.POSITIONAL_OR_KEYWORD)
    required = sum(p.kind in kinds and p.default is inspect.Parameter.empty for p in params)
    return required, any(p.kind is inspect.Parameter.VAR_POSITIONAL for p in params)


def _actor(policy: Any, env) -> Callable[[Any], Any]:
    """``observation -> action`` for a policy whose ``action`` takes the observation, (x, y, yaw) or (x, y, yaw, t)."""
    act = getattr(policy, "action", None)
    if not callable(act):
        raise ParameterError(f"system.policy: the factory returned {type(policy).__name__}, which has no action() method")
    required, star = _positional(act)
    u = env.unwrapped
    if required == 3:
        return lambda obs: act(*u.robot_pose)
    if required == 4:
        return lambda obs: act(*u.robot_pose, u.episode.rows[-1][0])
    if required == 1 or (required == 0 and star):
        return act
    raise ParameterError(f"system.policy: action() must take (observation), (x, y, yaw) or (x, y, yaw, t); "
                         f"{type(policy).__name__}.action takes {required} arguments")


def _env_settings(env: Any) -> dict:
    """The recipe's environment settings, checked now (a mistake is the recipe's, before any run)."""
    from worldgen.envs.config import resolve

    env = {} if env is None else env
    if not isinstance(env, Mapping):
        raise ParameterError(f"system.env must be a mapping of environment settings, got {quoted(env)}")
    fixed = sorted(set(env) & set(_ENV_FIXED))
    if fixed:
        raise ParameterError(f"system.env: {fixed[0]!r} is the campaign's to choose (the world of each run); "
                             "give only the environment's settings")
    # The episode lasts the task's own time limit, the judge's; no policy reads the reward, and the default
    # geodesic one regenerates the world for its distance field (0.3-1 s a world, and a shrunk world, edited
    # since, does not regenerate at all): the walkthrough reward needs nothing.
    settings = {"time_limit_factor": None, "reward": "walkthrough"} | dict(env)
    resolve(settings)
    return settings


def _episode(env, obs, act: Callable) -> tuple[Any, Any]:
    """Drive the env, reset to ``obs``, to the episode's end: the (n, 4) trajectory and (m, 3) ``t, v, w`` commands."""
    import numpy as np

    u = env.unwrapped
    commands = []
    while True:
        action = act(obs)
        t = u.episode.rows[-1][0]
        obs, _, terminated, truncated, _ = env.step(action)
        v, w = np.clip(np.asarray(action, dtype=float).reshape(-1), u.action_space.low, u.action_space.high)
        commands.append((t, float(v), float(w)))
        if terminated or truncated:
            break
    commands.append((u.episode.rows[-1][0], 0.0, 0.0))
    return u.episode.trajectory, np.array(commands)


@dataclass(frozen=True)
class PolicySystem:
    """A policy in ``worldgen/Navigation-v0``: ``policy`` is ``module:factory``, ``env`` the settings."""

    policy: str
    env: dict = field(default_factory=dict, hash=False)
    criteria: Optional[dict] = field(default=None, hash=False)
    kind: str = "policy"

    def run(self, world: Path, task: str, run: str, workdir: Path) -> Outcome:
        import gymnasium

        import worldgen.envs  # noqa: F401  (registers worldgen/Navigation-v0)
        from worldgen.envs.source import FolderSource
        from worldgen.sim.drive import record_run

        started = time.perf_counter()
        bag = bag_of(world, task, run, workdir)
        source = FolderSource(world, task)
        meta = source.ground.meta
        (x0, y0), (x1, y1) = meta["bounds"]["min"][:2], meta["bounds"]["max"][:2]
        # The goal distance is observed within the world's own diagonal unless the recipe fixes the bound.
        settings: dict[str, Any] = {"goal_distance_max": math.hypot(x1 - x0, y1 - y0)} | dict(self.env)
        env = gymnasium.make("worldgen/Navigation-v0", disable_env_checker=True, **settings)
        try:
            u: Any = env.unwrapped
            u.source = source
            obs, _ = env.reset(seed=0)  # the same world and policy: the same run
            chosen = u.task
            try:
                policy = _call_factory(_factory(self.policy), env)
            except Exception as exc:  # the policy's own error: no run to judge, not the robot failing
                return unjudged(f"policy factory raised {said(exc)}", started)
            act = _actor(policy, env)  # an action() of the wrong shape is the recipe's mistake: it stops here
            try:
                trajectory, commands = _episode(env, obs, act)
            except Exception as exc:
                return unjudged(f"policy raised {said(exc)}", started)
            walkers = u.episode.walkers
            walked = walkers.reacted if walkers is not None else {}
        finally:
            env.close()
        record_run(bag, trajectory, commands, meta, chosen, run)
        # People who react to the robot walked elsewhere than world.json has them: the run is judged against
        # where they went, as the environment judges its episodes (a person who stepped aside is not hit).
        truth = as_walked(Path(world), meta, walked, bag.parent.parent / "walked" / bag.name) if walked else Path(world)
        return judged(bag, truth, task, run, self.criteria, started)


def _call_factory(factory: Callable, env) -> Any:
    """The policy: the factory called with the environment when it takes an argument, else without."""
    required, star = _positional(factory)
    return factory(env) if required >= 1 or star else factory()


# -- drive -------------------------------------------------------------------------------------------------

@dataclass(frozen=True)
class DriveSystem:
    """``worldgen drive``: the reference robot (pure pursuit along the reference path) in ``sim``."""

    sim: str = "mujoco"
    criteria: Optional[dict] = field(default=None, hash=False)
    kind: str = "drive"

    def run(self, world: Path, task: str, run: str, workdir: Path) -> Outcome:
        from worldgen.files import move_into_place
        from worldgen.sim.drive import drive

        started = time.perf_counter()
        bag = bag_of(world, task, run, workdir)
        scratch = Path(tempfile.mkdtemp(prefix=".drive-", dir=bag.parent))
        try:
            try:
                done = drive(world, scratch, sim=self.sim, task=task)
            except SimulatorError as exc:  # the simulator broke down: nothing to judge
                return unjudged(f"{self.sim} failed: {exc}", started)
            move_into_place(done.bag, bag)  # the campaign's name for it, judged as the campaign's run
        finally:
            shutil.rmtree(scratch, ignore_errors=True)
        return judged(bag, Path(world), task, run, self.criteria, started)


# -- the recipe's block ------------------------------------------------------------------------------------

def _criteria(criteria: Any) -> Optional[dict]:
    """The criteria as ``worldgen judge`` reads them, read now (a file once, not in every worker).

    Each run is judged alone, so a success rate's confidence form (``{min, confidence}``: a lower bound
    over many runs, which one run can never lift above 1 - confidence) is read as its point form ``min``:
    the run must succeed (for any ``min`` > 0). The campaign's tally of runs is where the bound belongs."""
    from worldgen.judge.evaluate import load_criteria

    if criteria is None:
        return None
    checked = load_criteria(criteria)
    rate = checked.get("navigation", {}).get("success_rate")
    if isinstance(rate, Mapping):
        checked["navigation"]["success_rate"] = rate["min"]
    return checked


def system_from_spec(spec: Mapping[str, Any], *, criteria: Any = None) -> System:
    """The system a recipe's ``system:`` block names; a one-line ParameterError naming what is wrong.

    ``criteria``: a criteria file path, YAML text or mapping as ``worldgen judge --criteria`` reads it
    (None: the run meets its scenario: it reaches the goal within the time limit without contact).
    """
    if not isinstance(spec, Mapping):
        raise ParameterError(f"system must be a mapping with one of {', '.join(_KINDS)}, got {quoted(spec)}")
    unknown = sorted(str(k) for k in set(spec) - SYSTEM_KEYS)
    if unknown:
        raise ParameterError(f"system: unknown key {unknown[0]!r}; allowed: {', '.join(sorted(SYSTEM_KEYS))}")
    kinds = [k for k in _KINDS if k in spec]
    if len(kinds) != 1:
        got = " and ".join(kinds) if kinds else "none"
        raise ParameterError(f"system must name exactly one kind of system ({', '.join(_KINDS)}), got {got}")
    kind = kinds[0]
    stray = sorted(set(spec) - {kind} - _KINDS[kind])
    if stray:
        raise ParameterError(f"system: key {stray[0]!r} does not go with {kind}")
    checked = _criteria(criteria)
    from worldgen.ros.deps import require_rosbags

    require_rosbags()  # every kind's run is a bag, written or read
    if kind == "policy":
        from worldgen.envs.deps import require_gymnasium

        require_gymnasium()
        if not isinstance(spec["policy"], str):
            raise ParameterError(f"system.policy must be 'module:factory', got {quoted(spec['policy'])}")
        _factory(spec["policy"])
        return PolicySystem(spec["policy"], _env_settings(spec.get("env")), checked)
    if kind == "drive":
        return DriveSystem(_drive_sim(spec["drive"]), checked)
    check_template(spec["command"])
    return CommandSystem(spec["command"], check_timeout(spec.get("timeout", DEFAULT_TIMEOUT)), checked)


def _drive_sim(block: Any) -> str:
    from worldgen.sim.drive import SIMS

    if block is None:
        block = {}
    if not isinstance(block, Mapping):
        raise ParameterError(f"system.drive must be a mapping such as {{sim: mujoco}}, got {quoted(block)}")
    extra = sorted(str(k) for k in set(block) - {"sim"})
    if extra:
        raise ParameterError(f"system.drive: unknown key {extra[0]!r}; allowed: sim")
    sim = block.get("sim", "mujoco")
    if sim not in SIMS:
        raise ParameterError(f"system.drive.sim must be one of {', '.join(SIMS)}, got {quoted(sim)}")
    return str(sim)
