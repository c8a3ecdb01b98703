"""Seamless loops of baked rotations (treeanim.loop): the cross-fade and the measured seam."""

import numpy as np
import pytest

from treeanim.loop import angles, close_loop, seam


def _about(axis, degrees):
    """Quaternions (x, y, z, w) of rotations by ``degrees`` (...,) about unit ``axis``."""
    half = np.radians(np.asarray(degrees, float))[..., None] / 2
    return np.concatenate([np.sin(half) * np.asarray(axis, float), np.cos(half)], axis=-1)


def _sway(frames, fps, period, amplitude=30.0, joints=3):
    """(frames, joints, 4): each joint sways about its own axis, sin(2π t / period)."""
    t = np.arange(frames) / fps
    axes = np.eye(3)[:joints]
    return np.stack([_about(axes[j], amplitude * np.sin(2 * np.pi * t / period + j)) for j in range(joints)], axis=1)


def _steps(a, b):
    """Rotation vectors (degrees, ..., 3) of the steps from ``a`` to ``b``, in ``a``'s frame."""
    (ax, ay, az, aw), (bx, by, bz, bw) = np.moveaxis(a, -1, 0), np.moveaxis(b, -1, 0)
    r = np.stack([aw * bx - ax * bw - ay * bz + az * by,  # conj(a) b
                  aw * by + ax * bz - ay * bw - az * bx,
                  aw * bz - ax * by + ay * bx - az * bw,
                  aw * bw + ax * bx + ay * by + az * bz], axis=-1)
    r = np.where(r[..., 3:] < 0, -r, r)
    s = np.linalg.norm(r[..., :3], axis=-1, keepdims=True)
    return np.degrees(2 * np.arctan2(s, r[..., 3:])) * r[..., :3] / np.maximum(s, 1e-300)


def _rate_changes(keys):
    """(F - 1, J) degrees: how much each step of a closed loop (keys[-1] == keys[0]) differs
    from the step before it, cyclically; entry k is at key k (entry 0: across the loop point)."""
    q = keys[:-1].astype(float)
    step = _steps(q, np.roll(q, -1, axis=0))
    return np.linalg.norm(step - np.roll(step, 1, axis=0), axis=-1)


def test_a_closed_loop_repeats_its_first_key_at_the_end_and_keeps_its_middle():
    raw = _sway(90, 30, period=2.3)
    keys = close_loop(raw, 60)
    assert keys.shape == (61, 3, 4) and keys.dtype == np.float32
    assert np.array_equal(keys[-1], keys[0])
    assert np.allclose(np.linalg.norm(keys, axis=-1), 1, atol=1e-6)
    assert np.all(angles(keys[30:60], raw[30:60]) < 1e-3), "frames fade .. n - 1 are the simulation's"
    assert np.all(angles(keys[0], raw[60]) < 1e-3), "the first key (and the key at T) is the frame at T"


def test_a_periodic_motion_loops_unchanged():
    """A motion that returns to its state after n frames (a periodic wind's) needs no blend:
    the loop is the motion itself, and the cross-fade adds nothing."""
    raw = _sway(90, 30, period=2.0)  # 60 frames a period
    keys = close_loop(raw, 60)
    assert np.all(angles(keys[:60], raw[:60]) < 1e-3)
    assert np.all(seam(keys, raw).added < 1e-3)


def test_the_cross_fade_matches_rates_at_both_ends():
    """Across the loop point and where the fade hands over to the clip's own motion, the rate
    of change runs on as in the motion (a smoothstep weight: its slope is 0 at both ends); a
    linear weight would change the rate by δ / fade there (δ: the two motions' difference),
    the smoothstep's by at most 6 δ / fade², its curvature at the ends)."""
    fps, n, fade = 30, 90, 30
    raw = _sway(n + fade, fps, period=3.7)  # slow: the fade is shorter than a period
    keys = close_loop(raw, n)
    natural = _rate_changes(np.concatenate([raw[:n + 1], raw[:1]]))[1:n].max(axis=0)  # the motion's own
    delta = angles(raw[n:n + fade], raw[:fade]).max(axis=0)
    rate = _rate_changes(keys)
    assert np.all(delta / fade > 5 * natural), "the test's motions differ: a linear weight would show"
    for k in (0, 1, fade - 1, fade, fade + 1):
        assert np.all(rate[k] <= natural + 7 * delta / fade**2), (k, rate[k], natural, delta / fade)


def test_seam_of_an_unclosed_clip_is_its_jump():
    raw = _sway(61, 30, period=2.3)
    s = seam(raw)  # the last key is not the first: a client jumps between them in no time
    assert np.allclose(s.jump, angles(raw[-1], raw[0]))
    assert s.jump.max() > 10
    assert "off the first" in s.line()
    closed = seam(close_loop(_sway(90, 30, period=2.3), 60))
    assert np.all(closed.jump == 0) and np.all(closed.ratio() <= 1.0 + 1e-9)
    assert "the last key is 0.00° off the first" in closed.line()


def test_close_loop_refuses_a_fade_it_cannot_make():
    raw = _sway(60, 30, period=2.3)
    for n in (60, 30):  # no frame past T to fade from; a fade as long as the clip
        with pytest.raises(ValueError, match="simulated frames"):
            close_loop(raw, n)
