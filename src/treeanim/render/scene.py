"""The scene a tree stands in: the sun (its direction from angles and back), the sky and the
ground's look (:class:`Scene`), and the ground's polygons cut in front of the eye."""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

#: The ground's polygons are clipped where they come nearer the eye than this (metres, along
#: the view): they never reach its plane.
GROUND_NEAR = 1e-4


def sun_direction(azimuth: float, elevation: float) -> tuple[float, float, float]:
    """Unit vector towards a sun at ``azimuth`` degrees about +y (0: towards +z, 90: towards +x)
    and ``elevation`` degrees above the horizon."""
    a, e = math.radians(azimuth), math.radians(elevation)
    return (math.cos(e) * math.sin(a), math.sin(e), math.cos(e) * math.cos(a))


def sun_angles(direction) -> tuple[float, float]:
    """Inverse of :func:`sun_direction`: (azimuth in [0, 360), elevation in [-90, 90]) degrees."""
    d = np.asarray(direction, float)
    d = d / np.linalg.norm(d)
    return math.degrees(math.atan2(d[0], d[2])) % 360.0, math.degrees(math.asin(np.clip(d[1], -1.0, 1.0)))


def clip_ground(polygon: np.ndarray, view_proj: np.ndarray, depth: float) -> np.ndarray:
    """Triangles of a convex polygon on the ground, in clip space, cut where it comes nearer the
    eye than :data:`GROUND_NEAR` (GL would clip it only at the near plane), drawn at ``depth``.

    Parameters
    ----------
    polygon : (K, 2) float
        Corners (x, z) on the ground y = 0, in order round it.
    view_proj : (4, 4) float
        World → clip, as :meth:`OrbitCamera.view_projection` returns it (GLSL's column-major
        bytes: a point p is ``p @ view_proj``).
    depth : float
        Where in the depth range (NDC z) the polygon lies, all of it.

    Returns
    -------
    (3 (K' - 2), 4) float32
        The clipped polygon as a fan of triangles (none if it lies behind the eye).
    """
    polygon = np.asarray(polygon, float)
    world = np.column_stack([polygon[:, 0], np.zeros(len(polygon)), polygon[:, 1], np.ones(len(polygon))])
    clip = world @ np.asarray(view_proj, float)
    d = clip[:, 3] - GROUND_NEAR
    kept = []
    for i in range(len(clip)):  # Sutherland-Hodgman against w >= GROUND_NEAR
        j = (i + 1) % len(clip)
        if d[i] >= 0:
            kept.append(clip[i])
        if (d[i] >= 0) != (d[j] >= 0):
            kept.append(clip[i] + (clip[j] - clip[i]) * (d[i] / (d[i] - d[j])))
    if len(kept) < 3:
        return np.zeros((0, 4), np.float32)
    kept = np.array(kept)
    kept[:, 2] = depth * kept[:, 3]
    fan = [(0, k, k + 1) for k in range(1, len(kept) - 1)]
    return kept.astype(np.float32)[np.ravel(fan)]


@dataclass
class Scene:
    """Look of the scene: sun, sky, ground. Colours are sRGB in [0, 1]."""

    sun_direction: tuple[float, float, float] = (0.40, 0.85, 0.35)
    sun_color: tuple[float, float, float] = (1.0, 0.95, 0.86)
    sun_intensity: float = 1.5
    sky_zenith: tuple[float, float, float] = (0.25, 0.47, 0.80)
    sky_horizon: tuple[float, float, float] = (0.76, 0.85, 0.93)
    ground_bounce: tuple[float, float, float] = (0.30, 0.32, 0.22)
    ambient: float = 0.75
    exposure: float = 1.0
    haze_distance: float | None = None  # metres; None: from the tree's size
    ground_grid: float = 0.0            # strength of a 1 m grid on the ground (0: none)
    clouds: float = 0.4                 # how much of the sky clouds cover (0: a clear sky .. 1)
    show_sky: bool = True
    show_ground: bool = True
    shadow: bool = True                 # the sun's shadows (tree on ground and on itself)
    shadow_size: int = 1024             # shadow-map texels a side (read when the renderer is made)
    translucency: float = 1.0           # sunlight through the leaves (0: opaque leaves)
    thin_pixels: float = 1.5            # twigs and blades of a half width below this (px) get soft edges (0: none)
