"""Carrying each object's local bend up the hierarchy (Eq. 12, DESIGN §6).

An object's segment j has world rotation ``R_parent(attach node) · C_j`` (both relative to
rest) and its node j sits at the parent's deformed attach node plus the parent-rotated bent
offset Σ_{i<j} Cᵢ sᵢ (accumulated per object by the bending pass).

Within a step only the *structural* objects — those that carry children — are composed node
by node, level by level (each level one vectorised pass); every other object (leaves, outer
twigs, grass blades: the bulk of the nodes) needs only its parent's rotation and base, per
object. The full per-node pose is assembled on demand by :meth:`CompositionPlan.full_pose`.
"""

from __future__ import annotations

import numpy as np

from .rotation import Workspace, qmat, qmul, qrot


class CompositionPlan:
    """Index arrays for composing the hierarchy, precomputed once.

    World quaternions ``Qw`` (4, N + 1) and positions ``P`` (3, N) are kept for the structural
    nodes; column N of ``Qw`` is the identity, the "parent rotation" of roots.
    """

    def __init__(self, tree, bplan):
        N, M = tree.n_nodes, tree.n_objects
        start = np.asarray(tree.object_start)
        count = np.asarray(tree.object_count)
        parent = np.asarray(tree.parent)
        attach = np.asarray(tree.attach_node)
        node_obj = tree.node_object
        self.N, self.M = N, M
        self.node_obj = node_obj
        is_root = parent < 0
        # Per object: where its parent rotation and its base position come from.
        self.rot_src = np.where(is_root, N, attach)
        self.base_src = np.where(is_root, start, attach)  # a root's base never moves
        self.flat_of_node = bplan.flat_of_node
        self.ofs_of_node = bplan.ofs_of_node
        self.ws = Workspace()
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
            ))

    def compose_structural(self, q_flat: np.ndarray, o_flat: np.ndarray, Qw: np.ndarray, P: np.ndarray) -> None:
        """World rotations and positions of the structural nodes (level by level, Eq. 12).

        Parameters
        ----------
        q_flat : (4, S + 1) float
            Local cumulative rotations (quaternions), from the bending pass.
        o_flat : (3, S + 1) float
            Bent node offsets from each object's base, rest coordinates (column S zero).
        Qw : (4, N + 1) float
            World quaternions, written at the structural nodes.
        P : (3, N) float
            World positions, written at the structural nodes.
        """
        for nodes, flat, ofs, rot_src, base_src in self.levels:
            qp = np.take(Qw, rot_src, axis=1)
            Qw[:, nodes] = qmul(qp, np.take(q_flat, flat, axis=1))  # Eq. 12
            P[:, nodes] = np.take(P, base_src, axis=1) + qrot(qp, np.take(o_flat, ofs, axis=1))

    def parent_frames(self, Qw: np.ndarray, P: np.ndarray, out=None) -> tuple[np.ndarray, np.ndarray]:
        """Per object: the parent's world quaternion at the attach node and the base position.

        ``out``: optional ((4, M), (3, M)) arrays to fill.
        """
        qo, bo = out if out is not None else (None, None)
        return (np.take(Qw, self.rot_src, axis=1, out=qo), np.take(P, self.base_src, axis=1, out=bo))

    def full_pose(self, q_flat: np.ndarray, o_flat: np.ndarray, q_par: np.ndarray, base: np.ndarray,
                  want_positions: bool = True, want_rotations: bool = True):
        """World positions (N, 3) and rotations (N, 3, 3) of every node.

        Parameters
        ----------
        q_flat, o_flat : arrays
            The bending pass's local rotations and bent offsets.
        q_par : (4, M) float
            Each object's parent world quaternion at its attach node (identity for roots).
        base : (3, M) float
            Each object's deformed base position.
        want_positions, want_rotations : bool
            Which outputs to build (None for the other).
        """
        ws = self.ws
        N = self.N
        qpn = np.take(q_par, self.node_obj, axis=1, out=ws.get("qpn", (4, N)))
        positions = rotations = None
        if want_positions:
            on = np.take(o_flat, self.ofs_of_node, axis=1, out=ws.get("on", (3, N)))
            pos = qrot(qpn, on, out=ws.get("pos", (3, N)), ws=ws)
            pos += np.take(base, self.node_obj, axis=1, out=ws.get("bn", (3, N)))
            positions = np.ascontiguousarray(pos.T)
        if want_rotations:
            qn = np.take(q_flat, self.flat_of_node, axis=1, out=ws.get("qn", (4, N)))
            rotations = qmat(qmul(qpn, qn, out=ws.get("qw", (4, N)), ws=ws), ws=ws)
        return positions, rotations
