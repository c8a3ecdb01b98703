"""Carrying each object's local bend up the hierarchy (Eq. 12, docs/design.md §6).

Every object bends in its local rest frame (u, v, w), whose orientation at rest is the
quaternion q₀. Carried by its parent, that frame has the world orientation
``f = R_parent(attach node) ⊗ q₀`` (Eq. 12); segment j of the object then has the world
rotation relative to rest ``R_j = f ⊗ C_j ⊗ q₀*`` and node j sits at the parent's deformed
attach node plus ``f`` applied to the local bent offset Σ_{i<j} Cᵢ sᵢ.

Within a step only the *structural* objects — those that carry children — are composed node
by node, level by level (each level one vectorised pass); every other object (leaves, outer
twigs, grass blades: the bulk of the nodes) needs only its frame f and base, per object. The
full per-node pose is assembled on demand by :meth:`CompositionPlan.positions` and
:meth:`CompositionPlan.rotations`.
"""

from __future__ import annotations

import numpy as np

from .rotation import Workspace, qmat, qmul, qrot


def qconj(q: np.ndarray) -> np.ndarray:
    """Conjugate (inverse) of (4, K) unit quaternions.

    Parameters
    ----------
    q : (4, K) float
    """
    c = q.copy()
    c[1:] *= -1.0
    return c


class CompositionPlan:
    """Index arrays for composing the hierarchy, precomputed once.

    Parameters
    ----------
    tree : Tree
    bplan : BendingPlan
    q0 : (4, M) float
        Rest frame quaternion of every object.

    Notes
    -----
    ``Fw`` (4, N + 1) holds, at the structural nodes, the world orientation ``f ⊗ C_j`` of the
    bent segment's frame; column N is the identity. A child's frame is
    ``Fw[attach] ⊗ q_rel`` with the constant ``q_rel = q₀(parent)* ⊗ q₀(child)`` (roots:
    ``q_rel = q₀``), since R(attach) = Fw[attach] ⊗ q₀(parent)*.
    """

    def __init__(self, tree, bplan, q0: np.ndarray):
        N, M = tree.n_nodes, tree.n_objects
        start = np.asarray(tree.object_start)
        count = np.asarray(tree.object_count)
        parent = np.asarray(tree.parent)
        attach = np.asarray(tree.attach_node)
        node_obj = tree.node_object
        self.N, self.M = N, M
        self.node_obj = node_obj
        self.ws = Workspace()
        is_root = parent < 0
        self.q0 = np.ascontiguousarray(q0)
        self.q0_conj = qconj(self.q0)
        self.q0c_node = np.ascontiguousarray(self.q0_conj[:, node_obj])
        self.q_rel = self.q0.copy()
        nr = np.flatnonzero(~is_root)
        if len(nr):
            self.q_rel[:, nr] = qmul(self.q0_conj[:, parent[nr]], self.q0[:, nr])
        # Per object: where its parent frame and its base position come from.
        self.rot_src = np.where(is_root, N, attach)
        self.base_src = np.where(is_root, start, attach)  # a root's base never moves
        self.flat_of_node = bplan.flat_of_node
        self.ofs_of_node = bplan.ofs_of_node
        structural = np.zeros(M, bool)
        structural[parent[parent >= 0]] = True
        self.structural = structural
        self.levels = []
        for sl in tree.level_slices():
            objs = np.arange(sl.start, sl.stop)
            objs = objs[structural[objs]]
            if len(objs) == 0:
                continue
            nodes = np.concatenate([np.arange(start[o], start[o] + count[o]) for o in objs])
            self.levels.append((
                nodes,
                self.flat_of_node[nodes],
                self.ofs_of_node[nodes],
                self.rot_src[node_obj[nodes]],
                self.base_src[node_obj[nodes]],
                self.q_rel[:, node_obj[nodes]].copy(),
            ))

    def compose_structural(self, q_flat: np.ndarray, o_flat: np.ndarray, Fw: np.ndarray, P: np.ndarray) -> None:
        """Segment frames and positions of the structural nodes (level by level, Eq. 12).

        Parameters
        ----------
        q_flat : (4, S + 1) float
            Local cumulative rotations (quaternions), from the bending pass.
        o_flat : (3, S + 1) float
            Local bent offsets of the nodes from their object's base (column S zero).
        Fw : (4, N + 1) float
            World segment frames, written at the structural nodes.
        P : (3, N) float
            World positions, written at the structural nodes.
        """
        for nodes, flat, ofs, rot_src, base_src, q_rel in self.levels:
            f = qmul(np.take(Fw, rot_src, axis=1), q_rel)  # the objects' frames, per node
            Fw[:, nodes] = qmul(f, np.take(q_flat, flat, axis=1))
            P[:, nodes] = np.take(P, base_src, axis=1) + qrot(f, np.take(o_flat, ofs, axis=1))

    def object_frames(self, Fw: np.ndarray, P: np.ndarray, out=None) -> tuple[np.ndarray, np.ndarray]:
        """Per object: its carried frame f (4, M) and its deformed base position (3, M).

        ``out``: optional ((4, M), (3, M)) arrays to fill.
        """
        qo, bo = out if out is not None else (None, None)
        ws = self.ws
        fp = np.take(Fw, self.rot_src, axis=1, out=ws.get("fp", (4, self.M)))
        f = qmul(fp, self.q_rel, out=qo, ws=ws)
        return f, np.take(P, self.base_src, axis=1, out=bo)

    def node_frames(self, f: np.ndarray) -> np.ndarray:
        """(4, N) each node's object frame f (a view of a scratch array, valid until the next call)."""
        return np.take(f, self.node_obj, axis=1, out=self.ws.get("fn", (4, self.N)))

    def positions(self, o_flat: np.ndarray, fn: np.ndarray, base: np.ndarray, out: np.ndarray | None = None) -> np.ndarray:
        """(N, 3) world positions: base + f ⊗ (bent local offset).

        Parameters
        ----------
        o_flat : (3, S + 1) float
            The bending pass's bent offsets.
        fn : (4, N) float
            From :meth:`node_frames`.
        base : (3, M) float
            Each object's deformed base position.
        out : (N, 3) float, optional
        """
        ws = self.ws
        N = self.N
        on = np.take(o_flat, self.ofs_of_node, axis=1, out=ws.get("on", (3, N)))
        pos = qrot(fn, on, out=ws.get("pos", (3, N)), ws=ws)
        pos += np.take(base, self.node_obj, axis=1, out=ws.get("bn", (3, N)))
        if out is None:
            out = np.empty((N, 3))
        out[...] = pos.T
        return out

    def rotations(self, q_flat: np.ndarray, fn: np.ndarray, out: np.ndarray | None = None) -> np.ndarray:
        """(N, 3, 3) world rotations relative to rest: f ⊗ C ⊗ q₀* per node.

        Parameters
        ----------
        q_flat : (4, S + 1) float
            The bending pass's local rotations.
        fn : (4, N) float
            From :meth:`node_frames`.
        out : (N, 3, 3) float, optional
        """
        ws = self.ws
        N = self.N
        qn = np.take(q_flat, self.flat_of_node, axis=1, out=ws.get("qn", (4, N)))
        g = qmul(fn, qn, out=ws.get("g", (4, N)), ws=ws)
        return qmat(qmul(g, self.q0c_node, out=ws.get("r", (4, N)), ws=ws), out=out, ws=ws)
