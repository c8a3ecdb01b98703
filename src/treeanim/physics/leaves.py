"""Leaf petioles' twist over time (load path): flutter, and no snap-through.

A leaf's twist follows its torsional mode (the v oscillator's L′_v, Eq. 11's saturating law)
plus a **flutter**: the lamina sheds vortices and oscillates about its petiole at a frequency
that rises with the wind, f = St·|U|/ℓ (Strouhal-like, ℓ the lamina's length; about 5 Hz for a
10 cm leaf at 10 m/s), each leaf at its own frequency and phase. The flutter is strongest for
a lamina edge-on to the wind and weakest for one pressed flat against it, and grows with the
dynamic pressure.

The twist state turns toward that target at a bounded angular speed, so a leaf never flips
from one side of its petiole to the other within a frame, whatever the wind and the frame
time: the torque on a lamina changes sign as it passes edge-on, and Eq. 11's law, which has no
inertia, would otherwise swing it through up to 180° in one step.
"""

from __future__ import annotations

import numpy as np

__all__ = ["LeafTwist", "FLUTTER_STROUHAL", "MAX_FLUTTER_HZ", "MAX_TWIST_RATE", "FLUTTER_SPEED"]

#: f·ℓ/U of the flutter (leaves of 5–15 cm flutter at several Hz in a 10 m/s wind).
FLUTTER_STROUHAL = 0.05
#: The flutter's highest frequency (Hz); at most a quarter of the step rate as well, so that a
#: frame never aliases it into a slow wobble.
MAX_FLUTTER_HZ = 12.0
#: The wind speed (m/s) at which the flutter reaches half its amplitude (it grows as U²/(U² + U_f²)).
FLUTTER_SPEED = 4.0
#: The fastest a leaf turns about its petiole (rad/s): a lamina's inertia and the air's damping
#: bound its angular speed (a leaf fluttering ±15° at 7 Hz turns at about 12 rad/s).
MAX_TWIST_RATE = 12.0


class LeafTwist:
    """The twist state of every leaf's petiole segments.

    Parameters
    ----------
    seg_leaf : (S,) int
        For each leaf segment (in the order the caller keeps them), its leaf (0 … L−1).
    size : (L,) float
        Each leaf's lamina length (m).
    seed : int
        Seed of the leaves' flutter phases and frequency spread.
    """

    def __init__(self, seg_leaf: np.ndarray, size: np.ndarray, seed: int):
        self.seg_leaf = np.asarray(seg_leaf, np.int64)
        L = len(size)
        nseg = np.bincount(self.seg_leaf, minlength=L).astype(float)
        self.share = 1.0 / np.maximum(nseg[self.seg_leaf], 1.0)  # each segment's part of the leaf's twist
        rng = np.random.default_rng([int(seed), 0x1EAF])
        # single precision: its sine is many times cheaper, and a flutter needs no more
        self.phase0 = rng.uniform(0.0, 2.0 * np.pi, L).astype(np.float32)
        # Strouhal per unit length, spread ±25 % so no two leaves move in lockstep
        self.st = FLUTTER_STROUHAL * rng.uniform(0.75, 1.25, L) / np.maximum(np.asarray(size, float), 1e-3)
        self.reset()

    def reset(self) -> None:
        """Untwisted, every leaf at its first phase."""
        self.gamma = np.zeros(len(self.seg_leaf))
        self.phase = self.phase0.copy()
        self.steps = 0

    def step(self, target: np.ndarray, speed: np.ndarray, incidence: np.ndarray, amplitude: float,
             dt: float) -> np.ndarray:
        """Turn every leaf segment toward its target twist plus the flutter; return the twist.

        Parameters
        ----------
        target : (S,) float
            The twist of the load (Eq. 11), rad.
        speed : (L,) float
            The wind speed at each leaf (m/s).
        incidence : (L,) float
            cos of the angle between the wind and the lamina's normal (0: edge-on).
        amplitude : float
            The flutter's largest twist (rad, ``PhysicsParams.leaf_flutter``); 0: none.
        dt : float
            Step length (s).

        Returns
        -------
        (S,) float
            The segments' twist now (rad), a view of the state.
        """
        f = np.minimum(self.st * speed, min(MAX_FLUTTER_HZ, 0.25 / dt))  # (the gusts vary it)
        f *= 2.0 * np.pi * dt
        self.phase += f
        self.steps += 1
        if self.steps % 1024 == 0:
            self.phase %= 2.0 * np.pi
        u2 = speed * speed
        a = np.abs(incidence)
        a *= -0.7
        a += 1.0
        a *= u2
        a *= amplitude / (u2 + FLUTTER_SPEED**2)
        a *= np.sin(self.phase)
        goal = target + self.share * a[self.seg_leaf]
        goal -= self.gamma
        limit = (MAX_TWIST_RATE * dt) * self.share
        np.minimum(goal, limit, out=goal)  # (np.clip's own overhead is many times this)
        limit *= -1.0
        np.maximum(goal, limit, out=goal)
        self.gamma += goal
        return self.gamma
