"""``worldgen/Navigation-v0``: point-goal navigation for a differential-drive robot in MuJoCo.

    >>> import gymnasium, worldgen.envs
    >>> env = gymnasium.make("worldgen/Navigation-v0", preset="drl_arena")
    >>> obs, info = env.reset(seed=0)             # a new checked world, in memory
    >>> obs, reward, terminated, truncated, info = env.step(env.action_space.sample())
    >>> env.observation_space.contains(obs)
    True

Worlds: ``generator`` and ``params`` (any registered generator), or ``preset``
(a preset's name or file, ``params`` on top), a new world per episode; or
``pack`` (a :class:`~worldgen.Pack` or its folder or archive), its worlds in
order, again from the first after the last: a fixed benchmark set. Default:
the ``drl_arena`` preset. Each episode drives the world's first task.
``curriculum`` (``"levels"``, ``"replay"`` or an instance of
:class:`~worldgen.envs.curriculum.LevelCurriculum` or :class:`~worldgen.envs.replay.LevelReplay`)
picks each episode's world from how the learner did (docs/rl.md, Curricula).

Action: ``Box([v_min, -w_max], [v_max, w_max])``, float32: forward speed v (m/s)
and turn rate w (rad/s, counter-clockwise), held for one control period
(``control_period``, default 0.1 s = 50 physics steps at the usual 0.002 s).
Values outside the box are clipped to it. The box is the ``linear_velocity`` and
``angular_velocity`` settings where given; unset, the robot's own limits
(its world's robot description: ``[0, max_speed]`` and ``turn_rate``; over a pack the
largest among its worlds), and each episode's robot then moves within its world's limits.

Observation: ``Box`` of float32, length ``S + 4``:
``[scan[0..S-1], goal_distance, goal_angle, last_v, last_w]`` where ``scan`` is the
lidar (``lidar_beams`` ranges, or ``lidar_sectors`` minima) in m within
``[lidar_range_min, lidar_range_max]``; ``goal_distance`` (m, in ``[0, D]``) and
``goal_angle`` (rad in [-pi, pi], counter-clockwise from the heading) are the
goal in the robot's frame (polar); ``last_v``, ``last_w`` the action applied in
the previous step (0 after a reset). Every bound is finite and fixed at
construction: ``D`` is ``goal_distance_max`` when set, else the diagonal of the
largest world the source makes (a generator's ``size``; a pack's largest
``bounds``; for a generator without ``size``, the seed-0 world's diagonal), and
a longer distance is clipped to it.

Reward, termination, truncation: :mod:`worldgen.envs.reward` (by default +100 at
the goal, -100 on a collision, plus potential-based shaping by the geodesic
distance to the goal, minus a time penalty; ``reward="walkthrough"`` for the
walkthrough's ``v/2 - |w|/2 - (1 - r)/2``); an episode terminates when the
robot's centre is within the task's ``goal_tolerance`` of the goal at the end
of a step, or at its first contact with anything but the floor (MuJoCo
contacts, checked every physics step; movers count; door leaves do not: the
robot may push a leaf open, and those contacts are reported apart,
``door_contacts``, one per push; by default a door whose leaf swings towards
the robot opens by itself as it comes near: the ``doors`` setting,
:mod:`worldgen.envs.doors`); it is truncated at the time limit: ``time_limit_factor`` x
the optimal time ``L / v_max`` (among people: the task's certified ``arrival_time`` where that is
longer) plus a half turn ``pi / w_max`` (default factor 2), or the task's own ``time_limit``
(world.json) when ``time_limit_factor`` is None.

Info: at reset ``world_id``, ``task``, ``reference_path_length`` (the optimal
path length, world.json ``tasks[].path.length``), ``time_limit`` (the one in force),
``geodesic_distance`` (the field's value at the spawn, when it is built), and
``world_seed`` (generated worlds) or ``world_index`` (packs); every step
``time`` and ``door_contact`` (the robot touched a door leaf during the step); at an episode's end also the figures of
:meth:`worldgen.envs.episode.Episode.figures`, under the oracles' names:
``success``, ``spl``, ``path_length``, ``collisions``, ``door_contacts``, ``doors_opened``, ``min_clearance``,
``duration``, ``time_to_goal``, ``reached_goal``, ...

Terrain: in a world with terrain (world.json ``terrain``) the robot is :mod:`worldgen.envs.terrain`'s base,
whose height and tilt follow its feet's contacts with the ground, and the lidar rides and tilts with it;
in a flat world it is the planar base of :mod:`worldgen.envs.robot`, as before.

Seeding: ``reset(seed=s)`` reseeds two independent streams derived from s (one
draws each episode's world seed, one the lidar noise), so the same seeds and
actions give the same observations in any process. ``reset(options=...)``:
``{"world_seed": n}`` drives that world of the generator, ``{"world_index": i}``
that world of the pack (the next reset goes on from there).
"""

from __future__ import annotations

import math
import time
from typing import TYPE_CHECKING, Any, Optional

import numpy as np

from worldgen.envs.config import resolve
from worldgen.envs.curriculum import make_curriculum
from worldgen.envs.deps import require_gymnasium
from worldgen.envs.doors import Openers, add_openers
from worldgen.envs.episode import Episode
from worldgen.envs.geodesic import GeodesicField
from worldgen.envs.lidar import Lidar
from worldgen.envs.period import run_period
from worldgen.envs.reacting import walkers_of
from worldgen.envs.reward import StepOutcome, reward
from worldgen.envs.robot import RobotModel, compile_world, servo_limits
from worldgen.envs.source import EpisodeWorld, PackSource, make_source
from worldgen.envs.terrain import add_base, lidar_frame, settle
from worldgen.errors import CallOrderError, ParameterError
from worldgen.groundtruth.folder import robot_description_of
from worldgen.judge.figures import Contact
from worldgen.scene.robot import MAX_SPEED, TURN_RATE
from worldgen.seeding import check_seed, draw_seed, env_rngs

if TYPE_CHECKING:  # the checker reads Gymnasium's types; at run time a missing extra is one clear line
    import gymnasium as gym
else:
    gym = require_gymnasium()

__all__ = ["NavigationEnv"]


class NavigationEnv(gym.Env):
    """Point-goal navigation in worldgen worlds (see the module's docstring for every space and rule)."""

    metadata: dict[str, Any] = {"render_modes": ["rgb_array"], "render_fps": 10}

    def __init__(self, generator: Optional[str] = None, params: Optional[dict] = None, preset: Optional[str] = None,
                 pack=None, render_mode: Optional[str] = None, difficulty: Optional[str] = None, curriculum: Any = None,
                 **settings: Any):
        if render_mode is not None and render_mode not in self.metadata["render_modes"]:
            raise ParameterError(f"parameter 'render_mode' must be one of None, "
                                 f"{', '.join(self.metadata['render_modes'])}, got {render_mode!r}")
        self.config = cfg = resolve(settings)
        self.source = make_source(generator, params, preset, pack, difficulty)  # difficulty: "7/10" (worldgen.leveling)
        #: This environment's own curriculum (worldgen.envs.curriculum, docs/rl.md#curricula), or None.
        self.curriculum = make_curriculum(curriculum, self.source)
        self.render_mode = render_mode
        self.metadata = dict(self.metadata, render_fps=1.0 / cfg.control_period)
        self.lidar = Lidar(cfg.lidar_beams, cfg.lidar_fov, cfg.lidar_angle_min, cfg.lidar_range_min,
                           cfg.lidar_range_max, cfg.lidar_noise, cfg.lidar_sectors)
        (v_lo, v_hi), w = self._action_bound()
        self._act_lo = np.array([v_lo, -w], dtype=np.float32)
        self._act_hi = np.array([v_hi, w], dtype=np.float32)
        self.action_space = gym.spaces.Box(self._act_lo, self._act_hi, dtype=np.float32)
        n = self.lidar.size
        if cfg.goal_distance_max is not None:
            self.goal_distance_max, self.goal_distance_bound_exact = float(cfg.goal_distance_max), False
        else:
            self.goal_distance_max, self.goal_distance_bound_exact = self.source.distance_bound()
        # The float32 bound rounded up, so that a float64 distance within it never lands above it.
        self._distance_cap = float(np.nextafter(np.float32(self.goal_distance_max), np.float32(np.inf)))
        low = np.concatenate([np.full(n, cfg.lidar_range_min), [0.0, -math.pi], self._act_lo]).astype(np.float32)
        high = np.concatenate([np.full(n, cfg.lidar_range_max), [self._distance_cap, math.pi],
                               self._act_hi]).astype(np.float32)
        # The geodesic field is built at each reset only where a reward can read it.
        self._needs_geodesic = cfg.reward == "geodesic" or cfg.reward_fn is not None
        self.geodesic: Optional[GeodesicField] = None
        self.observation_space = gym.spaces.Box(low, high, dtype=np.float32)
        self._world_rng: Optional[np.random.Generator] = None
        self._noise_rng: Optional[np.random.Generator] = None
        self._next_index = 0
        self._sim: Optional[RobotModel] = None
        # On terrain, the body's centre over flat ground (where the lidar rides from); None on flat ground.
        self._centre: Optional[float] = None
        self.world: Optional[EpisodeWorld] = None
        self.episode: Optional[Episode] = None
        self._painter = None
        self.reset_timings: dict = {}

    def _action_bound(self) -> tuple[tuple[float, float], float]:
        """((v_min, v_max), w_max) of the action box: the settings where given, else the source's robots'
        largest limits (a source that states none: the description's defaults)."""
        cfg = self.config
        bound = getattr(self.source, "motion_bound", None)
        speed, turn = bound() if bound is not None else (MAX_SPEED, TURN_RATE)
        v = cfg.linear_velocity if cfg.linear_velocity is not None else (0.0, speed)
        return v, cfg.angular_velocity if cfg.angular_velocity is not None else turn

    def _servo_limits(self, world: EpisodeWorld) -> tuple[tuple[float, float], float]:
        """The episode's servos' (v_min, v_max), w_max: the settings where given, else the limits of its world's
        robot description."""
        robot = world.description if world.description is not None else robot_description_of(world.metadata())
        return servo_limits(robot, self.config.linear_velocity, self.config.angular_velocity)

    # -- episode --------------------------------------------------------------------------------------------
    def _reseed(self, seed: Optional[int]) -> None:
        entropy = seed if seed is not None else draw_seed(self.np_random)
        self._world_rng, self._noise_rng = env_rngs(entropy)
        if self.curriculum is not None:
            self.curriculum.reseed(entropy)

    def _next_world(self, options: dict):
        if isinstance(self.source, PackSource):
            index = options.get("world_index", self._next_index)
            if isinstance(index, bool) or not isinstance(index, (int, np.integer)) or not 0 <= index < len(self.source):
                raise ParameterError(f"option 'world_index' must be an integer in [0, {len(self.source) - 1}], "
                                     f"got {index!r}")
            self._next_index = (int(index) + 1) % len(self.source)
            return self.source.world(int(index)), {"world_index": int(index)}
        seed = options.get("world_seed")
        if self.curriculum is not None:
            if seed is None:
                return self.curriculum.next_world(self.source, self._world_rng)
            self.curriculum.leave()  # a world the caller chose: not the curriculum's episode
        assert self._world_rng is not None, "reset() seeds the world stream first"
        seed = draw_seed(self._world_rng) if seed is None else check_seed(seed, "option 'world_seed'")
        return self.source.world(seed), {"world_seed": seed}

    def reset(self, *, seed: Optional[int] = None, options: Optional[dict] = None):
        super().reset(seed=seed)
        if seed is not None or self._world_rng is None:
            self._reseed(seed)
        options = dict(options or {})
        known = "world_index" if isinstance(self.source, PackSource) else "world_seed"
        unknown = sorted(set(options) - {known})
        if unknown:
            raise ParameterError(f"unknown reset option '{unknown[0]}' for worlds from a "
                                 f"{'pack' if known == 'world_index' else 'generator'}; known options: {known}")
        t0 = time.perf_counter()
        world, where = self._next_world(options)
        t1 = time.perf_counter()
        cfg = self.config
        spawn = world.task["spawn"]
        movers = walkers_of(world)  # people who react to the robot among them (docs/people.md)
        (v_lo, v_max), w_max = self._servo_limits(world)
        floor = add_base(world.mjcf, world.robot, (v_lo, v_max), w_max, world.terrain, world.floor)
        add_openers(world.mjcf, world.doors, cfg.doors)
        sim = compile_world(world.mjcf, (spawn[0], spawn[1], spawn[5]), floor, [m["name"] for m in world.movers])
        self._centre = settle(sim, world.robot) if world.terrain else None
        world.mjcf = None  # the tree is compiled: let it go
        self._substeps = cfg.substeps(float(sim.model.opt.timestep))
        self._sim = sim
        t2 = time.perf_counter()
        self._goal = np.array(world.task["goal"][:2], dtype=float)
        self.geodesic = None
        if self._needs_geodesic:
            self.geodesic = GeodesicField.for_scene(world.scene(), world.robot, self._goal, cfg.geodesic_spacing)
        t3 = time.perf_counter()
        self._movers = movers
        if len(movers):
            movers.place(sim.data, sim.mocap, movers.positions(np.zeros(1))[0])
        import mujoco
        mujoco.mj_forward(sim.model, sim.data)
        self._openers = Openers(sim.model, sim.data, world.doors, cfg.doors, cfg.door_trigger, cfg.door_speed)
        self.world = world
        self._tolerance = float(world.task["goal_tolerance"])
        if cfg.time_limit_factor is None:
            self._time_limit = float(world.task["time_limit"])
        else:
            optimal = max(world.reference_path_length / v_max, world.task.get("arrival_time") or 0.0)  # among people
            self._time_limit = cfg.time_limit_factor * optimal + math.pi / w_max
        self._lidar_height = cfg.lidar_height if cfg.lidar_height is not None else world.lidar_height
        self._last_action = np.zeros(2)
        self.episode = Episode(world, *sim.pose())
        self.episode.walkers = movers
        self._painter = None
        obs = self._observe()
        #: Seconds the last reset spent getting the world (generating or reading it), adding the robot and
        #: compiling, building the geodesic field, and in all (benchmarks/bench_env.py reports them).
        self.reset_timings = {"world": t1 - t0, "compile": t2 - t1, "geodesic": t3 - t2,
                              "total": time.perf_counter() - t0}
        x, y, _ = sim.pose()
        self._geodesic_now = self.geodesic.distance(x, y) if self.geodesic is not None else math.nan
        info = {"world_id": world.world_id, "task": str(world.task["id"]),
                "reference_path_length": world.reference_path_length, "time_limit": self._time_limit, **where}
        if self.geodesic is not None:
            info["geodesic_distance"] = self._geodesic_now
        return obs, info

    def report_score(self, value: float) -> None:
        """The learner's score for this episode's level (``curriculum="replay"``: e.g. its mean absolute
        advantage); in a vector env ``envs.call("report_score", v)`` or ``envs.set_attr("level_score", [...])``."""
        if self.curriculum is None:
            raise ParameterError("report_score needs an environment made with curriculum='replay'")
        self.curriculum.report_score(value)

    @property
    def level_score(self) -> float:
        """This episode's level's score (``curriculum="replay"``; NaN before one); set it to report one."""
        current = getattr(self.curriculum, "current", None)
        return float(current.score) if current is not None else math.nan

    @level_score.setter
    def level_score(self, value: float) -> None:
        self.report_score(value)

    def curriculum_stats(self) -> dict:
        """The curriculum's figures for logging (per-level success, or the replay buffer's); {} without one."""
        return self.curriculum.stats() if self.curriculum is not None else {}

    @property
    def task(self) -> dict:
        """The current episode's task, as world.json ``tasks[]`` has it (spawn, goal, path, time_limit, ...)."""
        if self.world is None:
            raise CallOrderError("call reset() first: there is no episode yet")
        return self.world.task

    @property
    def robot_pose(self) -> tuple[float, float, float]:
        """(x, y, yaw) of the robot now: m, m, rad (a scripted baseline's privileged view)."""
        if self._sim is None:
            raise CallOrderError("call reset() first: there is no episode yet")
        return self._sim.pose()

    # -- stepping -------------------------------------------------------------------------------------------
    def _running(self) -> tuple[RobotModel, Episode, EpisodeWorld]:
        """The episode's compiled world, its record and its world; CallOrderError before the first reset."""
        if self._sim is None or self.episode is None or self.world is None:
            raise CallOrderError("call reset() first: there is no episode yet")
        return self._sim, self.episode, self.world

    def step(self, action):
        if self.episode is None or self.episode.done:
            raise CallOrderError("call reset() first: the episode has not started or has ended")
        a = np.asarray(action, dtype=np.float64).reshape(-1)
        if a.shape != (2,) or not np.all(np.isfinite(a)):
            raise ParameterError(f"parameter 'action' must be two finite numbers (v m/s, w rad/s), got {action!r}")
        v, w = np.clip(a, self._act_lo, self._act_hi)
        sim, ep, _ = self._running()
        data = sim.data
        data.ctrl[sim.ctrl] = (v, 0.0, w)
        previous = self._goal_polar(*sim.pose())[0]
        ep.new_step()
        if len(self._openers):
            ep.door_openings.extend(Contact(float(data.time), name) for name in self._openers.update(*sim.pose()[:2]))
        collided = self._simulate()
        x, y, yaw = sim.pose()
        ep.record(float(data.time), x, y, yaw)
        self._last_action = np.array([v, w])
        obs = self._observe()
        distance, angle = self._goal_polar(x, y, yaw)
        reached = distance <= self._tolerance
        geodesic_before = self._geodesic_now
        if self.geodesic is not None:
            self._geodesic_now = self.geodesic.distance(x, y)
        outcome = StepOutcome(float(v), float(w), reached, collided, float(self._ranges.min()), distance,
                              previous, angle, float(data.time), self._geodesic_now, geodesic_before)
        r = reward(outcome, self.config)
        terminated = bool(reached or (collided and self.config.terminate_on_collision))
        truncated = bool(not terminated and data.time >= self._time_limit - 1e-9)
        info = {"time": float(data.time), "door_contact": ep.door_touched}
        if terminated or truncated:
            ep.done = True
            info.update(ep.figures())
            if self.curriculum is not None:
                info.update(self.curriculum.episode_end(info))
        return obs, r, terminated, truncated, info

    def _simulate(self) -> bool:
        """One control period of physics steps (movers driven before each); True when a contact began."""
        sim, ep, world = self._running()
        return run_period(sim, ep, self._movers, self._substeps, world.robot.radius, self.config.terminate_on_collision)

    def _goal_polar(self, x: float, y: float, yaw: float) -> tuple[float, float]:
        dx, dy = self._goal[0] - x, self._goal[1] - y
        angle = (math.atan2(dy, dx) - yaw + math.pi) % (2.0 * math.pi) - math.pi
        return math.hypot(dx, dy), angle

    def _observe(self) -> np.ndarray:
        sim = self._running()[0]
        x, y, yaw = sim.pose()
        # On terrain the lidar rides and tilts with the body (worldgen.envs.terrain); on flat ground it is level.
        frame = None if self._centre is None else lidar_frame(sim, self._lidar_height, self._centre)
        self._ranges = self.lidar.cast(sim.model, sim.data, x, y, yaw, self._lidar_height, sim.body, frame)
        scan = self.lidar.observe(self._ranges, self._noise_rng)
        distance, angle = self._goal_polar(x, y, yaw)
        obs = np.empty(self.lidar.size + 4, dtype=np.float32)
        obs[:-4] = scan
        obs[-4:] = (min(distance, self._distance_cap), angle, self._last_action[0], self._last_action[1])
        return obs

    # -- drawing --------------------------------------------------------------------------------------------
    def render(self):
        if self.render_mode is None:
            gym.logger.warn("render() was called without a render_mode; pass render_mode='rgb_array' to the env")
            return None
        if self.episode is None:
            raise CallOrderError("call reset() before render()")
        from worldgen.envs.render import TopDown, mover_discs

        if self._painter is None:
            self._painter = TopDown(self.world.metadata())
        traj = self.episode.trajectory
        xy = self._movers.positions([self._sim.data.time])[0] if len(self._movers) else None
        return self._painter.frame(self._sim.pose(), traj[:, 1:3], self.lidar.angles, self._ranges,
                                   mover_discs(self.world.movers, xy), bool(self.episode.contacts))

    def close(self):
        self._sim = None
        self._painter = None
        super().close()

