"""Scripted runs: pulls scheduled on the command line hold and let go at their times."""

import numpy as np
import pytest

import treeanim as ta
from treeanim.scripted import Pull, frames, parse_pull


class Recorder:
    """A stand-in for a Simulation that records what is held at each step."""

    def __init__(self):
        self.held, self.time, self.log = {}, 0.0, []

    def pull(self, i, force):
        self.held[i] = tuple(force)

    def release(self, i=None):
        if i is None:
            self.held.clear()
        else:
            self.held.pop(i, None)

    def step(self, dt):
        self.log.append((self.time, dict(self.held)))
        self.time += dt


def held_at(log, t):
    return next(h for t0, h in reversed(log) if t0 <= t + 1e-9)


def test_overlapping_and_back_to_back_pulls():
    pulls = [parse_pull("0:1,0,0@0-2"), parse_pull("1:0,0,2@1-3"), parse_pull("0:0,-5,0@2-2.5")]
    rec = Recorder()
    list(frames(rec, 4.0, 10, pulls, step=0.05))
    assert held_at(rec.log, 0.5) == {0: (1.0, 0.0, 0.0)}
    assert held_at(rec.log, 1.5) == {0: (1.0, 0.0, 0.0), 1: (0.0, 0.0, 2.0)}
    assert held_at(rec.log, 2.2) == {0: (0.0, -5.0, 0.0), 1: (0.0, 0.0, 2.0)}
    assert held_at(rec.log, 2.7) == {1: (0.0, 0.0, 2.0)}
    assert held_at(rec.log, 3.5) == {}
    assert rec.held == {}, "everything is let go at the end"


def test_frames_reach_their_times_in_fixed_steps():
    """The viewer's clock (treeanim.clock): every step 1/60 s, each frame within half a step
    of its time, at a frame rate the step does not divide."""
    rec = Recorder()
    times = [rec.time for _ in frames(rec, 2.0, 7, [])]
    assert len(times) == 14
    np.testing.assert_allclose(times, np.arange(14) / 7, atol=0.5 / 60 + 1e-12)
    steps = np.diff([t for t, _ in rec.log])
    np.testing.assert_allclose(steps, 1 / 60, rtol=1e-9)


def test_scripted_pull_matches_hand_stepping():
    """The same pull scheduled by frames() and done by hand gives the same motion."""
    tree = ta.load_preset("beam")
    a, b = ta.Simulation(tree), ta.Simulation(tree)
    for k in frames(a, 2.0, 20, [Pull(0, (1.0, 0.0, 0.5), 0.25, 1.0)], step=0.05):
        pass
    t = 0.0
    while t < 1.95 - 1e-9:
        if 0.25 - 1e-9 <= t < 1.0 - 1e-9:
            b.pull(0, (1.0, 0.0, 0.5))
        else:
            b.release()
        b.step(0.05)
        t += 0.05
    np.testing.assert_allclose(a.positions, b.positions, atol=1e-9)
    assert np.abs(a.positions - tree.rest_positions).max() > 1e-3


@pytest.mark.parametrize("text", ["0:1,2@0-1", "x:1,2,3@0-1", "0:1,2,3@2-1", "0:1,2,3", "0:nan,0,0@0-1"])
def test_bad_pull_refused(text):
    with pytest.raises(ValueError, match="--pull"):
        parse_pull(text)
