"""Joint poses as a glTF client composes them from rotation keys, and the mesh skinned on them:
what :mod:`treeanim.joints` and :mod:`treeanim.compact` measure their errors with.

Quaternions are glTF's (x, y, z, w); a skeleton is a :class:`treeanim.export.Skeleton`.
"""

from __future__ import annotations

import numpy as np

from .loop import _mul

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


def _rotate(q: np.ndarray, v: np.ndarray) -> np.ndarray:
    """Vectors v (..., 3) rotated by unit quaternions q (..., 4), (x, y, z, w)."""
    u, w = q[..., :3], q[..., 3:]
    c = 2.0 * np.cross(u, v)
    return v + w * c + np.cross(u, c)


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
    keys = np.asarray(keys, np.float64)
    F, J = keys.shape[:2]
    rest = _rest(tree, skel)
    parent = skel.joint_parent
    offset = rest - rest[np.maximum(parent, 0)]
    world = np.zeros((F, J, 4))
    world[..., 3] = 1.0
    pos = np.zeros((F, J, 3))
    for idx in _levels(parent)[1:]:  # one pass per depth, every joint of it and every frame at once
        p = parent[idx]
        world[:, idx] = _mul(world[:, p], keys[:, idx])
        pos[:, idx] = pos[:, p] + _rotate(world[:, p], offset[idx])
    world /= np.linalg.norm(world, axis=-1, keepdims=True)
    return world, pos


def _skinned(world, position, rest, pos, joints, weights) -> np.ndarray:
    """(V, 3) vertex positions of one frame: Σ w (R_j (x − rest_j) + p_j)."""
    out = np.zeros_like(pos)
    for slot in range(joints.shape[1]):
        w = weights[:, slot]
        if not np.any(w):
            continue
        j = joints[:, slot]
        out += w[:, None] * (_rotate(world[j], pos - rest[j]) + position[j])
    return out


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
    ra, rb = _rest(tree, sa), _rest(tree, sb)
    xa, xb = np.asarray(xa, np.float64), np.asarray(xb, np.float64)
    wta, wtb = wta / 255.0, wtb / 255.0
    sse, worst = 0.0, 0.0
    for f in range(len(wa)):  # a loop over frames; every vertex at once
        d = _skinned(wa[f], pa[f], ra, xa, ja, wta) - _skinned(wb[f], pb[f], rb, xb, jb, wtb)
        d2 = np.einsum("vi,vi->v", d, d)
        sse += float(d2.sum())
        worst = max(worst, float(d2.max()))
    return float(np.sqrt(sse / max(len(xa) * len(wa), 1))), float(np.sqrt(worst)), len(wa)
