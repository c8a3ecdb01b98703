"""Joint poses as a glTF client composes them from rotation keys, and the mesh skinned on them:
what :mod:`treeanim.joints` and :mod:`treeanim.compact` measure their errors with.

Quaternions are glTF's (x, y, z, w); a skeleton is a :class:`treeanim.export.Skeleton`.
"""

from __future__ import annotations

import numpy as np

from .physics.compiled import njit

__all__ = ["displacement", "world_pose"]


def _levels(parent: np.ndarray) -> list[np.ndarray]:
    """Joints by depth (the root, depth 0, first); parents precede children in index order."""
    depth = np.zeros(len(parent), np.int64)
    todo = parent >= 0
    hop = np.where(todo, parent, 0)
    while np.any(todo):  # one pass per level, every joint at once
        depth[todo] += 1
        todo = todo & (hop > 0)
        hop = np.where(todo, np.where(parent[hop] >= 0, parent[hop], 0), 0)
    order = np.argsort(depth, kind="stable")
    return np.split(order, np.flatnonzero(np.diff(depth[order])) + 1)


@njit(cache=True, inline="always")
def _qmul(a, b):
    """The Hamilton product a b of quaternions (x, y, z, w) as a tuple."""
    return (a[3] * b[0] + a[0] * b[3] + a[1] * b[2] - a[2] * b[1],
            a[3] * b[1] - a[0] * b[2] + a[1] * b[3] + a[2] * b[0],
            a[3] * b[2] + a[0] * b[1] - a[1] * b[0] + a[2] * b[3],
            a[3] * b[3] - a[0] * b[0] - a[1] * b[1] - a[2] * b[2])


@njit(cache=True, inline="always")
def _qrot(q, x, y, z):
    """The vector (x, y, z) rotated by the unit quaternion q (x, y, z, w), as a tuple."""
    cx, cy, cz = 2.0 * (q[1] * z - q[2] * y), 2.0 * (q[2] * x - q[0] * z), 2.0 * (q[0] * y - q[1] * x)
    return (x + q[3] * cx + q[1] * cz - q[2] * cy,
            y + q[3] * cy + q[2] * cx - q[0] * cz,
            z + q[3] * cz + q[0] * cy - q[1] * cx)


@njit(cache=True)
def _compose(keys, parent, offset, order, world, pos):
    """world[f, j] = world[f, parent] keys[f, j]; pos[f, j] = pos[f, parent] + world[f, parent]
    offset[j]: the joints in ``order`` (parents before children), every frame."""
    for f in range(keys.shape[0]):
        for j in order:
            p = parent[j]
            world[f, j, 0], world[f, j, 1], world[f, j, 2], world[f, j, 3] = _qmul(world[f, p], keys[f, j])
            x, y, z = _qrot(world[f, p], offset[j, 0], offset[j, 1], offset[j, 2])
            pos[f, j, 0] = pos[f, p, 0] + x
            pos[f, j, 1] = pos[f, p, 1] + y
            pos[f, j, 2] = pos[f, p, 2] + z


def _rest(tree, skel) -> np.ndarray:
    """(J, 3) rest positions of the joints (the root joint at the origin)."""
    return np.concatenate([np.zeros((1, 3)), tree.rest_positions[skel.joint_node[1:]]])


def world_pose(tree, skel, keys: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """World rotations and positions of ``skel``'s joints as a client composes ``keys``.

    Parameters
    ----------
    tree : Tree
    skel : Skeleton
    keys : (F, J, 4) float
        Local rotations (x, y, z, w), as :func:`treeanim.export.bake` records them.

    Returns
    -------
    world : (F, J, 4) float64
        Unit quaternions of each joint's world rotation.
    position : (F, J, 3) float64
        Each joint's world position (m): its parent's, plus its constant rest offset turned
        by the parent's rotation.
    """
    keys = np.ascontiguousarray(keys, np.float64)
    F, J = keys.shape[:2]
    rest = _rest(tree, skel)
    parent = skel.joint_parent
    offset = rest - rest[np.maximum(parent, 0)]
    world = np.zeros((F, J, 4))
    world[..., 3] = 1.0
    pos = np.zeros((F, J, 3))
    _compose(keys, parent, offset, np.concatenate(_levels(parent)[1:]), world, pos)
    world /= np.linalg.norm(world, axis=-1, keepdims=True)
    return world, pos


@njit(cache=True, inline="always")
def _skin_vertex(world, position, rest, x, joints, weights, v):
    """Vertex v of one frame, skinned: Σ w (R_j (x − rest_j) + p_j), as a tuple."""
    ox = oy = oz = 0.0
    for slot in range(joints.shape[1]):
        w = weights[v, slot]
        if w == 0.0:
            continue
        j = joints[v, slot]
        rx, ry, rz = _qrot(world[j], x[v, 0] - rest[j, 0], x[v, 1] - rest[j, 1], x[v, 2] - rest[j, 2])
        ox += w * (rx + position[j, 0])
        oy += w * (ry + position[j, 1])
        oz += w * (rz + position[j, 2])
    return ox, oy, oz


@njit(cache=True)
def _distances(wa, pa, ra, xa, ja, wta, wb, pb, rb, xb, jb, wtb):
    """The sum and the largest of the squared distances between the mesh skinned two ways,
    over vertices and frames."""
    sse, worst = 0.0, 0.0
    for f in range(wa.shape[0]):
        for v in range(xa.shape[0]):
            ax, ay, az = _skin_vertex(wa[f], pa[f], ra, xa, ja, wta, v)
            bx, by, bz = _skin_vertex(wb[f], pb[f], rb, xb, jb, wtb, v)
            d2 = (ax - bx) ** 2 + (ay - by) ** 2 + (az - bz) ** 2
            sse += d2
            worst = max(worst, d2)
    return sse, worst


def displacement(tree, a, b) -> tuple[float, float, int]:
    """The distance between the mesh skinned two ways, frame by frame.

    Parameters
    ----------
    tree : Tree
    a, b : tuple
        Each (skel, (world, position), pos, joints, weights): a skeleton, its joints' poses at
        F frames (:func:`world_pose`), and the vertices at rest (V, 3), their joints (V, 4) and
        weights (V, 4, summing to 255) as :func:`treeanim.export.skin` gives them.

    Returns
    -------
    rms, worst : float
        Root mean square over vertices and frames, and the largest (m).
    frames : int
        F.
    """
    (sa, (wa, pa), xa, ja, wta), (sb, (wb, pb), xb, jb, wtb) = a, b
    c = np.ascontiguousarray
    args = [(c(w, np.float64), c(p, np.float64), _rest(tree, s), c(x, np.float64), c(j, np.int64), c(wt, np.float64) / 255.0)
            for s, w, p, x, j, wt in ((sa, wa, pa, xa, ja, wta), (sb, wb, pb, xb, jb, wtb))]
    sse, worst = _distances(*args[0], *args[1])  # every vertex at every frame, compiled
    return float(np.sqrt(sse / max(len(xa) * len(wa), 1))), float(np.sqrt(worst)), len(wa)
