"""Small vectorised rotation helpers in component-major layout.

Vectors are (3, K) arrays and unit quaternions (4, K) arrays with rows (w, x, y, z) — the
project's one quaternion convention (glTF's (x, y, z, w) is made from it in
:mod:`treeanim.export`); the last
axis runs over objects, segments or nodes, so every operation is a contiguous numpy loop over
K. Quaternions keep the per-segment work small (a product is 28 passes over K numbers, a 3×3
product 27 over 9K); they are turned into 3×3 matrices only for the output.

Every helper takes an optional ``out`` and a scratch :class:`Workspace`, so that the
simulation's step allocates no large temporaries (fresh large blocks cost a page fault per
4 KiB on first touch, which at tree sizes costs more than the arithmetic).
"""

from __future__ import annotations

import numpy as np


class Workspace:
    """Reusable scratch arrays, one per (name, shape)."""

    def __init__(self):
        self._arrays: dict = {}

    def get(self, name: str, shape: tuple[int, ...]) -> np.ndarray:
        """An uninitialised float64 array of ``shape`` reserved for ``name``.

        Parameters
        ----------
        name : str
            What the array is for (two uses that overlap in time need two names).
        shape : tuple of int
        """
        key = (name, shape)
        a = self._arrays.get(key)
        if a is None:
            a = self._arrays[key] = np.empty(shape)
        return a


_DEFAULT_WS = Workspace()

def cross(a: np.ndarray, b: np.ndarray, out: np.ndarray | None = None) -> np.ndarray:
    """Cross products of (3, K) column stacks (``out`` must not alias ``a`` or ``b``)."""
    out = np.empty(np.broadcast_shapes(a.shape, b.shape)) if out is None else out
    np.multiply(a[1], b[2], out=out[0])
    out[0] -= a[2] * b[1]
    np.multiply(a[2], b[0], out=out[1])
    out[1] -= a[0] * b[2]
    np.multiply(a[0], b[1], out=out[2])
    out[2] -= a[1] * b[0]
    return out


def dot(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Column-wise dot products of (3, K) stacks."""
    d = a[0] * b[0]
    d += a[1] * b[1]
    d += a[2] * b[2]
    return d


def qmul(a: np.ndarray, b: np.ndarray, out: np.ndarray | None = None,
         ws: Workspace | None = None) -> np.ndarray:
    """Hamilton products a ⊗ b of (4, K) quaternion stacks (rotation b first, then a).

    Parameters
    ----------
    a, b : (4, K) float
        Quaternions, rows (w, x, y, z).
    out : (4, K) float, optional
        Output; must not alias ``a`` or ``b``.
    ws : Workspace, optional
        Scratch arrays.

    Returns
    -------
    (4, K) float
    """
    K = b.shape[1]
    if out is None:
        out = np.empty((4, K))
    tmp = (ws or _DEFAULT_WS).get("qmul", (K,))
    a0, a1, a2, a3 = a
    b0, b1, b2, b3 = b
    w, x, y, z = out
    mul = np.multiply
    mul(a0, b0, out=w)
    w -= mul(a1, b1, out=tmp)
    w -= mul(a2, b2, out=tmp)
    w -= mul(a3, b3, out=tmp)
    mul(a0, b1, out=x)
    x += mul(a1, b0, out=tmp)
    x += mul(a2, b3, out=tmp)
    x -= mul(a3, b2, out=tmp)
    mul(a0, b2, out=y)
    y -= mul(a1, b3, out=tmp)
    y += mul(a2, b0, out=tmp)
    y += mul(a3, b1, out=tmp)
    mul(a0, b3, out=z)
    z += mul(a1, b2, out=tmp)
    z -= mul(a2, b1, out=tmp)
    z += mul(a3, b0, out=tmp)
    return out


def qrot(q: np.ndarray, v: np.ndarray, conj: bool = False, out: np.ndarray | None = None,
         ws: Workspace | None = None) -> np.ndarray:
    """Rotate (3, K) vectors by (4, K) unit quaternions (by their inverses if ``conj``).

    v′ = v + w·t + q⃗ × t with t = 2 q⃗ × v.

    Parameters
    ----------
    q : (4, K) float
        Unit quaternions, rows (w, x, y, z).
    v : (3, K) float
        Vectors.
    conj : bool
        Rotate by the inverse rotations.
    out : (3, K) float, optional
        Output; must not alias ``v``.
    ws : Workspace, optional
        Scratch arrays.

    Returns
    -------
    (3, K) float
    """
    K = v.shape[1]
    ws = ws or _DEFAULT_WS
    if out is None:
        out = np.empty((3, K))
    t = ws.get("qrot_t", (3, K))
    tmp = ws.get("qrot_tmp", (K,))
    w = q[0]
    qx, qy, qz = q[1], q[2], q[3]
    vx, vy, vz = v
    tx, ty, tz = t
    mul = np.multiply
    # t = 2 q⃗ × v;  v′ = v + w t + q⃗ × t.  For the inverse (w, −q⃗): v′ = v − w t + q⃗ × t.
    mul(qy, vz, out=tx)
    tx -= mul(qz, vy, out=tmp)
    mul(qz, vx, out=ty)
    ty -= mul(qx, vz, out=tmp)
    mul(qx, vy, out=tz)
    tz -= mul(qy, vx, out=tmp)
    t *= 2.0
    ox, oy, oz = out
    mul(w, t, out=out)
    if conj:
        np.negative(out, out=out)
    out += v
    ox += mul(qy, tz, out=tmp)
    ox -= mul(qz, ty, out=tmp)
    oy += mul(qz, tx, out=tmp)
    oy -= mul(qx, tz, out=tmp)
    oz += mul(qx, ty, out=tmp)
    oz -= mul(qy, tx, out=tmp)
    return out


def qmat(q: np.ndarray, out: np.ndarray | None = None, ws: Workspace | None = None) -> np.ndarray:
    """(K, 3, 3) rotation matrices of (4, K) unit quaternions.

    Parameters
    ----------
    q : (4, K) float
    out : (K, 3, 3) float, optional
    ws : Workspace, optional
    """
    K = q.shape[1]
    ws = ws or _DEFAULT_WS
    if out is None:
        out = np.empty((K, 3, 3))
    w, x, y, z = q
    p = ws.get("qmat_p", (9, K))  # 2xx 2yy 2zz 2xy 2xz 2yz 2wx 2wy 2wz
    xx, yy, zz, xy, xz, yz, wx, wy, wz = p
    mul = np.multiply
    mul(x, x, out=xx)
    mul(y, y, out=yy)
    mul(z, z, out=zz)
    mul(x, y, out=xy)
    mul(x, z, out=xz)
    mul(y, z, out=yz)
    mul(w, x, out=wx)
    mul(w, y, out=wy)
    mul(w, z, out=wz)
    p *= 2.0
    m9 = ws.get("qmat_m", (9, K))
    np.add(yy, zz, out=m9[0])
    np.subtract(1.0, m9[0], out=m9[0])
    np.subtract(xy, wz, out=m9[1])
    np.add(xz, wy, out=m9[2])
    np.add(xy, wz, out=m9[3])
    np.add(xx, zz, out=m9[4])
    np.subtract(1.0, m9[4], out=m9[4])
    np.subtract(yz, wx, out=m9[5])
    np.subtract(xz, wy, out=m9[6])
    np.add(yz, wx, out=m9[7])
    np.add(xx, yy, out=m9[8])
    np.subtract(1.0, m9[8], out=m9[8])
    out.reshape(K, 9)[...] = m9.T
    return out


def matrix_to_quat(R: np.ndarray) -> np.ndarray:
    """(4, K) unit quaternions (w, x, y, z), w >= 0, of (K, 3, 3) rotation matrices.

    Parameters
    ----------
    R : (K, 3, 3) float
        Proper rotations.

    Returns
    -------
    numpy.ndarray, (4, K) float
        C-contiguous, scalar part first.
    """
    from scipy.spatial.transform import Rotation

    xyzw = Rotation.from_matrix(np.asarray(R, float).reshape(-1, 3, 3)).as_quat(canonical=True)
    return np.ascontiguousarray(np.roll(xyzw, 1, axis=1).T)
