"""Modal parameters of every object (Eqs. 20–22, docs/design.md §4).

Each object gets three modes (u, v, w) with a natural frequency f (Hz) and a damping ratio ζ:

* f′ⱼ = dⱼ / hⱼ² (mean diameter over length squared) mapped linearly onto the kind's
  [fmin, fmax] at the current season (Eq. 20), separately per kind;
* ζⱼ from rⱼ = (descendant sub-branches) + (descendant leaves)/6 mapped linearly onto
  [ζmin, ζmax] (Eq. 21);
* f_u = f, f_v = f(1 + 0.1·noise), f_w = f(1 + 0.1·noise), likewise ζ (Eq. 22), noise uniform
  in [−0.5, 0.5]; leaves scale ζ_w and ζ_v by the preset's ``leaf_zeta_w_scale`` and
  ``leaf_zeta_v_scale``.

A degenerate range (all f′ or all r of a kind equal, e.g. every leaf has r = 0) draws uniformly
in [min, max]. All random numbers are drawn once per seed (:class:`ModalDraws`), so changing the
season or the ranges re-maps the same draws smoothly.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..model.geometry import object_lengths
from ..model.params import PhysicsParams
from ..model.tree import KINDS, Tree

__all__ = ["ModalParameters", "ModalDraws", "object_lengths", "mean_diameters", "descendant_counts",
           "subtree_sums", "derive_modes"]


@dataclass
class ModalParameters:
    """Natural frequencies and damping ratios of every object's three modes.

    Attributes
    ----------
    f : (M, 3) float
        Natural frequencies in Hz, columns (u, v, w). Writable: the simulation reads the array
        at every step (and checks it: finite and > 0).
    zeta : (M, 3) float
        Damping ratios, columns (u, v, w). Writable (finite and >= 0).

    Notes
    -----
    Mode u is driven by the load along w and moves the object along w; mode w is driven by the
    load along u and moves it along u; mode v (driven by the lever-arm moment r·L_w) twists it
    about v (Eqs. 2–6).
    """

    f: np.ndarray
    zeta: np.ndarray


@dataclass(frozen=True)
class ModalDraws:
    """The random numbers of Eqs. 20–22, drawn once per seed.

    Attributes
    ----------
    f_uniform, zeta_uniform : (M,) float in [0, 1)
        Positions inside [fmin, fmax] / [ζmin, ζmax] used where a kind's range is degenerate.
    noise : (M, 4) float in [−0.5, 0.5)
        Eq. 22's noise() for f_v, f_w, ζ_v, ζ_w.
    """

    f_uniform: np.ndarray
    zeta_uniform: np.ndarray
    noise: np.ndarray

    @classmethod
    def draw(cls, n_objects: int, seed: int) -> "ModalDraws":
        """Draw the numbers for ``n_objects`` objects from ``seed`` (deterministic).

        Parameters
        ----------
        n_objects : int
            Number of objects M.
        seed : int
            Any non-negative integer; every bit counts (seeds 0 and 2**32 differ).

        Returns
        -------
        ModalDraws
        """
        # The whole seed, not its low 32 bits, plus the stream tag "modes".
        rng = np.random.default_rng([int(seed), 0x6D6F646573])
        return cls(
            f_uniform=rng.random(n_objects),
            zeta_uniform=rng.random(n_objects),
            noise=rng.random((n_objects, 4)) - 0.5,
        )


def mean_diameters(tree: Tree) -> np.ndarray:
    """Mean of each object's node diameters.

    Parameters
    ----------
    tree : Tree

    Returns
    -------
    numpy.ndarray, (M,) float
        Metres.
    """
    return np.add.reduceat(tree.node_diameter, tree.object_start) / tree.object_count


def subtree_sums(tree: Tree, values: np.ndarray) -> np.ndarray:
    """Each object's value plus that of everything growing on it (all generations).

    Parameters
    ----------
    tree : Tree
    values : (M, ...) float

    Returns
    -------
    numpy.ndarray, (M, ...) float
    """
    out = np.array(values, float)
    for sl in reversed(tree.level_slices()):  # children come after parents, levels sorted
        idx = np.arange(sl.start, sl.stop)
        idx = idx[tree.parent[idx] >= 0]
        np.add.at(out, tree.parent[idx], out[idx])
    return out


def descendant_counts(tree: Tree, present: np.ndarray | None = None) -> tuple[np.ndarray, np.ndarray]:
    """Descendant sub-branches and descendant leaves of every object (all generations).

    Parameters
    ----------
    tree : Tree
    present : (M,) bool, optional
        Count only these leaves (those still on the tree at a season); default all.

    Returns
    -------
    branches, leaves : (M,) int
        Number of objects of kind 'branch' (resp. 'leaf') below each object in the hierarchy.
    """
    is_b = (tree.kind == "branch").astype(np.int64)
    is_l = (tree.kind == "leaf").astype(np.int64)
    if present is not None:
        is_l *= np.asarray(present, bool)
    sums = subtree_sums(tree, np.stack([is_b, is_l], axis=1)).astype(np.int64)
    return sums[:, 0] - is_b, sums[:, 1] - is_l


def _map_linear(x: np.ndarray, lo: float, hi: float, uniform: np.ndarray) -> np.ndarray:
    """Map x linearly from [min x, max x] onto [lo, hi]; a degenerate x range uses ``uniform``."""
    xmin, xmax = float(np.min(x)), float(np.max(x))
    span = xmax - xmin
    if not np.isfinite(span) or span <= 1e-12 * max(abs(xmax), abs(xmin), 1e-300):
        return lo + uniform * (hi - lo)
    return lo + (x - xmin) * ((hi - lo) / span)


def derive_modes(tree: Tree, params: PhysicsParams, season: float, draws: ModalDraws,
                 present: np.ndarray | None = None) -> ModalParameters:
    """Modal parameters of every object at ``season`` (Eqs. 20–22).

    Parameters
    ----------
    tree : Tree
        The tree.
    params : PhysicsParams
        Ranges per kind (summer and winter) and the leaf ζ scales.
    season : float
        0 (summer) .. 1 (winter); interpolates the ranges.
    draws : ModalDraws
        The seeded random numbers.
    present : (M,) bool, optional
        Eq. 21 counts only these leaves (the ones still on the tree); default all, as the
        paper's model does.

    Returns
    -------
    ModalParameters
        New (M, 3) arrays.

    Raises
    ------
    ValueError
        If a kind present in the tree has no range in ``params``.
    """
    M = tree.n_objects
    fprime = mean_diameters(tree) / object_lengths(tree) ** 2  # Eq. 20
    nb, nl = descendant_counts(tree, present)
    r = nb + nl / 6.0  # Eq. 21
    f = np.empty(M)
    zeta = np.empty(M)
    for kind in KINDS:
        sel = np.flatnonzero(tree.kind == kind)
        if len(sel) == 0:
            continue
        rng_ = params.modes(kind, season)
        if rng_ is None:
            raise ValueError(f"physics: no f/zeta range for kind {kind!r}, which the tree has")
        f[sel] = _map_linear(fprime[sel], rng_.f[0], rng_.f[1], draws.f_uniform[sel])
        zeta[sel] = _map_linear(r[sel], rng_.zeta[0], rng_.zeta[1], draws.zeta_uniform[sel])
    n = draws.noise
    F = np.stack([f, f * (1 + 0.1 * n[:, 0]), f * (1 + 0.1 * n[:, 1])], axis=1)  # Eq. 22
    Z = np.stack([zeta, zeta * (1 + 0.1 * n[:, 2]), zeta * (1 + 0.1 * n[:, 3])], axis=1)
    leaf = tree.kind == "leaf"
    Z[leaf, 1] *= params.leaf_zeta_v_scale
    Z[leaf, 2] *= params.leaf_zeta_w_scale
    return ModalParameters(F, Z)
