"""People who react to the robot (worldgen.people.react): a robot standing on a person's line, the tube
held at every instant, determinism across processes, and the timed certificate against the tube."""

from __future__ import annotations

import subprocess
import sys

import numpy as np
import pytest

from worldgen.people.behaviours import BEHAVIOURS, TUBES, Tube, tube_distance
from worldgen.people.react import Reactions
from worldgen.people.timed import MARGIN, TRACKING, timed_path

ROBOT_R = 0.2
PERSON_R = 0.25


def _line(speed=1.2, start=-6.0, duration=12.0, y=0.0):
    t = np.round(np.arange(0.0, duration + 1e-9, 0.1), 6)
    return np.c_[t, start + speed * t, np.full(len(t), y)]


def _walk(behaviour, robot=(0.0, 0.0), steps=240, dt=0.05, substeps=5):
    """A person walking the x axis at 1.2 m/s through a robot standing at ``robot``: the least gap between
    the discs, every substep's position, and the clips."""
    track = _line()
    r = Reactions([track], [PERSON_R], [behaviour], [TUBES[behaviour]])
    samples = []
    for _ in range(steps):
        r.step(dt, robot, (0.0, 0.0), ROBOT_R)
        share = np.arange(1, substeps + 1) / substeps
        t = r.t - dt + dt * share
        samples.append(np.c_[t, r.positions(share)[:, 0, :]])
    rows = np.vstack(samples)
    gap = np.hypot(rows[:, 1] - robot[0], rows[:, 2] - robot[1]) - PERSON_R - ROBOT_R
    return float(gap.min()), rows, int(r.clips[0]), track


def _inside(rows, track, tube: Tube) -> float:
    """The largest amount (m) by which any sampled position lies outside the tube (<= 0: inside)."""
    dist = tube_distance(rows[:, 1:], rows[:, 0], track, tube.tau)
    return float((dist - tube.d).max())


def test_impassive_walks_into_a_robot_standing_on_its_line():
    gap, rows, clips, track = _walk("impassive")
    assert gap < -0.4 and clips == 0
    assert np.allclose(rows[:, 1], np.interp(rows[:, 0], track[:, 0], track[:, 1]), atol=1e-9)


def test_regular_yields_without_contact_and_stays_in_its_tube():
    gap, rows, clips, track = _walk("regular")
    assert gap > 0.05  # stepped aside: no contact
    assert _inside(rows, track, TUBES["regular"]) <= 1e-9
    assert rows[-1, 1] > 4.0  # and went on


@pytest.mark.parametrize("behaviour", BEHAVIOURS)
@pytest.mark.parametrize("robot", [(0.0, 0.0), (0.0, 0.5), (1.0, -0.8), (3.0, 2.0)])
def test_every_behaviour_stays_in_its_tube_at_every_substep(behaviour, robot):
    _, rows, _, track = _walk(behaviour, robot)
    assert _inside(rows, track, TUBES[behaviour]) <= 1e-9


def test_a_moving_robot_among_many_people_keeps_everyone_in_their_tubes():
    rng = np.random.default_rng(5)
    tracks = [_line(speed=rng.uniform(0.8, 1.5), start=rng.uniform(-8, -2), y=rng.uniform(-3, 3)) for _ in range(12)]
    kinds = [BEHAVIOURS[i % len(BEHAVIOURS)] for i in range(12)]
    r = Reactions(tracks, [PERSON_R] * 12, kinds, [TUBES[k] for k in kinds])
    worst = -np.inf
    for k in range(200):
        robot = (4.0 - 0.04 * k, 0.5 * np.sin(0.05 * k))
        r.step(0.05, robot, (-0.8, 0.0), ROBOT_R)
        share = np.array([0.25, 0.5, 1.0])
        xy = r.positions(share)
        for i, track in enumerate(tracks):
            t = r.t - 0.05 + 0.05 * share
            worst = max(worst, _inside(np.c_[t, xy[:, i]], track, TUBES[kinds[i]]))
    assert worst <= 1e-9


def test_surprised_stops_then_goes_on_and_curious_turns_to_the_robot():
    _, rows, _, track = _walk("surprised", robot=(0.0, 1.5))
    lag = rows[:, 0] - np.interp(rows[:, 1], track[:, 1], track[:, 0])  # how far behind its recorded time
    assert lag.max() > 1.0 and abs(lag[-1]) < 0.05
    _, rows, _, _ = _walk("curious", robot=(0.0, 2.5))
    assert rows[:, 2].max() > 0.5  # stepped toward the robot, off its line (y = 0)


_SCRIPT = """
import numpy as np
from worldgen.people.behaviours import BEHAVIOURS, TUBES
from worldgen.people.react import Reactions
t = np.round(np.arange(0, 12.0001, 0.1), 6)
tracks = [np.c_[t, -6 + (1.0 + 0.1 * i) * t, 0.3 * i - 0.6 + 0 * t] for i in range(5)]
r = Reactions(tracks, [0.25] * 5, list(BEHAVIOURS), [TUBES[b] for b in BEHAVIOURS])
out = [r.step(0.1, (0.5 - 0.02 * k, 0.1), (-0.2, 0.0), 0.2).copy() for k in range(120)]
print(np.asarray(out).tobytes().hex()[:2000], int(r.clips.sum()), repr(float(np.asarray(out).sum())))
"""


def test_reactions_are_the_same_in_fresh_processes():
    runs = {subprocess.run([sys.executable, "-c", _SCRIPT], capture_output=True, text=True, check=True).stdout
            for _ in range(2)}
    assert len(runs) == 1


def _crossing():
    """A person crossing a 6 m straight path at its middle, 1 m/s, arriving when a full-speed robot would."""
    t = np.round(np.arange(0.0, 12.0 + 1e-9, 0.1), 6)
    return np.c_[t, np.full(len(t), 3.0), -6.0 + 1.0 * t]


@pytest.mark.parametrize("tube", [Tube(0.0, 0.0), Tube(0.6, 1.5), Tube(0.3, 0.7), Tube(0.8, 0.0)])
def test_the_timed_path_clears_the_tube_and_a_wider_tube_is_touched(tube):
    way = np.array([[0.0, 0.0], [6.0, 0.0]])
    track = _crossing()
    inflation = ROBOT_R + 0.05
    timed = timed_path(way, [track], [PERSON_R], inflation, 0.5, [tube])
    assert timed is not None
    h = 0.002
    t = np.arange(0.0, timed.arrival + h, h)
    me = np.c_[np.interp(t, timed.rows[:, 0], timed.rows[:, 1]), np.interp(t, timed.rows[:, 0], timed.rows[:, 2])]
    gap = tube_distance(me, t, track, tube.tau + h / 2) - (inflation + PERSON_R + tube.d)
    assert gap.min() >= 0.5 * h  # the certificate's margin, less what the robot moves between samples
    # The earliest schedule waits only as long as it must: a tube widened past the margin is entered.
    wider = tube_distance(me, t, track, tube.tau + 0.1) - (inflation + PERSON_R + tube.d + MARGIN + TRACKING + 0.06)
    assert wider.min() < 0
