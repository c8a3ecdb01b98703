"""Ambient occlusion in a crown, from the density of its leaves: computed once, at the mesh's build.

The leaves' area is binned into a grid of cells over the crown (leaf area density, m²/m³).
From each cell's centre, rays in :data:`DIRECTIONS` directions (a Fibonacci sphere) march to
the grid's edge and sum the density they cross; the light a ray brings is Beer's law's
exp(−G·∫ρ ds), G = ½ (leaves facing every way), each ray weighted by what lies beyond it (the
sky above, the ground below, :data:`GROUND_WEIGHT` of it). A cell's occlusion is its weighted
mean, and a vertex takes the trilinear interpolation of its cells: the inside of a dense crown
is dark, a leaf in a gap between clumps is open, its bottom darker than its top.
"""

from __future__ import annotations

import numpy as np
from scipy.ndimage import map_coordinates

#: Cells along the crown's longest side.
CELLS = 20
#: Rays from each cell.
DIRECTIONS = 24
#: Extinction per unit of leaf area density and length (G of a spherical leaf angle distribution).
EXTINCTION = 0.5
#: Weight of light from below (the ground) against light from above (the sky).
GROUND_WEIGHT = 0.3


def _sphere(n: int) -> np.ndarray:
    """``n`` unit vectors spread evenly over the sphere (Fibonacci), fixed."""
    k = np.arange(n) + 0.5
    y = 1.0 - 2.0 * k / n
    r = np.sqrt(1.0 - y * y)
    a = np.pi * (3.0 - np.sqrt(5.0)) * k
    return np.column_stack([r * np.cos(a), y, r * np.sin(a)])


def crown_occlusion(points: np.ndarray, leaves: np.ndarray, area: np.ndarray) -> np.ndarray:
    """The share of sky and ground light the crown lets reach each point (1 = open).

    Parameters
    ----------
    points : (V, 3) float
        Where the light is wanted (vertices at rest), metres.
    leaves : (L, 3) float
        Where the leaves' area lies (samples of it), metres.
    area : (L,) float
        The area each sample stands for, m².

    Returns
    -------
    (V,) float in (0, 1]
    """
    points = np.asarray(points, float)
    if len(leaves) == 0 or len(points) == 0:
        return np.ones(len(points))
    lo, hi = leaves.min(axis=0), leaves.max(axis=0)
    cell = max(float((hi - lo).max()) / CELLS, 1e-3)
    lo = lo - cell
    shape = np.ceil((hi + cell - lo) / cell).astype(int) + 1
    idx = np.minimum(((leaves - lo) / cell).astype(int), shape - 1)
    density = np.zeros(shape)
    np.add.at(density, tuple(idx.T), area / cell**3)

    steps = int(np.ceil(np.linalg.norm(shape)))
    # Empty cells round the grid, as deep as the longest ray: a ray beyond the crown reads 0.
    padded = np.pad(density, steps + 1)
    strides = np.array(padded.strides) // padded.itemsize
    cells = np.stack(np.meshgrid(*[np.arange(n) + steps + 1 for n in shape], indexing="ij"), -1).reshape(-1, 3)
    base, flat = cells @ strides, padded.ravel()
    dirs = _sphere(DIRECTIONS)
    weight = np.where(dirs[:, 1] > 0.0, 1.0, GROUND_WEIGHT) * (0.5 + 0.5 * np.abs(dirs[:, 1]))
    light = np.zeros(len(cells))
    for d, w in zip(dirs, weight):
        # Whole cells along the ray from each cell's centre (half its own first).
        offsets = np.floor(0.5 + (np.arange(1, steps + 1)[:, None] - 0.5) * d).astype(int) @ strides
        depth = sum(flat[base + k] for k in offsets)
        light += w * np.exp(-EXTINCTION * cell * depth)
    grid = (light / weight.sum()).reshape(shape)
    # Cell centres sit at (i + ½) cells from lo: a point's coordinate in the grid's index space.
    return np.clip(map_coordinates(grid, ((points - lo) / cell - 0.5).T, order=1, mode="nearest"), 0.0, 1.0)
