"""Orbit / pan / zoom camera (pyrr matrices).

Matrices are returned in pyrr's layout (row-vector convention: ``p_clip = p @ view @ proj``),
whose bytes are exactly what an OpenGL ``mat4`` uniform expects; the mathematical (column-
vector) matrix is their transpose.
"""

from __future__ import annotations

import math

import numpy as np
from pyrr import matrix44

Bounds = tuple[tuple[float, float, float], tuple[float, float, float]]


class OrbitCamera:
    """A camera orbiting ``target`` at ``distance``, y up.

    Parameters
    ----------
    target : (3,) float
        The point looked at.
    distance : float
        Metres from the target to the eye.
    azimuth : float
        Degrees about +y; 0 puts the eye on +z looking towards −z, 90 on +x.
    elevation : float
        Degrees above the horizontal plane through the target, clamped to ±89.
    fov_y : float
        Vertical field of view in degrees.
    near, far : float or None
        Clip planes; None derives them from the distance (near = distance/100,
        far = 100·distance + 100 m).
    """

    def __init__(self, target=(0.0, 1.0, 0.0), distance: float = 5.0, azimuth: float = 0.0,
                 elevation: float = 10.0, fov_y: float = 40.0, near: float | None = None,
                 far: float | None = None) -> None:
        self.target = np.array(target, dtype=float)
        self.distance = float(distance)
        self.azimuth = float(azimuth)
        self.elevation = float(elevation)
        self.fov_y = float(fov_y)
        self.near = near
        self.far = far

    # ------------------------------------------------------------------ geometry
    @property
    def elevation(self) -> float:
        return self._elevation

    @elevation.setter
    def elevation(self, value: float) -> None:
        self._elevation = float(np.clip(value, -89.0, 89.0))

    @property
    def forward(self) -> np.ndarray:
        """Unit vector from the eye towards the target."""
        az, el = math.radians(self.azimuth), math.radians(self.elevation)
        return -np.array([math.cos(el) * math.sin(az), math.sin(el), math.cos(el) * math.cos(az)])

    @property
    def right(self) -> np.ndarray:
        """Unit vector to the right of the view (horizontal)."""
        az = math.radians(self.azimuth)
        return np.array([math.cos(az), 0.0, -math.sin(az)])

    @property
    def up(self) -> np.ndarray:
        """Unit vector up in the view."""
        return np.cross(self.right, self.forward)

    @property
    def eye(self) -> np.ndarray:
        """The eye position, world."""
        return self.target - self.distance * self.forward

    def clip_planes(self) -> tuple[float, float]:
        """(near, far) in metres."""
        near = self.near if self.near is not None else max(self.distance / 100.0, 1e-4)
        far = self.far if self.far is not None else 100.0 * self.distance + 100.0
        return float(near), float(far)

    # ------------------------------------------------------------------ matrices
    def view_matrix(self) -> np.ndarray:
        """(4, 4) float32 view matrix (pyrr layout)."""
        return matrix44.create_look_at(self.eye, self.target, np.array([0.0, 1.0, 0.0]), dtype=np.float32)

    def projection_matrix(self, aspect: float) -> np.ndarray:
        """(4, 4) float32 perspective projection for ``aspect`` = width / height (pyrr layout)."""
        near, far = self.clip_planes()
        return matrix44.create_perspective_projection(self.fov_y, max(float(aspect), 1e-6), near, far,
                                                      dtype=np.float32)

    def view_projection(self, width: int, height: int) -> np.ndarray:
        """(4, 4) float32 view·projection for a ``width`` × ``height`` viewport (pyrr layout)."""
        return (self.view_matrix().astype(float) @ self.projection_matrix(width / max(height, 1))
                .astype(float)).astype(np.float32)

    # ------------------------------------------------------------------ interaction
    def orbit(self, d_azimuth: float, d_elevation: float) -> None:
        """Turn about the target by degrees."""
        self.azimuth = (self.azimuth + d_azimuth) % 360.0
        self.elevation = self.elevation + d_elevation

    def pan(self, dx: float, dy: float, height: int) -> None:
        """Move the target with the image by (dx, dy) pixels (x right, y down) of a viewport
        ``height`` pixels tall, so the point under the cursor stays under it."""
        s = self.pixel_angle(height) * self.distance
        self.target = self.target - dx * s * self.right + dy * s * self.up

    def zoom(self, factor: float) -> None:
        """Multiply the distance by ``factor`` (< 1 moves closer)."""
        self.distance = float(np.clip(self.distance * factor, 1e-3, 1e6))

    def frame(self, bounds: Bounds, aspect: float = 16 / 9, margin: float = 1.08) -> None:
        """Aim at the centre of axis-aligned ``bounds`` ((x0, y0, z0), (x1, y1, z1)) and step back
        until the upright elliptic cylinder inscribed in them (a crown is round, not boxy),
        seen from the current direction, fits the view of ``aspect`` (w / h) with ``margin``
        to spare."""
        lo, hi = np.asarray(bounds[0], float), np.asarray(bounds[1], float)
        self.target = 0.5 * (lo + hi)
        half = 0.5 * (hi - lo)
        a = np.linspace(0.0, 2.0 * np.pi, 32, endpoint=False)
        ring = np.stack([half[0] * np.cos(a), np.zeros_like(a), half[2] * np.sin(a)], 1)
        rel = np.concatenate([ring - [0.0, half[1], 0.0], ring + [0.0, half[1], 0.0]])
        across = np.abs(rel @ self.right)
        upward = np.abs(rel @ self.up)
        depth = rel @ self.forward  # towards the far side is positive
        tan_y = math.tan(math.radians(self.fov_y) / 2)
        tan_x = tan_y * aspect
        # Each corner must satisfy |across| <= tan_x (distance + depth), likewise upward.
        need = np.maximum(margin * across / tan_x, margin * upward / tan_y) - depth
        self.distance = max(float(need.max()), 1e-3)

    # ------------------------------------------------------------------ rays
    def pixel_angle(self, height: int) -> float:
        """Metres per pixel at one metre from the eye (small-angle size of a pixel)."""
        return 2.0 * math.tan(math.radians(self.fov_y) / 2) / max(int(height), 1)

    def ray(self, x: float, y: float, width: int, height: int) -> tuple[np.ndarray, np.ndarray]:
        """The world ray through window point (x, y): origin top-left, y down, pixel centres at
        +0.5 (GLFW cursor coordinates). Returns (origin = the eye, unit direction)."""
        ndc_x = 2.0 * x / max(width, 1) - 1.0
        ndc_y = 1.0 - 2.0 * y / max(height, 1)
        th = math.tan(math.radians(self.fov_y) / 2)
        d = self.forward + ndc_x * th * (width / max(height, 1)) * self.right + ndc_y * th * self.up
        return self.eye.copy(), d / np.linalg.norm(d)

    def project(self, points, width: int, height: int) -> np.ndarray:
        """Window coordinates (x, y, depth) of world ``points`` (K, 3): the inverse of :meth:`ray`
        (x right, y down, depth in [0, 1] inside the clip planes)."""
        p = np.atleast_2d(np.asarray(points, float))
        clip = np.concatenate([p, np.ones((len(p), 1))], axis=1) @ self.view_projection(width, height).astype(float)
        ndc = clip[:, :3] / clip[:, 3:4]
        return np.stack([(ndc[:, 0] + 1) * 0.5 * width, (1 - ndc[:, 1]) * 0.5 * height, (ndc[:, 2] + 1) * 0.5], 1)
