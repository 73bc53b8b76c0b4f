"""The social-navigation figures of one run: how close the robot came to people, how long it stayed in
their personal space, and how soon it would have hit one (the figures HuNavSim's evaluator reports).

People are world.json's ``people[]`` (:mod:`worldgen.people.places`), each a disc walking its
``t, x, y`` rows and waiting at its last point; scripted movers (``dynamic_obstacles[]``, looping) are
discs too. Positions come from :func:`worldgen.scene.motion.positions_at`, the same interpolation the
exports drive MuJoCo's mocap bodies with. Every figure is None in a world without people.

The run is sampled at its recorded rows and at least every :data:`PEOPLE_DT` s between them (robot
positions interpolated linearly), because people move while a robot stands still.
"""

from __future__ import annotations

import math
from typing import Optional

import numpy as np

from worldgen.groundtruth.ground import Ground, as_trajectory, load

__all__ = ["PERSONAL_SPACE", "PEOPLE_DT", "discs", "disc_gaps", "timed_samples", "min_person_distance", "personal_space_time",
           "min_time_to_collision", "social_figures"]

#: Personal space (m, from the robot's centre to a person's): the outer edge of Hall's personal zone
#: (1.2 m, "The Hidden Dimension", 1966), the radius social-navigation evaluators commonly use.
PERSONAL_SPACE = 1.2
#: The longest time step (s) between the samples the people's figures are measured at.
PEOPLE_DT = 0.05


def discs(meta: dict) -> tuple[list[str], np.ndarray, np.ndarray, list[np.ndarray], list[bool]]:
    """(names, radii, is_person, tracks, loops) of the movers then the people: mover_positions' order."""
    rows = [(m, False) for m in meta.get("dynamic_obstacles") or []] + [(p, True) for p in meta.get("people") or []]
    names = [str(m["name"]) for m, _ in rows]
    radii = np.array([float(m["radius"]) for m, _ in rows])
    person = np.array([is_person for _, is_person in rows], dtype=bool)
    tracks = [np.asarray(m["trajectory"], dtype=float) for m, _ in rows]
    loops = [bool(m.get("loop", False)) for m, _ in rows]
    return names, radii, person, tracks, loops


def disc_gaps(pts: np.ndarray, ground: Ground) -> np.ndarray:
    """(samples, discs) gap (m) between the footprint's edge and each mover's or person's disc at each
    ``t, x, y`` sample; discs in :func:`discs`' order."""
    from worldgen.scene.motion import positions_at

    _, radii, _, tracks, loops = discs(ground.meta)
    if not tracks:
        return np.zeros((len(pts), 0))
    return _centre_distance(positions_at(tracks, loops, pts[:, 0]), pts) - radii - ground.robot.radius


def timed_samples(trajectory) -> np.ndarray:
    """The run's rows plus rows every PEOPLE_DT s between them: (m, 3) ``t, x, y``."""
    traj = as_trajectory(trajectory)
    t0, t1 = float(traj[0, 0]), float(traj[-1, 0])
    times = np.union1d(traj[:, 0], np.arange(t0, t1, PEOPLE_DT)) if t1 > t0 else traj[:1, 0]
    return np.c_[times, np.interp(times, traj[:, 0], traj[:, 1]), np.interp(times, traj[:, 0], traj[:, 2])]


def _centre_distance(centres: np.ndarray, pts: np.ndarray) -> np.ndarray:
    """(samples, discs) distance from the robot's centre at each ``t, x, y`` sample to each disc's centre."""
    return np.hypot(centres[..., 0] - pts[:, 1:2], centres[..., 1] - pts[:, 2:3])


class _Among:
    """One run among a world's people, sampled once: the samples, the people's centres and radii there,
    and the centre distances, shared by every figure below."""

    def __init__(self, trajectory, world):
        from worldgen.scene.motion import positions_at

        self.ground = load(world)
        self.pts = timed_samples(trajectory)
        _, radii, person, tracks, loops = discs(self.ground.meta)
        keep = np.flatnonzero(person)
        self.any = len(keep) > 0
        if self.any:
            self.centres = positions_at([tracks[i] for i in keep], [loops[i] for i in keep], self.pts[:, 0])
            self.radii = radii[keep]
            self.distance = _centre_distance(self.centres, self.pts)

    def min_gap(self) -> Optional[float]:
        if not self.any:
            return None
        return float((self.distance - self.radii - self.ground.robot.radius).min())

    def time_within(self, radius: float) -> Optional[float]:
        if not self.any:
            return None
        inside = (self.distance < radius).any(axis=1)
        return float(np.diff(self.pts[:, 0])[inside[:-1]].sum())

    def min_ttc(self) -> Optional[float]:
        pts = self.pts
        if not self.any or len(pts) < 2:
            return None
        dt = np.diff(pts[:, 0])[:, None, None]
        v_robot = np.diff(pts[:, 1:], axis=0)[:, None, :] / dt
        v_people = np.diff(self.centres, axis=0) / dt
        p = self.centres[:-1] - pts[:-1, None, 1:]
        v = v_people - v_robot
        reach = self.radii[None, :] + self.ground.robot.radius
        a = (v * v).sum(axis=-1)
        b = 2.0 * (p * v).sum(axis=-1)
        c = (p * p).sum(axis=-1) - reach ** 2
        disc = b * b - 4.0 * a * c
        with np.errstate(divide="ignore", invalid="ignore"):
            first = (-b - np.sqrt(np.maximum(disc, 0.0))) / (2.0 * a)
        ttc = np.where(c <= 0.0, 0.0, np.where((a > 0) & (disc >= 0) & (b < 0), first, math.inf))
        best = float(ttc.min())
        return None if math.isinf(best) else best


def social_figures(trajectory, world, radius: float = PERSONAL_SPACE) -> tuple:
    """(min_person_distance, personal_space_time, min_time_to_collision) of one run, sampled once."""
    among = _Among(trajectory, world)
    return among.min_gap(), among.time_within(radius), among.min_ttc()


def min_person_distance(trajectory, world) -> Optional[float]:
    """Smallest gap (m) between the footprint's edge and any person's disc over the run (<= 0: contact)."""
    return _Among(trajectory, world).min_gap()


def personal_space_time(trajectory, world, radius: float = PERSONAL_SPACE) -> Optional[float]:
    """Seconds the robot's centre spent within ``radius`` m of any person's centre.

    Each step between samples (at most PEOPLE_DT s) counts whole when it starts inside, so the figure is
    within one step per entry or exit of the exact time.
    """
    return _Among(trajectory, world).time_within(radius)


def min_time_to_collision(trajectory, world) -> Optional[float]:
    """Smallest time to collision (s) with any person over the run; None when never on a collision course.

    At each sample the robot and each person keep their velocities over the next step (finite
    differences); the time to collision is when the two discs would first touch (0 when they already
    do). None also in a world without people.
    """
    return _Among(trajectory, world).min_ttc()
