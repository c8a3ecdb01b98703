"""Fewer triangles: a lamina outlined by a few of its corners and no petiole, for the sun's
shadow map (always) and for the trees of a scene far from the camera; tubes of half the sides,
for a scene's far trees and shadow map; a scene's shadow casters by thickness, for a map to
leave out twigs far thinner than its texel; far grass one blade a clump (docs/design.md §17,
Drawing).

A far tree's leaves and bark hand over from the full mesh to the coarse one across a band of
distance, node by node: each pixel of a leaf or branch in the band is drawn by one of the two,
chosen by a 4 × 4 ordered dither against its node's place in the band (``LOD_FADE`` in
``shaders/tree.*``), so it is whole all the way and the switch does not pop.

Far grass hands over the same way, but by weight, not by pixels: a blade there is a soft line
under a pixel wide, whose pixels hold the share of them it covers. Across the grass's band a
clump's copies (:func:`clump_copies`) fade out, node by node, and its simulated blade widens to
:data:`CLUMP_WIDTH` times its width, so the clump's lines keep about their weight on screen;
beyond the band the copies are not drawn.
"""

from __future__ import annotations

import numpy as np

from ..model.lamina import ear_clip
from ..model.tree import BRANCH_SIDES, Tree
from .mesh import BLADE_CLUMP, MATERIAL_BARK, MATERIAL_BLADE, MATERIAL_LAMINA, TreeMesh

#: Corners of a lamina's outline kept for a far tree's leaves: six triangles, at a size where
#: the leaf's teeth and curve are below a pixel.
LOD_LAMINA_CORNERS = 8
#: Sides of the bark's tubes a far tree keeps one in (of ``BRANCH_SIDES``): eight, whose outline
#: is within 8 % of the round one's, so a twig drawn as a soft line keeps its weight.
LOD_TUBE_STEP = 2
#: A scene's shadow map leaves out bark thinner than this share of its texel (a twig a fifth of
#: a texel wide only speckles it), in classes of diameter split at these (metres).
THIN_CASTER_TEXELS = 0.25
CASTER_DIAMETERS = (0.04, 0.02, 0.01, 0.005)
#: A scene's tree draws its coarse leaves where a leaf is shorter than this on screen (px) ...
LOD_COARSE_PIXELS = 8.0
#: ... its full ones where longer than this, and both, dithered, between.
LOD_FULL_PIXELS = 12.0
#: Grass draws its clumps whole where a blade is wider than this on screen (px), one blade a
#: clump where narrower than this, and hands over between (:func:`blade_band`).
BLADE_FULL_PIXELS = 1.0
BLADE_COARSE_PIXELS = 0.5
#: ... where its simulated blade is drawn this many times as wide, for its clump's blades
#: together: the copies are shorter and overlap, and seen low the grass saturates (a meadow all
#: one blade a clump is nearest the full clumps' at 1.5 seen from 10° and 35° up, at 2 from 60°).
CLUMP_WIDTH = 1.5


def coarse_laminas(mesh: TreeMesh, tree: Tree, corners: int) -> np.ndarray:
    """Every lamina of the mesh outlined by ``corners`` of its outline's corners, evenly spaced
    (a lamina's vertices are its outline's, in order, leaf after leaf: mesh notes); the whole
    lamina where the coarse outline would cross itself.

    Returns
    -------
    (T, 3) uint32
        Indices into ``mesh.vertices``, leaf after leaf in mesh order.
    """
    lamina = np.flatnonzero(mesh.material == MATERIAL_LAMINA)
    if not len(lamina):
        return np.zeros((0, 3), np.uint32)
    outline = tree.lamina.outline
    K = len(outline)
    keep = np.unique(np.linspace(0, K, corners, endpoint=False).round().astype(int))
    try:
        tris = keep[ear_clip(outline[keep])]
    except ValueError:  # the coarse outline crosses itself: keep the full lamina
        tris = np.asarray(tree.lamina.triangles)
    return lamina.reshape(-1, K)[:, tris].reshape(-1, 3).astype(np.uint32)


def median_leaf(tree: Tree) -> float:
    """The median length of the tree's leaves (metres; 0 without leaves)."""
    lengths = np.asarray(tree.lamina_length)
    lengths = lengths[lengths > 0]
    return float(np.median(lengths)) if len(lengths) else 0.0


def median_blade(tree: Tree) -> float:
    """The median width of the tree's grass blades at their nodes (metres; 0 without blades)."""
    blade = np.asarray(tree.kind)[tree.node_object] == "blade"
    return float(np.median(np.asarray(tree.node_diameter)[blade])) if blade.any() else 0.0


def lod_band(size: float, pixels_per_metre: float, full: float = LOD_FULL_PIXELS,
             coarse: float = LOD_COARSE_PIXELS) -> tuple[float, float]:
    """(near, far) metres from the eye over which a scene's leaves hand over from full to
    coarse: where a leaf ``size`` metres long (:func:`median_leaf`) is ``full`` and ``coarse``
    pixels long on screen.

    Parameters
    ----------
    size : float
    pixels_per_metre : float
        A metre's size on screen at one metre from the eye.
    full, coarse : float

    Returns
    -------
    (float, float)
        Nothing is coarse (1e30 m) where ``size`` is 0 (no leaves).
    """
    if size <= 0.0:
        return 1e30, 2e30
    return size * pixels_per_metre / full, size * pixels_per_metre / coarse


def blade_band(width: float, pixels_per_metre: float) -> tuple[float, float]:
    """(near, far) metres from the eye over which the grass hands over from whole clumps to one
    blade a clump: where a blade ``width`` metres wide (:func:`median_blade`) is
    :data:`BLADE_FULL_PIXELS` and :data:`BLADE_COARSE_PIXELS` wide on screen (:func:`lod_band`)."""
    return lod_band(width, pixels_per_metre, BLADE_FULL_PIXELS, BLADE_COARSE_PIXELS)


def clump_copies(mesh: TreeMesh) -> np.ndarray:
    """(T,) bool over ``mesh.indices``: the triangles of the blade clumps' copies, the last
    ``BLADE_CLUMP - 1`` of each blade's :data:`~.mesh.BLADE_CLUMP` runs of triangles (the first
    is the simulated blade's: mesh notes)."""
    blade = mesh.material[mesh.indices[:, 0]] == MATERIAL_BLADE
    obj = np.repeat(np.arange(len(mesh.object_triangles)), mesh.object_triangles)
    return blade & (np.arange(len(blade)) - mesh.object_triangle_start[obj] >= mesh.object_triangles[obj] // BLADE_CLUMP)


def coarse_tubes(mesh: TreeMesh, step: int = LOD_TUBE_STEP) -> np.ndarray:
    """The bark's tubes with every ``step``-th side of their :data:`BRANCH_SIDES`: the same
    rings and fans, from the same vertices (a ring's are its sides in order, ``uv.x`` = side /
    sides; a base fan's apexes half a side on), each band and fan triangle of a kept side
    reaching ``step`` sides on (mesh notes: a band's triangles are (a, a+1, b+1) and
    (a, b+1, b), a base fan's (apex, a+1, a), a tip fan's (apex, a, a+1), a on a ring and b on
    the next).

    Returns
    -------
    (T / step, 3) uint32
        Indices into ``mesh.vertices``.
    """
    t = mesh.part_indices("BARK").astype(np.int64)
    u = mesh.vertices["uv"][:, 0].astype(np.float64) * BRANCH_SIDES
    side = np.floor(u + 0.25).astype(np.int64) % BRANCH_SIDES  # a fan apex: the side it leans from
    apex = np.abs(u - np.floor(u) - 0.5) < 0.25
    base = np.arange(len(u)) - side  # the first vertex of a vertex's ring

    def on(v, s):
        return base[v] + s % BRANCH_SIDES

    v0, v1, v2 = t.T
    band = ~apex[v0] & (base[v1] == base[v0]) & (side[v0] % step == 0)
    base_fan = apex[v0] & (side[v0] % step == 0)
    tip_fan = (~apex[v0] & (base[v1] == base[v2]) & (base[v0] != base[v1]) & (side[v1] % step == 0)
               & (side[v2] == (side[v1] + 1) % BRANCH_SIDES))
    a, b = v0[band], v2[band]  # a on a ring, b + 1 on the next
    s, n = side[a], side[a] + step
    tris = [np.stack([a, on(a, n), on(b, n)], -1), np.stack([a, on(b, n), on(b, s)], -1),
            np.stack([v0[base_fan], on(v2[base_fan], side[v0[base_fan]] + step), v2[base_fan]], -1),
            np.stack([v0[tip_fan], v1[tip_fan], on(v1[tip_fan], side[v1[tip_fan]] + step)], -1)]
    return np.concatenate(tris).astype(np.uint32)


def caster_classes(mesh: TreeMesh, tree: Tree, casters: np.ndarray) -> list[tuple[float, np.ndarray]]:
    """A scene's shadow casters by thickness, so the map can leave out those far thinner than
    its texel (:data:`THIN_CASTER_TEXELS`): they would only speckle it.

    Parameters
    ----------
    mesh : TreeMesh
    tree : Tree
    casters : (T, 3) int
        The shadow pass's triangles (:func:`~.shadow.shadow_indices`).

    Returns
    -------
    list of (float, (T_k, 3) int)
        Each class's thickest diameter (metres; inf for the first, which holds bark of at least
        the first of :data:`CASTER_DIAMETERS` and all but bark) and its triangles: bark by its
        node's diameter, between one of :data:`CASTER_DIAMETERS` and the one before.
    """
    first = casters[:, 0]
    d = np.where(mesh.material[first] == MATERIAL_BARK, np.asarray(tree.node_diameter)[mesh.node[first]], np.inf)
    bounds = (np.inf, *CASTER_DIAMETERS, 0.0)
    return [(hi, casters[(d >= lo) & (d < hi) | ((k == 0) & np.isinf(d))])
            for k, (hi, lo) in enumerate(zip(bounds[:-1], bounds[1:]))]
