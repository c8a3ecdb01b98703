"""Joint budgets: merge a baked skeleton into at most N joints where it costs least motion.

The full skeleton (:func:`treeanim.export.skeleton`) has one joint per segment: 2,522 on a
small cherry, 17,048 on a large one, more than engines take in one skin. :func:`reduce` merges
joints into their parents until at most N are left; a merged joint's nodes (and every vertex
on them) then ride the joint they merged into rigidly, and the joints below it hang from that
joint with a constant offset, so the file still holds rotations only.

Which joints merge is chosen from the baked full-resolution motion (the full keys are baked
once anyway): merging joint j into its kept parent k moves each vertex x of j's subtree by
at most |R x − x| = 2 sin(θ/2) |x − pivot|, θ the angle of j's rotation relative to k, so
the squared displacement it adds over the clip is at most

    cost(j) = 4 mean_t(1 − (q_k(t) · q_j(t))²) · Σ_{x in subtree(j)} |x − pivot_j|²

(q the joints' world quaternions: the scalar part of q_k⁻¹ q_j is their dot product). The
cheapest merge is made first and the costs of the merged joint's children, which now hang
from k, are measured again (a heap with lazy updates). This is greedy least squares: it
minimises the RMS displacement added merge by merge. It is measured rather than assumed from
the structure (a rule such as "petioles first" guesses the motion): on a small cherry in wind
8, a budget of 256 keeps about 200 leaf joints, the leaves that flutter most, and merges the
branch segments that turn with their neighbours, while the quiet leaves ride their twigs.

:func:`motion_error` measures the result against the full motion: every vertex of the mesh,
skinned as the file skins it, at every frame, in metres.
"""

from __future__ import annotations

import heapq

import numpy as np

from .export import Skeleton
from .loop import _conj, _mul
from .pose import _levels, _rest, displacement, world_pose

__all__ = ["fit", "full_index", "motion_error", "rekey", "reduce", "report", "world_pose"]


def _subtree_spread(skel: Skeleton, rest: np.ndarray, pos: np.ndarray, joint: np.ndarray) -> np.ndarray:
    """(J,) Σ |x − pivot_j|² over the vertices ``pos`` (V, 3) riding j's subtree (``joint``:
    each vertex's joint)."""
    J = skel.count
    n = np.bincount(joint, minlength=J).astype(float)
    s = np.stack([np.bincount(joint, pos[:, i], minlength=J) for i in range(3)], axis=1)
    q = np.bincount(joint, np.einsum("vi,vi->v", pos, pos), minlength=J)
    for idx in reversed(_levels(skel.joint_parent)[1:]):  # children into parents, deepest first
        p = skel.joint_parent[idx]
        np.add.at(n, p, n[idx])
        np.add.at(s, p, s[idx])
        np.add.at(q, p, q[idx])
    return np.maximum(q - 2.0 * np.einsum("ji,ji->j", rest, s) + n * np.einsum("ji,ji->j", rest, rest), 0.0)


def reduce(tree, skel: Skeleton, world: np.ndarray, pos: np.ndarray, joint: np.ndarray, budget: int) -> Skeleton:
    """``skel`` merged into at most ``budget`` joints where it costs least motion.

    Parameters
    ----------
    tree : Tree
    skel : Skeleton
        The full skeleton.
    world : (F, J, 4) float
        Its joints' world rotations over the clip (:func:`world_pose`).
    pos, joint : (V, 3) float, (V,) int
        The mesh's vertices at rest and the joint each rides (the first of
        :func:`treeanim.export.skin`): they weigh each merge by the displacement it causes.
    budget : int
        The most joints to keep, the root included (>= 2).

    Returns
    -------
    Skeleton
        The kept joints, in the full skeleton's order; ``node_joint`` maps each node to the
        kept joint it rides. With ``budget`` >= ``skel.count``, ``skel`` itself.
    """
    J = skel.count
    if budget >= J:
        return skel
    if budget < 2:
        raise ValueError(f"a joint budget of {budget}: at least 2")
    rest = _rest(tree, skel)
    spread = 4.0 * _subtree_spread(skel, rest, np.asarray(pos, float), np.asarray(joint, np.int64))
    parent = skel.joint_parent.copy()  # each kept joint's kept parent
    world = np.asarray(world, np.float64)

    def cost(j: int, k: int) -> float:
        c = np.einsum("fi,fi->f", world[:, k], world[:, j])
        return float(np.mean(1.0 - c * c) * spread[j])

    first = 1.0 - np.einsum("fji,fji->fj", world[:, parent[1:]], world[:, 1:]) ** 2
    costs = np.mean(first, axis=0) * spread[1:]
    heap = list(zip(costs.tolist(), range(1, J)))
    heapq.heapify(heap)
    kids: list[list[int]] = [[] for _ in range(J)]
    for j, p in enumerate(parent[1:].tolist(), start=1):
        kids[p].append(j)
    merged = np.zeros(J, bool)
    current = np.concatenate([[np.inf], costs])
    left = J
    while left > budget:  # one merge per pass: the loop runs over merges, never over frames
        c, j = heapq.heappop(heap)
        if merged[j] or c != current[j]:
            continue  # a stale entry: j merged, or its parent changed since
        k = int(parent[j])
        merged[j] = True
        left -= 1
        for ch in kids[j]:
            if merged[ch]:
                continue
            parent[ch] = k
            current[ch] = cost(ch, k)
            heapq.heappush(heap, (current[ch], ch))
            kids[k].append(ch)
    owner = np.where(merged, parent, np.arange(J))
    while True:  # each merged joint's kept ancestor, by pointer jumping
        nxt = owner[owner]
        if np.array_equal(nxt, owner):
            break
        owner = nxt
    keep = ~merged
    index = np.cumsum(keep) - 1
    node_joint = np.where(skel.node_joint >= 0, index[owner[np.maximum(skel.node_joint, 0)]], -1)
    kept_parent = parent[keep]
    return Skeleton(joint_node=skel.joint_node[keep],
                    joint_parent=np.where(kept_parent >= 0, index[owner[np.maximum(kept_parent, 0)]], -1),
                    node_joint=node_joint)


def full_index(full: Skeleton, reduced: Skeleton) -> np.ndarray:
    """(Jr,) each kept joint's index in the full skeleton."""
    return np.concatenate([[0], full.node_joint[reduced.joint_node[1:]]])


def rekey(full: Skeleton, reduced: Skeleton, world: np.ndarray) -> np.ndarray:
    """(F, Jr, 4) float32 local rotations of ``reduced``'s joints from the full skeleton's
    world rotations (F, J, 4): a kept joint turns as in the full motion, relative to its kept
    parent."""
    idx = full_index(full, reduced)
    w = np.asarray(world, np.float64)[:, idx]
    local = _mul(_conj(w[:, np.maximum(reduced.joint_parent, 0)]), w)
    local[:, 0] = [0.0, 0.0, 0.0, 1.0]
    local /= np.linalg.norm(local, axis=-1, keepdims=True)
    return np.where(local[..., 3:] < 0, -local, local).astype(np.float32)


def motion_error(tree, full: Skeleton, reduced: Skeleton, full_keys: np.ndarray, mesh, present=None,
                 world: tuple[np.ndarray, np.ndarray] | None = None, frames: int = 31) -> tuple[float, float, int]:
    """The displacement of the mesh skinned on ``reduced`` from the full motion, as a client
    skins the two files: every vertex, at ``frames`` frames of ``full_keys`` (F, J, 4) evenly
    spread over the clip, its first and last included (all F if fewer).

    Parameters
    ----------
    world : (world, position), optional
        :func:`world_pose` of ``full`` and ``full_keys``, if already at hand.

    Returns
    -------
    rms, worst : float
        Root mean square over vertices and frames, and the largest (m).
    measured : int
        The number of frames measured.
    """
    from .export import skin

    wf, pf = world if world is not None else world_pose(tree, full, full_keys)
    pick = np.unique(np.round(np.linspace(0, len(wf) - 1, min(len(wf), max(frames, 2)))).astype(np.int64))
    wf, pf = wf[pick], pf[pick]
    _, _, pos, jf, ww = skin(tree, mesh, full, present)
    _, _, _, jr, wr8 = skin(tree, mesh, reduced, present)
    return displacement(tree, (full, (wf, pf), pos, jf, ww), (reduced, world_pose(tree, reduced, rekey(full, reduced, wf)),
                                                             pos, jr, wr8))


def fit(tree, full: Skeleton, raw: np.ndarray, n: int, budget: int | None, present=None, mesh=None):
    """Fit baked keys to a joint budget: what ``export --joints`` does.

    Parameters
    ----------
    tree : Tree
    full : Skeleton
        The full skeleton ``raw`` (F, J, 4) was baked for.
    n : int
        The clip's frames: the error is measured over keys 0 … n (a loop's simulated frames
        past T only choose the merges).
    budget : int or None
        The most joints; None keeps them all.
    present : (M,) bool, optional
        Objects on the tree.
    mesh : TreeMesh, optional
        The mesh the file skins, whose vertices the merges and the error weigh (the tree's,
        :func:`~treeanim.render.mesh.build_mesh`, by default).

    Returns
    -------
    skel, keys, error
        The reduced skeleton and its keys (F, Jr, 4); :func:`motion_error` (None if nothing
        was merged).
    """
    if budget is None or budget >= full.count:
        return full, raw, None
    from .export import skin
    from .render.mesh import build_mesh

    mesh = mesh if mesh is not None else build_mesh(tree)
    world, position = world_pose(tree, full, raw)
    _, _, pos, joint, _ = skin(tree, mesh, full, present)
    skel = reduce(tree, full, world, pos, joint[:, 0], budget)
    error = motion_error(tree, full, skel, raw[:n + 1], mesh, present, world=(world[:n + 1], position[:n + 1]))
    return skel, rekey(full, skel, world), error


def report(full: Skeleton, skel: Skeleton, budget: int | None, error) -> str:
    """The command's line on the joints kept and the motion lost."""
    if error is None:
        return f"joints: all {full.count:,} (the full motion)" + (f"; within the budget of {budget:,}" if budget else "")
    return (f"joints: {skel.count:,} of {full.count:,} (budget {budget:,}); against the full motion: RMS "
            f"{error[0] * 100:.2f} cm, worst {error[1] * 100:.2f} cm of vertex displacement "
            f"({error[2]} frames measured)")
