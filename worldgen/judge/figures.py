"""The oracles' figures of one recorded run in one world (the implementation behind :mod:`worldgen.testing.oracles`).

A trajectory is an (n, 3) array-like of ``t, x, y`` rows (seconds, metres), or
(n, 4) with a yaw column, which is accepted and ignored: every figure here is
about the footprint, a vertical cylinder, which looks the same at every yaw.
Times must not decrease.

A world is what :func:`worldgen.groundtruth.ground.load` takes: a :class:`~worldgen.World`, a world of a built pack
(:class:`~worldgen.PackWorld`, folder or archive) or a written world folder (its
world.json is read). Figures are for the world's first task unless ``task`` names another.

Clearances and contacts are FCL distances between the footprint cylinder
(world.json ``robot``) and every collider, measured at the recorded samples and
between them no further apart than a quarter of the robot radius (the same
spacing the feasibility check proves reference paths at), so a run that cuts
through a thin obstacle between two recorded samples is still caught.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any, Optional

import numpy as np

from worldgen.errors import ParameterError
from worldgen.groundtruth.ground import Ground, as_trajectory, leaves_of, load
from worldgen.judge.proxemics import social_split
from worldgen.judge.social import disc_gaps, discs, social_figures, timed_samples

__all__ = [
    "Contact", "Run",
    "path_length", "path_efficiency", "time_to_goal", "reached_goal", "min_clearance",
    "collisions", "door_contacts", "DOOR_DEBOUNCE", "min_separation", "run", "BARN_K", "BARN_REFERENCE_SPEED", "barn_score",
]


@dataclass(frozen=True)
class Contact:
    """The footprint touches ``entity`` from time ``time`` (s) on (the first sample of each contact)."""

    time: float
    entity: str


#: Seconds (of the run's time): a touch of a door leaf that begins within this of the last touch of the same
#: leaf ending is the same door contact (one push, whose contact MuJoCo makes and breaks many times as the
#: leaf gives way), not a new one. The environment counts door contacts by the same rule.
DOOR_DEBOUNCE = 2.0


# -- figures -------------------------------------------------------------------

def path_length(trajectory) -> float:
    """Length (m) of the recorded polyline."""
    xy = as_trajectory(trajectory)[:, 1:]
    return float(np.hypot(*np.diff(xy, axis=0).T).sum()) if len(xy) > 1 else 0.0


def path_efficiency(trajectory, world, task: Optional[str] = None) -> float:
    """Recorded length / the task's reference path length (1.0 = as short as the best path; > 1 = longer)."""
    ref = (load(world).task(task)["path"] or {}).get("length")
    if ref is None or ref <= 0:
        raise ParameterError(f"task {load(world).task(task)['id']!r} has no reference path length to compare with")
    return path_length(trajectory) / float(ref)


def _goal_index(traj: np.ndarray, task: dict) -> Optional[int]:
    goal = np.asarray(task["goal"][:2], dtype=float)
    d = np.hypot(*(traj[:, 1:] - goal).T)
    hits = np.nonzero(d <= float(task["goal_tolerance"]))[0]
    return int(hits[0]) if len(hits) else None


def reached_goal(trajectory, world, task: Optional[str] = None) -> bool:
    """True when some recorded sample lies within the task's goal_tolerance of its goal point."""
    return _goal_index(as_trajectory(trajectory), load(world).task(task)) is not None


def time_to_goal(trajectory, world, task: Optional[str] = None) -> Optional[float]:
    """Seconds from the first sample to the first sample within goal_tolerance; None if never reached."""
    traj = as_trajectory(trajectory)
    k = _goal_index(traj, load(world).task(task))
    return None if k is None else float(traj[k, 0] - traj[0, 0])


def _dense(traj: np.ndarray, spacing: float) -> np.ndarray:
    """(m, 3) ``t, x, y``: the recorded samples plus interpolated ones, no gap wider than ``spacing``."""
    if len(traj) < 2:
        return traj
    seg = np.diff(traj, axis=0)
    n = np.maximum(np.ceil(np.hypot(seg[:, 1], seg[:, 2]) / spacing).astype(np.int64), 1)
    owner = np.repeat(np.arange(len(seg)), n)
    frac = (np.arange(n.sum()) - np.repeat(np.cumsum(n) - n, n)) / np.repeat(n, n)
    return np.vstack([traj[:-1][owner] + frac[:, None] * seg[owner], traj[-1:]])


def _samples(traj: np.ndarray, ground: Ground) -> np.ndarray:
    """The run at least every quarter robot radius of its path, and, where movers or people walk, at least
    every PEOPLE_DT s too (a robot standing still while a person walks into it has few samples in space)."""
    pts = _dense(traj, ground.robot.radius / 4.0)
    if ground.meta.get("dynamic_obstacles") or ground.meta.get("people"):
        both = np.vstack([pts, timed_samples(traj)])
        pts = both[np.unique(both[:, 0], return_index=True)[1]]
    return pts


def min_clearance(trajectory, world) -> float:
    """Smallest FCL distance (m) from the footprint to any collider along the run; negative = FCL contact depth.

    Door leaves are left out, as from :func:`collisions`: a robot may push one open, and a leaf where it
    started says nothing about a leaf that swung (its contacts are :func:`door_contacts`).
    """
    ground = load(world)
    pts = _samples(as_trajectory(trajectory), ground)
    fixed = ground.fixed_colliders
    best = float(fixed.nearest(ground.robot, pts[:, 1:], expect=ground.robot.clearance).distance)
    if best > 0:
        return best
    # FCL's signed distance reads ~0 for a cylinder inside a box: take its contact depth instead.
    return min(best, -max((depth for _, _, depth in _touching(pts, ground, fixed)), default=0.0))


def collisions(trajectory, world) -> list[Contact]:
    """Every contact of the footprint with a collider or a mover along the run, in time order.

    A contact is reported once, at the first sample where it begins; the same
    entity touched again after a gap is a second contact. A mover is touched
    where its disc, at the sample's time, meets the footprint's (gap <= 0, as
    FCL counts touching). A door leaf (world.json ``doors[].name``) is not a
    collision: a robot may push it open, the way the reference path goes through
    its doorway; :func:`door_contacts` reports those contacts.
    """
    leaves = leaves_of(load(world))
    return [c for c in _contacts(trajectory, world) if c.entity not in leaves]


def door_contacts(trajectory, world) -> list[Contact]:
    """The contacts of :func:`collisions`' kind with door leaves, each leaf where it starts (pushed, not hit).

    One per push: a touch of a leaf beginning within :data:`DOOR_DEBOUNCE` s of the last sample touching
    that leaf continues the same door contact.
    """
    leaves = leaves_of(load(world))
    return [c for c in _contacts(trajectory, world) if c.entity in leaves] if leaves else []


def _contacts(trajectory, world) -> list[Contact]:
    ground = load(world)
    pts = _samples(as_trajectory(trajectory), ground)
    col = ground.colliders
    names = list(col.names) + discs(ground.meta)[0]  # colliders, then movers and people
    touching = np.zeros((len(pts), len(names)), dtype=bool)
    for p, c, _ in _touching(pts, ground):
        touching[p, c] = True
    if len(names) > len(col):
        touching[:, len(col):] = disc_gaps(pts, ground) <= 0.0
    starts = touching & ~np.vstack([np.zeros((1, touching.shape[1]), dtype=bool), touching[:-1]])
    leaves = leaves_of(ground)
    for c in (c for c, name in enumerate(names) if name in leaves):
        on = np.nonzero(touching[:, c])[0]
        # A leaf touched again soon after is the same push (DOOR_DEBOUNCE): no new contact.
        again = on[1:][(np.diff(on) > 1) & (np.diff(pts[on, 0]) <= DOOR_DEBOUNCE)]
        starts[again, c] = False
    out = [Contact(float(pts[p, 0]), names[c]) for p, c in zip(*np.nonzero(starts))]
    return sorted(out, key=lambda k: (k.time, k.entity))


def _touching(pts: np.ndarray, ground: Ground, colliders=None):
    """(sample index, collider index, FCL penetration depth) of every touching pair (of ``colliders``,
    by default every collider of the world)."""
    col, robot = colliders if colliders is not None else ground.colliders, ground.robot
    if len(col) == 0:
        return
    # Only pairs whose box bound says they could touch are asked of FCL.
    candidates = col.lower_bounds(robot, pts[:, 1:]) <= 1e-9
    body = col.body(robot)
    for p, c in zip(*np.nonzero(candidates)):
        col.place(body, robot, pts[p, 1], pts[p, 2])
        d = col.distance(body, robot, int(c))
        if d <= 0.0:  # FCL counts touching as contact
            yield int(p), int(c), col.depth(body, int(c)) if d < 0.0 else 0.0


def min_separation(trajectory, world) -> Optional[float]:
    """Smallest gap (m) between the footprint's edge and any mover's or person's disc over the run's times.

    Movers and people are where world.json's ``dynamic_obstacles`` scripts and ``people`` tracks have
    them at each sample time (:func:`worldgen.scene.motion.positions_at`); None without either.
    """
    ground = load(world)
    if not (ground.meta.get("dynamic_obstacles") or ground.meta.get("people")):
        return None
    # Movers walk at about a metre a second: sample time no coarser than the footprint spacing allows.
    return float(disc_gaps(_samples(as_trajectory(trajectory), ground), ground).min())


@dataclass(frozen=True)
class Run:
    """Every figure of one run in one world, as :func:`worldgen.judge.evaluate.evaluate` tabulates them."""

    world_id: str
    task: str
    reached_goal: bool
    time_to_goal: Optional[float]
    duration: float
    path_length: float
    path_efficiency: Optional[float]
    min_clearance: float
    collisions: tuple[Contact, ...]
    min_separation: Optional[float]
    max_velocity: float
    #: The task's exact reference path length (m); None where the world has no proven path.
    reference_length: Optional[float] = None
    #: Contacts with door leaves (pushed open: not collisions).
    door_contacts: tuple[Contact, ...] = ()
    #: With people (worldgen.judge.social): the smallest gap to one (m), the seconds spent in a
    #: person's personal space, the smallest time to collision with one (s; None: never on course).
    min_person_distance: Optional[float] = None
    personal_space_time: Optional[float] = None
    min_time_to_collision: Optional[float] = None
    #: With people: the figures users compare across tools, split by behaviour
    #: (:func:`worldgen.judge.proxemics.social_split`); left out of :meth:`as_dict` without people.
    social: Optional[dict] = None

    def as_dict(self) -> dict[str, Any]:
        d = {k: getattr(self, k) for k in self.__dataclass_fields__}
        if d["social"] is None:
            del d["social"]
        for key in ("collisions", "door_contacts"):
            d[key] = [{"time": c.time, "entity": c.entity} for c in getattr(self, key)]
        return d


def run(trajectory, world, task: Optional[str] = None) -> Run:
    """All figures of one run at once (colliders built once)."""
    ground = load(world)
    traj = as_trajectory(trajectory)
    t = ground.task(task)
    length = path_length(traj)
    ref = (t["path"] or {}).get("length")  # None where the world has no proven path (infeasible on purpose)
    dt = np.diff(traj[:, 0])
    step = np.hypot(*np.diff(traj[:, 1:], axis=0).T)
    moving = dt > 0
    vmax = float((step[moving] / dt[moving]).max()) if np.any(moving) else 0.0
    contacts, leaves = _contacts(traj, ground), leaves_of(ground)  # FCL once, split as collisions() and door_contacts()
    person_gap, personal_time, ttc = social_figures(traj, ground)  # the run among people, sampled once
    return Run(
        world_id=str(ground.meta.get("world_id", "")), task=t["id"],
        reached_goal=reached_goal(traj, ground, task), time_to_goal=time_to_goal(traj, ground, task),
        duration=float(traj[-1, 0] - traj[0, 0]), path_length=length,
        path_efficiency=(length / float(ref)) if ref else None,
        min_clearance=min_clearance(traj, ground), collisions=tuple(c for c in contacts if c.entity not in leaves),
        min_separation=min_separation(traj, ground), max_velocity=vmax,
        reference_length=float(ref) if ref else None,
        door_contacts=tuple(c for c in contacts if c.entity in leaves),
        min_person_distance=person_gap, personal_space_time=personal_time, min_time_to_collision=ttc,
        social=social_split(trajectory, ground, task) if ground.meta.get("people") else None,
    )


# -- the BARN Challenge's score --------------------------------------------------------

#: The lower clip of the BARN score, in optimal times. The ICRA 2022 runner (Daffan/the-barn-challenge,
#: run.py) clipped at 4; its ROS 2 runner, used for the dynamic worlds 300-359, clips at 2, so a
#: perfect run scores 0.5. 2 is the default: scores comparable with today's challenge.
BARN_K = 2.0
#: m/s. BARN's optimal time is the reference path length / 2 m/s (the Jackal's top speed), in every runner.
BARN_REFERENCE_SPEED = 2.0
#: The upper clip (optimal times), the same in every BARN runner: slower runs all score 1/8.
_BARN_CEILING = 8.0


def barn_score(success: bool, time: Optional[float], reference_length: Optional[float],
               k: float = BARN_K, reference_speed: float = BARN_REFERENCE_SPEED) -> Optional[float]:
    """The BARN Challenge score of one run: success x OT / clip(time, k OT, 8 OT), OT = length / speed.

    ``reference_length`` is the task's exact reference path length (m); without one (a world with no
    proven path) there is no optimal time and the score is None. A failed run scores 0.
    """
    if not (isinstance(k, (int, float)) and 0 < k <= _BARN_CEILING):
        raise ParameterError(f"parameter 'barn_k' must be in (0, {_BARN_CEILING:g}] (BARN used 4, then 2), got {k!r}")
    if not (isinstance(reference_speed, (int, float)) and 0 < reference_speed < float("inf")):
        raise ParameterError(f"parameter 'reference_speed' must be a number > 0 (m/s), got {reference_speed!r}")
    if reference_length is None or reference_length <= 0:
        return None
    if not success:
        return 0.0
    if time is None:
        raise ParameterError("a successful run needs its time to goal for a BARN score, got None")
    optimal = float(reference_length) / float(reference_speed)
    return optimal / min(max(float(time), k * optimal), _BARN_CEILING * optimal)


# -- colliders from world.json (a folder has no Scene) ------------------------------
