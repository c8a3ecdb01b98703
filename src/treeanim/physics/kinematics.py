"""Placing the tree's bodies from their joints, and the ground they rest on (docs/design.md §12).

:func:`forward_kinematics` turns the joints' rotations and velocities into every body's world
pose and velocity, parents first. :func:`ground_contact` does the same and keeps every body's
end above the ground: the ground is a hard floor, met inelastically (an end pressed into it is
turned back up onto it, its joint turning no further than that, and its speed into the ground
taken away).
"""

from __future__ import annotations

import numpy as np

from .articulated import _cross, rot_exp
from .compiled import njit

__all__ = ["forward_kinematics", "ground_contact"]


@njit(cache=True, inline="always", fastmath=True, error_model="numpy")
def _place(b, parent, r0, Q, w, R, P, Om, V):
    """Body ``b``'s R, P, Om and V from its parent's (placed before it) and its joint."""
    p = parent[b]
    if p < 0:
        for i in range(3):
            for j in range(3):
                R[b, i, j] = Q[b, i, j]
            P[b, i] = r0[b, i]
            Om[b, i] = 0.0
            V[b, i] = 0.0
        for i in range(3):
            Om[b, i] = w[b, i]
        return
    for i in range(3):
        for j in range(3):
            s = 0.0
            for k in range(3):
                s += R[p, i, k] * Q[b, k, j]
            R[b, i, j] = s
    rx = R[p, 0, 0] * r0[b, 0] + R[p, 0, 1] * r0[b, 1] + R[p, 0, 2] * r0[b, 2]
    ry = R[p, 1, 0] * r0[b, 0] + R[p, 1, 1] * r0[b, 1] + R[p, 1, 2] * r0[b, 2]
    rz = R[p, 2, 0] * r0[b, 0] + R[p, 2, 1] * r0[b, 1] + R[p, 2, 2] * r0[b, 2]
    P[b, 0] = P[p, 0] + rx
    P[b, 1] = P[p, 1] + ry
    P[b, 2] = P[p, 2] + rz
    cx, cy, cz = _cross(Om[p, 0], Om[p, 1], Om[p, 2], rx, ry, rz)
    V[b, 0] = V[p, 0] + cx
    V[b, 1] = V[p, 1] + cy
    V[b, 2] = V[p, 2] + cz
    for i in range(3):
        Om[b, i] = Om[p, i] + R[p, i, 0] * w[b, 0] + R[p, i, 1] * w[b, 1] + R[p, i, 2] * w[b, 2]


@njit(cache=True, fastmath=True, error_model="numpy")
def forward_kinematics(parent, r0, Q, w, R, P, Om, V):
    """World rotations ``R``, joint positions ``P``, angular velocities ``Om`` and joint-point
    velocities ``V`` of every body from its joint's rotation ``Q`` and velocity ``w``.

    Parameters
    ----------
    parent : (B,) int64
        Parent body (−1: the ground).
    r0 : (B, 3)
        Rest offset of each joint from its parent's joint (a root's: its world position).
    Q : (B, 3, 3), w : (B, 3)
        Joint rotations and angular velocities, in the parent's rest axes.
    R, P, Om, V : (B, 3, 3), (B, 3), (B, 3), (B, 3)
        Written.
    """
    for b in range(parent.shape[0]):
        _place(b, parent, r0, Q, w, R, P, Om, V)


@njit(cache=True, fastmath=True, error_model="numpy")
def ground_contact(parent, r0, seg, floor, Q, w, R, P, Om, V) -> int:
    """:func:`forward_kinematics`, keeping each body's end at or above its ``floor``.

    A body whose end ``P + R·seg`` is below its floor is turned, about the horizontal axis
    across it, until the end is on the floor (its direction across the ground kept); the
    joint's rotation ``Q`` takes the turn, so the bodies beyond it follow. If the end then moves
    into the ground, that speed is taken away by the smallest change of the joint's angular
    velocity ``w`` (an inelastic contact). It only takes energy away.

    Parameters
    ----------
    parent, r0, Q, w, R, P, Om, V : see :func:`forward_kinematics`
        ``Q`` and ``w`` are changed where a body meets the ground.
    seg : (B, 3)
        Each body's rest segment, joint to end.
    floor : (B,) float
        The lowest height of each body's end (m).

    Returns
    -------
    int
        The number of bodies that met the ground.
    """
    C = np.empty((3, 3))
    Rn = np.empty((3, 3))
    met = 0
    for b in range(parent.shape[0]):
        _place(b, parent, r0, Q, w, R, P, Om, V)
        ex = R[b, 0, 0] * seg[b, 0] + R[b, 0, 1] * seg[b, 1] + R[b, 0, 2] * seg[b, 2]
        ey = R[b, 1, 0] * seg[b, 0] + R[b, 1, 1] * seg[b, 1] + R[b, 1, 2] * seg[b, 2]
        ez = R[b, 2, 0] * seg[b, 0] + R[b, 2, 1] * seg[b, 1] + R[b, 2, 2] * seg[b, 2]
        L = np.sqrt(ex * ex + ey * ey + ez * ez)
        if P[b, 1] + ey >= floor[b] or not L > 0.0:
            continue
        met += 1
        hor = np.sqrt(ex * ex + ez * ez)
        # the end's new direction: up to the floor, its heading across the ground kept
        dy = min(1.0, max(-1.0, (floor[b] - P[b, 1]) / L))
        if hor > 1e-12 * L:
            hx, hz = ex / hor, ez / hor
        else:
            hx, hz = 1.0, 0.0
        c = np.sqrt(1.0 - dy * dy)
        nx, ny, nz = c * hx, dy, c * hz
        ax, ay, az = _cross(ex / L, ey / L, ez / L, nx, ny, nz)
        s = np.sqrt(ax * ax + ay * ay + az * az)
        ang = np.arctan2(s, (ex * nx + ey * ny + ez * nz) / L)
        if s > 0.0:
            rot_exp(ax / s * ang, ay / s * ang, az / s * ang, C)
            p = parent[b]
            # R_b ← C·R_b, and Q_b = R_pᵀ·R_b (R_p = 1 for a root)
            for i in range(3):
                for j in range(3):
                    Rn[i, j] = C[i, 0] * R[b, 0, j] + C[i, 1] * R[b, 1, j] + C[i, 2] * R[b, 2, j]
            for i in range(3):
                for j in range(3):
                    if p < 0:
                        Q[b, i, j] = Rn[i, j]
                    else:
                        Q[b, i, j] = R[p, 0, i] * Rn[0, j] + R[p, 1, i] * Rn[1, j] + R[p, 2, i] * Rn[2, j]
        # the end's speed into the ground, taken away by the least change δ of the body's
        # angular velocity ((δ × r)·ŷ = −v_y); δ is in world axes, w in the parent's rest axes
        rx, ry, rz = L * nx, L * ny, L * nz
        cx, cy, cz = _cross(Om[b, 0], Om[b, 1], Om[b, 2], rx, ry, rz)
        vy = V[b, 1] + cy
        # (a steep body cannot stop its end by turning: it takes at most |v_y|/L·2 of turn)
        k2 = max(rx * rx + rz * rz, 0.25 * L * L)
        if vy < 0.0:
            dx, dz = vy / k2 * rz, -vy / k2 * rx  # δ = −v_y (r × ŷ)/|r × ŷ|², r × ŷ = (−r_z, 0, r_x)
            p = parent[b]
            if p < 0:
                w[b, 0] += dx
                w[b, 2] += dz
            else:
                for i in range(3):
                    w[b, i] += R[p, 0, i] * dx + R[p, 2, i] * dz
        _place(b, parent, r0, Q, w, R, P, Om, V)
    return met
