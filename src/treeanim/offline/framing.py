"""The offline commands' camera: the tree framed in the picture."""

from __future__ import annotations

import math

import numpy as np


def default_elevation(tree) -> float:
    """Degrees: low for trees (a person's view), higher for flat scenes such as grass."""
    P = tree.rest_positions
    ext = P.max(axis=0) - P.min(axis=0)
    return 25.0 if ext[1] < 0.3 * max(ext[0], ext[2]) else 2.0


def framed_camera(tree, width: int, height: int, azimuth: float = 0.0, elevation: float | None = None,
                  distance: float | None = None, present=None, margin: float = 1.12):
    """An :class:`OrbitCamera` looking at ``tree`` from ``azimuth`` / ``elevation`` (degrees).

    The target and distance are chosen so that the tree's rest nodes (those of the ``present``
    objects; leaves padded by their lamina) fill the ``width`` × ``height`` view, centred, with
    ``margin`` to spare; ``distance`` (metres) overrides the distance only.
    """
    from ..render.camera import OrbitCamera

    if elevation is None:
        elevation = default_elevation(tree)
    cam = OrbitCamera(azimuth=azimuth, elevation=elevation)
    P = np.asarray(tree.rest_positions, float)
    pad = np.zeros(len(P))
    if len(getattr(tree, "lamina_length", ())):
        pad = np.asarray(tree.lamina_length, float)[tree.node_object]
    pad = pad + 0.5 * np.asarray(tree.node_diameter, float)
    if present is not None:
        keep = np.repeat(np.asarray(present, bool), tree.object_count)
        if keep.any():
            P, pad = P[keep], pad[keep]
    lo, hi = P.min(axis=0), P.max(axis=0)
    cam.target = 0.5 * (lo + hi)
    tan_y = math.tan(math.radians(cam.fov_y) / 2)
    tan_x = tan_y * width / max(height, 1)
    right, up, fwd = cam.right, cam.up, cam.forward
    D = float(np.max(hi - lo)) or 1.0
    for _ in range(6):
        rel = P - cam.target
        a, u, d = rel @ right, rel @ up, rel @ fwd
        need = np.maximum(margin * (np.abs(a) + pad) / tan_x, margin * (np.abs(u) + pad) / tan_y) - d
        D = max(float(need.max()), 1e-3)
        # Centre the tree's image: shift the target by the middle of its projected extents.
        depth = D + d
        x, y = a / (depth * tan_x), u / (depth * tan_y)
        px, py = pad / (depth * tan_x), pad / (depth * tan_y)
        sx = 0.5 * (float((x + px).max()) + float((x - px).min()))
        sy = 0.5 * (float((y + py).max()) + float((y - py).min()))
        if abs(sx) < 1e-4 and abs(sy) < 1e-4:
            break
        cam.target = cam.target + sx * D * tan_x * right + sy * D * tan_y * up
    cam.distance = float(distance) if distance is not None else D
    return cam
