"""What a :class:`~treeanim.physics.paper_sim.PaperSim` derives from its tree and physics
(docs/design.md §5–§8): rest geometry and the bending and composition plans, stiffness,
masses, and the modes (Eqs. 20–22; the drag constants for ``modes='physical'``).

:class:`Derived` is mixed into PaperSim; it computes once per tree what the step's stages
(:mod:`~treeanim.physics.stages`) read, and again when the physics, the season or the modal
model change.
"""

from __future__ import annotations

import numpy as np

from ..model.geometry import lamina_frames, object_lengths, polygon_centroid, segment_lengths
from .bending import BendingPlan, rest_frames
from .hierarchy import CompositionPlan
from .modal import derive_modes, mean_diameters
from .physical import physical_modes
from .rotation import Workspace, matrix_to_quat


class Derived:
    """Set-up of a PaperSim: everything computed from the tree, its physics and the season."""

    def _geometry(self) -> None:
        """Per-object rest frames, lever arms, areas and volumes (fixed for the tree)."""
        tree = self._tree
        X = np.asarray(tree.rest_positions, float)
        start = np.asarray(tree.object_start)
        count = np.asarray(tree.object_count)
        tip = start + count - 1
        M = self._M
        frames = rest_frames(tree)  # (M, 3, 3): columns u, v, w
        u = frames[:, :, 0]
        kind = tree.kind
        leaf = kind == "leaf"
        self._bplan = BendingPlan(tree, frames)
        self._cplan = CompositionPlan(tree, self._bplan, matrix_to_quat(frames))
        length = object_lengths(tree)
        dmean = mean_diameters(tree)
        p0pn = X[tip] - X[start]
        r = np.einsum("ij,ij->i", u, p0pn)  # Eq. 3: r = u · P0Pn
        lam_area = np.zeros(M)
        if tree.lamina is not None and np.any(leaf):
            leaves = np.flatnonzero(leaf)
            unit_area = float(tree.lamina.area)
            cx, cy = polygon_centroid(tree.lamina.outline)
            L = np.asarray(tree.lamina_length, float)[leaves, None]
            lam_area[leaves] = unit_area * L[:, 0] ** 2
            # The lamina sits on the petiole's tip, in the frame the mesh and picking use.
            tipn, lu, lv, _ = lamina_frames(tree, leaves)
            centroid = X[tipn] + L * (cx * lu + cy * lv)
            r[leaves] = np.linalg.norm(centroid - X[start[leaves]], axis=1)
        self._lever = r
        self._area = length * dmean + lam_area
        # Volumes: tapered segments (frusta ≈ cylinders of the mean diameter).
        seg = segment_lengths(tree)
        dseg = 0.5 * (tree.node_diameter[1:] + tree.node_diameter[:-1])
        dseg = np.append(dseg, 0.0)
        self._round_volume = np.add.reduceat(0.25 * np.pi * dseg**2 * seg, start)
        self._flat_area = np.add.reduceat(dseg * seg, start)  # blades: width × length
        self._lam_area = lam_area
        self._nseg = (count - 1).astype(float)
        self._sample_ofs = self._bplan.ofs_of_node[start + count // 2]  # the middle node: where the wind is sampled
        self._tip_node = tip
        self._rest_P = X.T.copy()
        # Base excitation: unique attach nodes of the non-root objects.
        self._nonroot = np.flatnonzero(tree.parent >= 0)
        att = np.asarray(tree.attach_node)[self._nonroot]
        self._att_nodes, att_inv = np.unique(att, return_inverse=True)
        # Per object, its base's column in the acceleration array (roots: the zero column).
        self._att_col = np.full(M, len(self._att_nodes), np.int64)
        self._att_col[self._nonroot] = att_inv
        self._ws = Workspace()
        o = self._bplan.order
        self._neg_half_pi_over_n_ord = -0.5 * np.pi / self._nseg[o]
        self._rest_bounds = (X.min(axis=0), X.max(axis=0))
        # Drag constants, for the modes of ``modes='physical'`` (:mod:`~treeanim.physics.physical`).
        self._frontal_area = np.where(leaf, lam_area, length * dmean)  # for the physical modes' air damping

    def _derive_physics(self) -> None:
        """Stiffness, gains, masses and twist constants from ``self._physics``."""
        p = self._physics
        kind = self._tree.kind
        gain = np.select([kind == "branch", kind == "leaf"], [p.wind_gain_branch, p.wind_gain_leaf],
                         p.wind_gain_blade)
        self._gain_area = gain * self._area
        mass = np.where(kind == "branch", p.wood_density * self._round_volume, 0.0)
        mass = np.where(kind == "leaf", p.leaf_density * (self._round_volume + self._lam_area * p.lamina_thickness),
                        mass)
        mass = np.where(kind == "blade", p.leaf_density * self._flat_area * p.lamina_thickness, mass)
        self._mass = mass
        self._k = self._bplan.stiffness(p.ei_max, p.stiffness_exponent)
        # Eq. 11's c0, per unit of the object's root stiffness k₀ (see the class notes).
        c0 = np.where(kind == "leaf", p.leaf_twist_c0, p.twist_c0)
        k_root = np.empty(self._M)
        k_root[self._bplan.order] = self._k[0]
        self._c0k = c0 / np.maximum(k_root, 1e-300)
        self._c0k_ord = self._c0k[self._bplan.order]

    def _derive_modes(self) -> None:
        """The modes f and ζ (Eqs. 20–22; Eq. 21 counts the fallen leaves too, as the paper does),
        or the physical ones (``modes='physical'``), into ``self._modes`` (in place when possible)."""
        m = derive_modes(self._tree, self._physics, self._season, self._draws)
        if self._modal == "physical":
            p, kind = self._physics, self._tree.kind
            cd = np.select([kind == "branch", kind == "leaf"], [p.drag_branch, p.drag_leaf], p.drag_blade)
            half_rho_cda = 0.5 * p.air_density * cd * self._frontal_area * self._present
            m = physical_modes(self._tree, p, m, self._mass * self._present, half_rho_cda)
        if hasattr(self, "_modes"):
            # Keep the user's references valid: overwrite in place when possible.
            cur = self._modes
            if isinstance(cur.f, np.ndarray) and cur.f.shape == m.f.shape and cur.f.flags.writeable:
                cur.f[...] = m.f
            else:
                cur.f = m.f
            if isinstance(cur.zeta, np.ndarray) and cur.zeta.shape == m.zeta.shape and cur.zeta.flags.writeable:
                cur.zeta[...] = m.zeta
            else:
                cur.zeta = m.zeta
        else:
            self._modes = m
        self._mode_snap = None  # force re-validation and new coefficients
