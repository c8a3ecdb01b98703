"""Aerodynamic loads beyond the paper (docs/design.md §12): quadratic drag on the air-relative wind.

The paper drives every object with a load linear in the wind (Eq. 19 × a gain). Here the load
is the drag of real air, ½ρ C A |U_rel| U_rel, with U_rel the wind relative to the moving object.
The simulation splits it as F(U) − c·v: :meth:`Drag.loads` gives the drag of the wind U itself,
and the damping c = ρ C A |U_rel| of the object's own motion v is taken implicitly by the
oscillators (:meth:`Simulation._aero_loads <treeanim.physics.simulation.Simulation>`).

* **branches** are cylinders across the flow: only the wind normal to the axis pushes
  (the cross-flow principle), F = ½ρ C_d D L |U_⊥| U_⊥;
* **leaves** take a normal force on the lamina, F = ½ρ C_n A |U| (U·n) n, with n the lamina's
  normal as the leaf is bent and twisted now, so a leaf turned edge-on to the wind sheds its
  load;
* **foliage reconfigures** (Vogel 1989): leaves and grass blades streamline as the wind rises,
  so above a reference speed U₀ their drag grows as U^(2 − r) instead of U²
  (Vogel's exponent b = −r, r ≈ 0.7 for broadleaves);
* grass blades are flexible strips across the flow, like branches, reconfiguring like leaves.

All loads come out in each object's carried frame (u, v, w), like the paper's L (Eq. 19).
"""

from __future__ import annotations

import numpy as np

from .rotation import Workspace, dot, qrot

__all__ = ["Drag"]


class Drag:
    """Drag constants of every object, and the drag of one step.

    Parameters
    ----------
    kind : (M,) str array
        'branch', 'leaf' or 'blade'.
    frontal_area : (M,) float
        Branches and blades: length × mean diameter (width); leaves: the lamina's area (m²).
    """

    def __init__(self, kind: np.ndarray, frontal_area: np.ndarray):
        self.leaf = np.flatnonzero(kind == "leaf")
        self.kind = kind
        self.area = np.asarray(frontal_area, float)
        self.ws = Workspace()
        self.leaf_speed = self.leaf_incidence = np.zeros(len(self.leaf))

    def derive(self, physics, present: np.ndarray) -> None:
        """Take ½ρ C A per object from ``physics`` (absent leaves carry no load).

        Parameters
        ----------
        physics : PhysicsParams
            ``air_density``, ``drag_branch``, ``drag_leaf``, ``drag_blade``,
            ``reconfiguration``, ``reconfiguration_speed``.
        present : (M,) bool
        """
        p = physics
        kind = self.kind
        cd = np.select([kind == "branch", kind == "leaf"], [p.drag_branch, p.drag_leaf], p.drag_blade)
        self.half_rho_cda = 0.5 * p.air_density * cd * self.area * present
        self.foliage = kind != "branch"
        self.blades = bool(np.any(kind == "blade"))
        self.c_cross = np.where(kind == "leaf", 0.0, self.half_rho_cda)
        self.c_leaf = np.where(kind == "leaf", self.half_rho_cda, 0.0)
        self.r = float(p.reconfiguration)
        self.u0 = float(p.reconfiguration_speed)

    def reconfigured(self, speed: np.ndarray, foliage: np.ndarray | None = None) -> np.ndarray:
        """Factor on ½ρ C A: (max(|U|, U₀)/U₀)^(−r) where ``foliage`` (None: everywhere), else 1
        (wood)."""
        f = np.maximum(speed, self.u0)
        f *= 1.0 / self.u0
        np.power(f, -self.r, out=f)
        if foliage is not None:
            f[~foliage] = 1.0
        return f

    def loads(self, wind: np.ndarray, frame: np.ndarray, tip_q: np.ndarray) -> np.ndarray:
        """Drag of the wind on every object, in its carried frame.

        Parameters
        ----------
        wind : (3, M) float
            The wind each object feels, world (m/s): U, or U minus the object's velocity.
        frame : (4, M) float
            The objects' carried frames (quaternions).
        tip_q : (4, M) float
            Each object's own bend and twist at its last segment (local quaternions): a leaf's
            at the petiole's tip, for its lamina normal.

        Returns
        -------
        (3, M) float
            (F_u, F_v, F_w) in newtons, in the carried frame.

        The leaves' wind speed and the cosine of its angle to each lamina's normal are kept
        as ``leaf_speed`` and ``leaf_incidence`` (L,) for their flutter. Every term is computed
        for all objects, with zero constants where it does not apply (whole arrays are cheaper
        than gathering the leaves and the rest apart).
        """
        M = wind.shape[1]
        ws = self.ws
        U = qrot(frame, wind, conj=True, out=ws.get("U", (3, M)), ws=ws)
        # cross-flow (branches, blades): only the wind normal to the axis v pushes
        un2 = U[0] * U[0]
        un2 += U[2] * U[2]
        k = np.sqrt(un2)
        if self.blades:  # blades reconfigure, wood does not
            k *= self.reconfigured(k, self.foliage)
        k *= self.c_cross
        F = np.empty((3, M))
        np.multiply(k, U[0], out=F[0])
        F[1] = 0.0
        np.multiply(k, U[2], out=F[2])
        if len(self.leaf):  # the normal force ½ρC A |U| (U·n) n on the lamina
            w, x, y, z = tip_q  # n = the leaf's bend and twist applied to its rest normal w
            n = ws.get("n", (3, M))
            np.multiply(x, z, out=n[0])
            n[0] += w * y
            np.multiply(y, z, out=n[1])
            n[1] -= w * x
            n[:2] *= 2.0
            np.multiply(x, x, out=n[2])
            n[2] += y * y
            n[2] *= -2.0
            n[2] += 1.0
            un2 += U[1] * U[1]
            speed = np.sqrt(un2)
            un = dot(U, n)
            self.leaf_speed = speed[self.leaf]
            self.leaf_incidence = un[self.leaf] / np.maximum(self.leaf_speed, 1e-300)
            un *= self.reconfigured(speed)
            un *= speed
            un *= self.c_leaf
            n *= un
            F += n
        return F
