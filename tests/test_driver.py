"""The frame driver (treeanim.driver): one clock and one step policy for the viewer's frames
and the offline commands'."""

import numpy as np
import pytest

import treeanim as ta
from treeanim.driver import MAX_FRAME_DT, STEP, FrameDriver, step_for


class Counter:
    """Stands in for a Simulation: counts steps and their lengths."""

    def __init__(self):
        self.time, self.steps = 0.0, []

    def step(self, h):
        self.steps.append(h)
        self.time += h


class Hand:
    def __init__(self):
        self.calls = []

    def step(self, sim, h, exact=True):
        self.calls.append((sim.time, h, exact))


@pytest.mark.parametrize("rate,step", [(60, 1 / 60), (30, 1 / 60), (24, 1 / 72), (7, 1 / 63), (1000, 1e-3),
                                       (0.5, 1 / 60)])
def test_step_for_divides_the_frame_interval_in_steps_of_at_most_the_step(rate, step):
    assert step_for(rate) == pytest.approx(step, rel=1e-12)
    assert step_for(rate) <= STEP * (1 + 1e-12)
    assert (1 / rate) / step_for(rate) == pytest.approx(round((1 / rate) / step_for(rate)), abs=1e-9)


@pytest.mark.parametrize("fps", [2, 7, 30, 60, 144])
def test_real_time_is_kept_in_fixed_steps_at_any_frame_rate(fps):
    """Ten seconds of frames at any rate: the simulation is within half a step of real time,
    every step the same length."""
    sim, driver = Counter(), FrameDriver()
    for _ in range(10 * fps):
        driver.advance(sim, 1 / fps)
    assert sim.time == pytest.approx(10.0, abs=0.5 * STEP + 1e-9)
    np.testing.assert_allclose(sim.steps, STEP, rtol=1e-12)


def test_a_stall_is_cut_to_the_longest_frame_and_nothing_is_owed_after_it():
    sim, driver = Counter(), FrameDriver()
    driver.advance(sim, 30.0)
    assert sim.time == pytest.approx(MAX_FRAME_DT, abs=STEP)
    t = sim.time
    driver.advance(sim, 0.0)
    assert sim.time == t


def test_slow_motion_shortens_the_step_and_keeps_one_step_a_frame():
    sim, driver = Counter(), FrameDriver()
    driver.time_scale = 0.25
    assert [driver.advance(sim, STEP) for _ in range(60)] == [1] * 60
    np.testing.assert_allclose(sim.steps, STEP / 4, rtol=1e-12)
    driver.time_scale = 2.0
    assert driver.step == STEP, "fast motion takes more steps, not longer ones"
    assert driver.advance(sim, STEP) == 2


def test_the_hand_acts_before_every_step_exact_at_the_first_and_after_follows_each():
    sim, driver, hand, after = Counter(), FrameDriver(), Hand(), []
    n = driver.advance(sim, 4 * STEP, hand, lambda: after.append(sim.time))
    assert n == 4
    assert [e for _, _, e in hand.calls] == [True, False, False, False]
    assert [t for t, _, _ in hand.calls] == pytest.approx([k * STEP for k in range(4)])
    assert after == pytest.approx([k * STEP for k in range(1, 5)])


def test_reset_forgets_what_was_due():
    sim, driver = Counter(), FrameDriver()
    driver.advance(sim, 0.4 * STEP)
    driver.reset()
    assert driver.advance(sim, 0.4 * STEP) == 0
    assert driver.advance(sim, 0.4 * STEP) == 1


@pytest.mark.parametrize("step", [0.0, -1.0, float("nan")])
def test_a_step_that_is_not_positive_is_refused(step):
    with pytest.raises(ValueError, match="step"):
        FrameDriver(step)


def test_the_viewer_and_the_offline_frames_take_the_same_steps():
    """One frame driver: 2 s of a pulled beam at 30 frames a second as the viewer advances it
    (real time, a grab acting before each step) and as `render` does (frames at a rate, a
    schedule) end in the same state."""
    from treeanim.scripted import Pull, Schedule, frames

    tree = ta.load_preset("beam")
    a, b = ta.Simulation(tree), ta.Simulation(tree)
    pull = [Pull(0, (10.0, 0.0, 5.0), 0.0, 1.0)]
    moved = max(np.abs(a.positions - tree.rest_positions).max() for _ in frames(a, 60, 30, pull))
    driver, hand = FrameDriver(), Schedule(pull)
    for k in range(60):
        driver.advance(b, 1 / 30 if k else 0.0, hand)
    hand.release(b)
    assert a.time == pytest.approx(b.time)
    np.testing.assert_allclose(a.positions, b.positions, atol=1e-12)
    assert moved > 1e-2, "the pull moved the beam"


@pytest.mark.parametrize("scale", [0.0, -1.0, float("nan"), float("inf")])
def test_a_time_scale_that_is_not_finite_and_positive_is_refused_and_the_old_one_kept(scale):
    driver = FrameDriver()
    driver.time_scale = 0.5
    with pytest.raises(ValueError, match="time scale"):
        driver.time_scale = scale
    assert driver.time_scale == 0.5


@pytest.mark.parametrize("rate", [0.0, -30.0, float("nan"), float("inf")])
def test_frames_at_a_rate_that_is_not_finite_and_positive_are_refused(rate):
    with pytest.raises(ValueError, match="rate"):
        FrameDriver.at_rate(rate)


def test_frames_need_a_rate():
    with pytest.raises(ValueError, match="at_rate"):
        next(FrameDriver().frames(Counter(), 3))
