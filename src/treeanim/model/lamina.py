"""Leaf blades: a species outline from a preset, smoothed, serrated and triangulated once."""

from __future__ import annotations

import numpy as np

from .tree import Lamina


def _catmull_rom(points: np.ndarray, per_span: int = 16) -> np.ndarray:
    """A dense Catmull–Rom curve through ``points`` (P, 2), ends clamped."""
    p = np.vstack([points[:1], points, points[-1:]])
    t = np.linspace(0.0, 1.0, per_span, endpoint=False)[:, None]
    t2, t3 = t * t, t * t * t
    spans = []
    for i in range(1, len(p) - 2):
        p0, p1, p2, p3 = p[i - 1], p[i], p[i + 1], p[i + 2]
        spans.append(
            0.5 * (2 * p1 + (-p0 + p2) * t + (2 * p0 - 5 * p1 + 4 * p2 - p3) * t2 + (-p0 + 3 * p1 - 3 * p2 + p3) * t3)
        )
    return np.vstack([*spans, points[-1:]])


def _resample(curve: np.ndarray, count: int) -> tuple[np.ndarray, np.ndarray]:
    """``count`` points evenly spaced by arc length along ``curve``, and their arc fraction."""
    seg = np.linalg.norm(np.diff(curve, axis=0), axis=1)
    s = np.concatenate([[0.0], np.cumsum(seg)])
    u = np.linspace(0.0, s[-1], count)
    pts = np.column_stack([np.interp(u, s, curve[:, 0]), np.interp(u, s, curve[:, 1])])
    return pts, u / s[-1]


def half_outline(control: np.ndarray, samples: int, teeth: int, tooth_depth: float) -> np.ndarray:
    """The right half of a blade: ``samples`` points from base to tip, serrated.

    Parameters
    ----------
    control : (P, 2) float
        Control points of the right half (x >= 0), base (x = 0) first, tip (x = 0) last.
    samples : int
        Points on the half outline, base and tip included.
    teeth : int
        Serration teeth along the half (0 for an entire margin).
    tooth_depth : float
        Tooth depth in units of the midrib length.
    """
    pts, frac = _resample(_catmull_rom(np.asarray(control, float)), samples)
    if teeth > 0 and tooth_depth > 0:
        # A forward-leaning sawtooth pushed outward, fading to zero at base and tip.
        saw = (frac * teeth) % 1.0
        fade = np.sin(np.pi * frac) ** 0.5
        x = pts[:, 0]
        # Never push the margin to (or past) the midrib, where the two halves would touch.
        pts[:, 0] = np.maximum(x + tooth_depth * fade * (saw - 0.5), 0.5 * x)
    return pts


def _area2(p: np.ndarray) -> float:
    return float(np.dot(p[:, 0], np.roll(p[:, 1], -1)) - np.dot(p[:, 1], np.roll(p[:, 0], -1)))


def self_intersects(polygon: np.ndarray) -> bool:
    """True if two non-adjacent edges of the closed ``polygon`` (K, 2) cross or touch."""
    a = np.asarray(polygon, float)
    b = np.roll(a, -1, axis=0)

    def orient(p, q, r):
        return np.sign((q[..., 0] - p[..., 0]) * (r[..., 1] - p[..., 1]) - (q[..., 1] - p[..., 1]) * (r[..., 0] - p[..., 0]))

    A, B = a[:, None], b[:, None]
    C, D = a[None, :], b[None, :]
    cross = (orient(A, B, C) * orient(A, B, D) <= 0) & (orient(C, D, A) * orient(C, D, B) <= 0)
    k = len(a)
    i, j = np.indices((k, k))
    adjacent = (np.abs(i - j) <= 1) | (np.abs(i - j) == k - 1)
    return bool(np.any(cross & ~adjacent))


def ear_clip(polygon: np.ndarray) -> np.ndarray:
    """Triangulate a simple counter-clockwise polygon by ear clipping.

    Returns
    -------
    (K - 2, 3) int
        Triangles as indices into ``polygon``, counter-clockwise.
    """
    poly = np.asarray(polygon, float)
    idx = list(range(len(poly)))
    tris = []
    guard = 0
    while len(idx) > 3 and guard < 10 * len(poly) ** 2:
        guard += 1
        n = len(idx)
        for k in range(n):
            i0, i1, i2 = idx[k - 1], idx[k], idx[(k + 1) % n]
            a, b, c = poly[i0], poly[i1], poly[i2]
            cross = (b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0])
            if cross <= 1e-12:
                continue  # reflex or degenerate corner
            others = poly[[j for j in idx if j not in (i0, i1, i2)]]
            if len(others):
                # Barycentric sign test: is any other vertex inside (or on) triangle abc?
                d1 = (others[:, 0] - b[0]) * (a[1] - b[1]) - (a[0] - b[0]) * (others[:, 1] - b[1])
                d2 = (others[:, 0] - c[0]) * (b[1] - c[1]) - (b[0] - c[0]) * (others[:, 1] - c[1])
                d3 = (others[:, 0] - a[0]) * (c[1] - a[1]) - (c[0] - a[0]) * (others[:, 1] - a[1])
                inside = (d1 >= 0) & (d2 >= 0) & (d3 >= 0)
                if np.any(inside):
                    continue
            tris.append((i0, i1, i2))
            idx.pop(k)
            break
        else:
            break
    if len(idx) == 3:
        tris.append(tuple(idx))
    tris = np.array(tris, dtype=np.int64).reshape(-1, 3)
    if len(tris) != len(poly) - 2 or abs(sum(_area2(poly[t]) for t in tris) - _area2(poly)) > 1e-9:
        raise ValueError("key 'lamina.outline': the outline is not a simple polygon")
    return tris


def make_lamina(shape: str, control, samples: int, teeth: int, tooth_depth: float, curl: float) -> Lamina:
    """Mirror a half outline into a whole blade and triangulate it once.

    The outline runs counter-clockwise: up the right side (x > 0) from the base to the tip,
    then down the left side. ``samples`` points per half give ``2 * samples - 2`` outline
    points and ``2 * samples - 4`` triangles.
    """
    right = half_outline(np.asarray(control, float), samples, teeth, tooth_depth)
    left = right[-2:0:-1] * [-1.0, 1.0]
    outline = np.vstack([right, left])
    if self_intersects(outline):
        raise ValueError(f"key 'lamina.outline': the {shape!r} outline crosses itself")
    if _area2(outline) < 0:
        outline = outline[::-1]
    return Lamina(shape=shape, outline=outline, triangles=ear_clip(outline), curl=float(curl))
