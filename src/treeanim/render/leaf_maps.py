"""A species' leaf maps, made from its lamina outline: albedo, relief and translucency.

One RGBA8 image over the outline's box (x across the blade from −``half_width`` to
+``half_width``, y along the midrib from 0 to ``length``, leaf units: the lamina's uv in
:mod:`treeanim.render.mesh`), drawn by ``shaders/tree.frag`` on every lamina:

- R, albedo: a factor on the leaf's colour, stored ÷ :data:`ALBEDO_SCALE` (veins paler than
  the blade, the blade a little darker towards its base, faint mottling);
- G, translucency: the share of the sun the lamina lets through (veins, thicker, less);
- B, A, relief: the normal's x and y in the blade's (u, v) frame, 0.5 + 0.5 n (veins sunk
  into the upper face: the lower face, seen from its side, has them raised).

Veins: a midrib tapering to the tip; pinnate side veins (alternate, leaving it at about 55°
and arching towards the tip), fading before the margin; a vein along the margin; and a net of
fine veins round small areoles (cellular noise). Made with numpy at first use, the same
image every time (a fixed seed), and kept per outline (:func:`leaf_maps`).
"""

from __future__ import annotations

import moderngl
import numpy as np

from ..model.tree import Lamina

#: Texels a side.
SIZE = 256
#: The albedo factor is stored divided by this (veins are paler than 1).
ALBEDO_SCALE = 1.5
#: Pairs of side veins on a midrib of length 1.
SIDE_VEINS = 9.0

_cache: dict[tuple, np.ndarray] = {}


def lamina_box(lamina: Lamina) -> tuple[float, float]:
    """(half width, length) of the lamina's outline: the box its maps cover, in leaf units."""
    outline = np.asarray(lamina.outline, float)
    return float(np.abs(outline[:, 0]).max()), float(outline[:, 1].max())


def _inside_distance(outline: np.ndarray, x: np.ndarray, y: np.ndarray) -> np.ndarray:
    """Signed distance from points to the outline's margin (> 0 inside), leaf units."""
    d = np.full(x.shape, np.inf)
    inside = np.zeros(x.shape, bool)
    for (ax, ay), (bx, by) in zip(outline, np.roll(outline, -1, axis=0)):
        ex, ey = bx - ax, by - ay
        t = np.clip(((x - ax) * ex + (y - ay) * ey) / max(ex * ex + ey * ey, 1e-30), 0.0, 1.0)
        d = np.minimum(d, np.hypot(x - ax - t * ex, y - ay - t * ey))
        if ay != by:  # even–odd rule: a ray to +x crosses the outline an odd number of times from inside
            inside ^= ((ay > y) != (by > y)) & (x < ax + (y - ay) * ex / ey)
    return np.where(inside, d, -d)


def _cell_edges(x: np.ndarray, y: np.ndarray, cell: float, rng: np.random.Generator) -> np.ndarray:
    """Distance to the nearest edge of a jittered Voronoi net of ``cell``-sized cells (F2 − F1)."""
    gx, gy = x / cell, y / cell
    ix, iy = np.floor(gx).astype(int), np.floor(gy).astype(int)
    nx, ny = ix.max() - ix.min() + 3, iy.max() - iy.min() + 3
    jitter = rng.random((nx, ny, 2))
    f1 = np.full(x.shape, np.inf)
    f2 = np.full(x.shape, np.inf)
    for dx in (-1, 0, 1):
        for dy in (-1, 0, 1):
            cx, cy = ix + dx, iy + dy
            j = jitter[cx - ix.min() + 1, cy - iy.min() + 1]
            d = np.hypot(cx + j[..., 0] - gx, cy + j[..., 1] - gy)
            f2 = np.where(d < f1, f1, np.minimum(f2, d))
            f1 = np.minimum(f1, d)
    return (f2 - f1) * cell


def _line(distance: np.ndarray, width: np.ndarray | float) -> np.ndarray:
    """A vein's profile across it: 1 on its axis, 0 beyond ``width`` (half width), smooth."""
    s = np.clip(1.0 - distance / np.maximum(width, 1e-9), 0.0, 1.0)
    return s * s * (3.0 - 2.0 * s)


def make_leaf_maps(lamina: Lamina, size: int = SIZE) -> np.ndarray:
    """The maps of ``lamina`` (module notes), computed (:func:`leaf_maps` keeps them).

    Parameters
    ----------
    lamina : Lamina
    size : int
        Texels a side.

    Returns
    -------
    (size, size, 4) uint8
        Row r at y = (r + ½) / size · length, column c at x = ((c + ½) / size · 2 − 1) · half width.
    """
    half, length = lamina_box(lamina)
    outline = np.asarray(lamina.outline, float)
    s = (np.arange(size) + 0.5) / size
    x, y = np.meshgrid((2.0 * s - 1.0) * half, s * length)
    r = np.abs(x)
    margin = _inside_distance(outline, x, y)
    width = np.maximum(r + margin, 1e-3)  # the blade's half width at this height, about
    rng = np.random.default_rng(0x1EAF)

    midrib = _line(r, 0.016 * (1.0 - 0.7 * y / length) + 0.003)
    # Side veins: the lines y − g(r) = constant, g(r) = r·(0.75 + 0.6 r / width) (about 55° at the
    # midrib, arching towards the tip); the left side's between the right's (alternate).
    spacing = length / SIDE_VEINS
    shift = np.where(x < 0.0, 0.45 * spacing, 0.0)
    phase = (y - r * (0.75 + 0.6 * r / width) - shift) / spacing
    across = np.abs(phase - np.round(phase)) * spacing / np.sqrt(1.0 + (0.75 + 1.2 * r / width) ** 2)
    reach = np.clip(1.0 - r / (0.92 * width), 0.0, 1.0)  # fading before the margin
    first = (np.round(phase) >= 0.35) & (np.round(phase) * spacing < 0.96 * length)
    side = _line(across, 0.0022 + 0.006 * reach) * np.sqrt(reach) * first
    rim = _line(np.abs(margin - 0.012), 0.004) * (margin > 0.0)
    fine = _line(0.5 * _cell_edges(x, y, 0.03 * length, rng), 0.0025) * 0.3
    veins = np.maximum.reduce([midrib, 0.8 * side, 0.7 * rim, fine * (1.0 - midrib)])

    mottle = _cell_edges(x, y, 0.09 * length, rng) / (0.09 * length)
    albedo = (0.9 + 0.1 * y / length) * (0.96 + 0.08 * mottle) * (1.0 + 0.45 * veins)
    translucency = 0.95 - 0.45 * veins - 0.1 * midrib
    # Relief: veins sunk into the upper face, the areoles between them puffed up a little.
    height = -0.003 * (midrib + 0.7 * side + 0.25 * fine) + 0.0015 * np.clip(mottle, 0, 1)
    dy, dx = np.gradient(height, length / size, 2.0 * half / size)
    n = np.stack([-dx, -dy, np.ones_like(dx)], -1)
    n /= np.linalg.norm(n, axis=-1, keepdims=True)
    maps = np.stack([albedo / ALBEDO_SCALE, translucency, 0.5 + 0.5 * n[..., 0], 0.5 + 0.5 * n[..., 1]], -1)
    return np.round(255.0 * np.clip(maps, 0.0, 1.0)).astype(np.uint8)


def leaf_maps(lamina: Lamina, size: int = SIZE) -> np.ndarray:
    """The maps of ``lamina`` (:func:`make_leaf_maps`), made once per outline and kept.

    Returns
    -------
    (size, size, 4) uint8, read-only
    """
    outline = np.ascontiguousarray(lamina.outline, float)
    key = (outline.tobytes(), outline.shape, size)
    if key not in _cache:
        maps = make_leaf_maps(lamina, size)
        maps.flags.writeable = False
        _cache[key] = maps
    return _cache[key]


def leaf_texture(ctx: moderngl.Context, lamina: Lamina) -> moderngl.Texture:
    """The maps of ``lamina`` (:func:`leaf_maps`) as a texture: mipmapped, clamped at its edges."""
    maps = leaf_maps(lamina)
    texture = ctx.texture(maps.shape[1::-1], 4, maps.tobytes())
    texture.build_mipmaps()
    texture.filter = (moderngl.LINEAR_MIPMAP_NEAREST, moderngl.LINEAR)
    texture.repeat_x = texture.repeat_y = False
    return texture
