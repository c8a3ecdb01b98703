"""Seamless loops of baked joint rotations, and the measure of a loop's seam.

A clip of ``n`` frames at ``fps`` lasts exactly T = n / fps and holds n + 1 keys, at 0, 1/fps,
…, T: a glTF client plays a clip from its first key to its last, and a looping one wraps the
time modulo that length, so the key at T and the key at 0 are shown at the same instant. A
looping clip therefore repeats its first key at T (the pose at T *is* the pose at 0) and every
step, the one across the loop point included, takes one frame interval.

The loop is closed by a cross-fade (:func:`close_loop`): the simulation runs ``fade`` frames
past T, and over the clip's first ``fade`` frames the motion turns from that continuation
(the simulation's frames T, T + 1/fps, …) into the clip's own start. The blend is a slerp
(linear in the quaternion log domain of the rotation from one motion to the other) with a
smoothstep weight: at both ends the weight and its rate are those of one motion alone, so the
pose and its rate of change run on unbroken into the fade and out of it. The key at T is the
simulation's frame T, so the clip's last step is one of the simulation's own.

Quaternions are glTF's (x, y, z, w), as :mod:`treeanim.export` writes them.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

__all__ = ["Seam", "close_loop", "seam"]


def _mul(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Hamilton products a b of (..., 4) quaternions (x, y, z, w)."""
    ax, ay, az, aw = np.moveaxis(a, -1, 0)
    bx, by, bz, bw = np.moveaxis(b, -1, 0)
    return np.stack([aw * bx + ax * bw + ay * bz - az * by,
                     aw * by - ax * bz + ay * bw + az * bx,
                     aw * bz + ax * by - ay * bx + az * bw,
                     aw * bw - ax * bx - ay * by - az * bz], axis=-1)


def _conj(q: np.ndarray) -> np.ndarray:
    return q * np.array([-1.0, -1.0, -1.0, 1.0])


def _log(q: np.ndarray) -> np.ndarray:
    """Rotation vectors (radians, the shorter way round) of unit quaternions (..., 4)."""
    q = np.where(q[..., 3:] < 0, -q, q)
    s = np.linalg.norm(q[..., :3], axis=-1, keepdims=True)
    angle = 2.0 * np.arctan2(s, q[..., 3:])
    return q[..., :3] * np.where(s > 1e-12, angle / np.maximum(s, 1e-300), 2.0)


def _exp(r: np.ndarray) -> np.ndarray:
    """Unit quaternions of rotation vectors (..., 3)."""
    angle = np.linalg.norm(r, axis=-1, keepdims=True)
    s = np.where(angle > 1e-12, np.sin(0.5 * angle) / np.maximum(angle, 1e-300), 0.5)
    return np.concatenate([r * s, np.cos(0.5 * angle)], axis=-1)


def angles(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Angles (degrees) of the rotations between unit quaternions ``a`` and ``b`` (..., 4)."""
    a, b = np.asarray(a, float), np.asarray(b, float)
    b = np.where(np.sum(a * b, axis=-1, keepdims=True) < 0, -b, b)  # q and -q: one rotation
    return np.degrees(4.0 * np.arctan2(np.linalg.norm(a - b, axis=-1), np.linalg.norm(a + b, axis=-1)))


def close_loop(raw: np.ndarray, n: int) -> np.ndarray:
    """Close a loop of ``n`` frames from ``raw`` (n + fade, J, 4) simulated keys, 1 <= fade < n.

    Frames ``fade`` … n − 1 are the simulation's; frame k < fade slerps from the simulation's
    frame n + k (the motion after T) to its frame k with the smoothstep weight w(k / fade),
    w(s) = s²(3 − 2s); the key at T repeats frame 0, which is the simulation's frame n.

    Returns
    -------
    (n + 1, J, 4) float32
        Unit quaternions (x, y, z, w), w >= 0; the last equals the first.

    Raises
    ------
    ValueError
        If ``raw`` does not hold n + fade frames with 1 <= fade < n.
    """
    raw = np.asarray(raw, float)
    fade = len(raw) - n
    if not 1 <= fade < n:
        raise ValueError(f"a loop of {n} frames needs {n + 1} to {2 * n - 1} simulated frames, got {len(raw)}")
    s = np.arange(fade) / fade
    w = (s * s * (3.0 - 2.0 * s))[:, None, None]
    after, start = raw[n:], raw[:fade]
    blend = _mul(after, _exp(w * _log(_mul(_conj(after), start))))
    out = np.concatenate([blend, raw[fade:n], blend[:1]])
    out /= np.linalg.norm(out, axis=-1, keepdims=True)
    out = np.where(out[..., 3:] < 0, -out, out)
    return out.astype(np.float32)


@dataclass(frozen=True)
class Seam:
    """How a looping clip's last key runs into its first, per joint (degrees).

    Attributes
    ----------
    step : (J,) float
        The clip's last step: from the last frame before T into the key at T, which a client
        shows at the same instant as the first key.
    largest : (J,) float
        Each joint's largest step between neighbouring keys everywhere else in the clip.
    jump : (J,) float
        The angle between the key at T and the first key: a jump the client shows in no time
        (0 for a closed loop).
    added : (J,) float
        The most the cross-fade adds to one frame's step: how much further the blended motion
        moves in a frame than either motion it blends (0 where not measured).
    """

    step: np.ndarray
    largest: np.ndarray
    jump: np.ndarray
    added: np.ndarray

    def ratio(self) -> np.ndarray:
        """(J,) the step into the first frame (and any jump) over the joint's largest step
        elsewhere (a joint that moves less than 0.001° a frame counts as moving that much)."""
        return (self.step + self.jump) / np.maximum(self.largest, 1e-3)

    def line(self) -> str:
        """One line for the command's report."""
        j = int(np.argmax(self.ratio()))
        a = int(np.argmax(self.added))
        return (f"loop seam: the last key is {self.jump.max():.2f}° off the first; the step into it is at most "
                f"{self.ratio()[j]:.2f}× a joint's largest step elsewhere (joint {j}: {self.step[j]:.2f}° against "
                f"{self.largest[j]:.2f}°); the cross-fade adds at most {self.added[a]:.2f}° to a frame's step "
                f"(joint {a})")


def seam(keys: np.ndarray, raw: np.ndarray | None = None) -> Seam:
    """The :class:`Seam` of a looping clip's keys (F, J, 4), F >= 3, as a client plays them.

    ``raw``, the simulated keys (F − 1 + fade, J, 4) the loop was closed from
    (:func:`close_loop`), measures what the cross-fade adds over the clip's first ``fade``
    frames; without it :attr:`Seam.added` is 0.
    """
    keys = np.asarray(keys, float)
    if len(keys) < 3:
        raise ValueError(f"a loop's seam needs at least 3 keys, got {len(keys)}")
    steps = angles(keys[:-1], keys[1:])
    added = np.zeros(keys.shape[1])
    if raw is not None:
        raw = np.asarray(raw, float)
        n = len(keys) - 1
        fade = len(raw) - n
        own = angles(raw[:fade], raw[1:fade + 1])  # the clip's own start, frames 0 … fade
        after = angles(raw[n:-1], raw[n + 1:])  # the motion after T, frames n … n + fade − 1
        after = np.concatenate([after, np.zeros((1,) + after.shape[1:])])[:fade]
        added = np.max(np.maximum(steps[:fade] - np.maximum(own, after), 0.0), axis=0)
    return Seam(step=steps[-1], largest=steps[:-1].max(axis=0), jump=angles(keys[-1], keys[0]), added=added)
