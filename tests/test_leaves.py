"""Living leaves (issue #12): flutter that rises with the wind, and no snap-through, measured
from the public API (the lamina's orientation is the rotation of each leaf's tip node)."""

from __future__ import annotations

import numpy as np
import pytest

import treeanim as ta


def leaf_tips(tree):
    leaves = np.flatnonzero(tree.kind == "leaf")
    return tree.object_start[leaves] + tree.object_count[leaves] - 1


def lamina_normals(name, speed, dt, seconds, warmup=2.0, every=1, **kw):
    """(T, K, 3) the rotated rest normal w of every ``every``-th leaf's lamina after ``warmup``."""
    tree = ta.load_preset(name)
    sim = ta.Simulation(tree, wind=ta.WindField(speed=speed, direction=(1.0, 0.0, 0.0)), **kw)
    tips = leaf_tips(tree)[::every]
    out = []
    for k in range(int(round(seconds / dt))):
        sim.step(dt)
        if k * dt >= warmup:
            out.append(sim.rotations[tips][:, :, 2].copy())
    return np.array(out)


def rotation_per_frame(name, speed, dt, seconds=5.0):
    """Degrees each leaf's lamina turns from one frame to the next (all leaves, all frames)."""
    tree = ta.load_preset(name)
    sim = ta.Simulation(tree, wind=ta.WindField(speed=speed, direction=(1.0, 0.0, 0.0)))
    tips = leaf_tips(tree)
    prev, angles = None, []
    for k in range(int(round(seconds / dt))):
        sim.step(dt)
        R = sim.rotations[tips]
        if prev is not None and k * dt >= 1.0:
            rel = np.einsum("kij,kil->kjl", prev, R)
            c = np.clip((np.trace(rel, axis1=1, axis2=2) - 1.0) / 2.0, -1.0, 1.0)
            angles.append(np.degrees(np.arccos(c)))
        prev = R.copy()
    assert np.isfinite(angles).all()
    return np.concatenate(angles)


def high_share(n, dt, cut=2.0):
    """Share of the orientation signal's power (about its mean) above ``cut`` Hz."""
    n = n - n.mean(axis=0)
    P = np.abs(np.fft.rfft(n, axis=0)) ** 2
    f = np.fft.rfftfreq(n.shape[0], dt)
    return float(P[f > cut].sum() / P[f > 0].sum())


def test_leaves_flutter_above_2_hz_more_in_stronger_wind_each_in_its_own_phase():
    dt = 1 / 60
    share = {}
    for U in (5.0, 15.0):
        n = lamina_normals("small_cherry", U, dt, seconds=14.0, every=3)
        share[U] = high_share(n, dt)
    # Before flutter the leaves only swung on their 1–2 Hz modes: 0.1 % (issue #12), 2 % with
    # the load path, of the orientation change lay above 2 Hz at 10 m/s.
    assert share[5.0] > 0.01
    assert share[15.0] > 0.05
    assert share[15.0] > 1.5 * share[5.0], share
    # No two leaves in lockstep: their fast (> 2 Hz) motions are nearly uncorrelated.
    spec = np.fft.rfft(n - n.mean(axis=0), axis=0)
    spec[np.fft.rfftfreq(n.shape[0], dt) <= 2.0] = 0.0
    fast = np.fft.irfft(spec, n=n.shape[0], axis=0)[:, :, 1]  # the normal's vertical part
    fast = fast[:, fast.std(axis=0) > 0]
    corr = np.corrcoef(fast.T)
    off = np.abs(corr[~np.eye(len(corr), dtype=bool)])
    assert np.median(off) < 0.2, np.median(off)


@pytest.mark.parametrize("name", ["tulip_poplar", "small_cherry"])
def test_no_leaf_snaps_through_in_a_gale_at_any_frame_rate(name):
    # Before (issue #12): in a 30 m/s gale the tulip poplar's leaves turned up to 180° in one
    # frame, p99.9 above 160° at 1/30 and at 1/120 s: they flipped from side to side every
    # frame, however short.
    slow = rotation_per_frame(name, 30.0, 1 / 30)
    fast = rotation_per_frame(name, 30.0, 1 / 120)
    p_slow, p_fast = np.percentile(slow, 99.9), np.percentile(fast, 99.9)
    assert p_slow < 70.0, p_slow
    assert fast.max() < 90.0, fast.max()  # never to the other side of the petiole
    # A bounded angular speed: four times the frames, about a quarter the turn per frame.
    assert p_fast < 0.4 * p_slow, (p_fast, p_slow)
