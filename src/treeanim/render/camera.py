"""Orbit / pan / zoom camera (row-vector matrices), and the one framing of a tree that the viewer
(F, and every new tree) and the offline commands share (:func:`framed_camera`,
:meth:`OrbitCamera.frame_points`).

Matrices are returned in the row-vector layout (``p_clip = p @ view @ proj``),
whose bytes are exactly what an OpenGL ``mat4`` uniform expects; the mathematical (column-
vector) matrix is their transpose.

Framing
-------
The camera looks at the centre of the tree's box (the pivot it orbits about) from
:data:`TREE_ELEVATION` degrees above the horizon (:data:`FLAT_ELEVATION` for flat scenes such
as grass), steps back until the tree's projected extents, times :data:`FRAME_MARGIN`, fit the
free part of the view, and centres the image there with a lens shift (an off-axis projection,
:attr:`OrbitCamera.shift`), so the pivot stays on the tree while the image moves clear of the
viewer's panel.
"""

from __future__ import annotations

import math

import numpy as np

Bounds = tuple[tuple[float, float, float], tuple[float, float, float]]

#: Degrees above the horizon a framed tree is seen from: a person's view a little above the
#: ground, high enough that the ground and the crown's shadow under it show (at 2° the ground
#: is a sliver and the shadow foreshortened to a line).
TREE_ELEVATION = 8.0
#: Degrees above the horizon a flat scene (grass: height under 0.3 of its width) is seen from.
FLAT_ELEVATION = 25.0
#: The framed image's extents times this fill the free view: a border of about 5 % of the
#: view at each side, room for a crown that leans in the wind.
FRAME_MARGIN = 1.12


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
    shift : (2,) float
        Lens shift: where the target appears, in normalised device coordinates (x right, y up,
        −1 … 1 across the view); (0, 0) is the centre. :meth:`frame_points` sets it.
    """

    def __init__(self, target=(0.0, 1.0, 0.0), distance: float = 5.0, azimuth: float = 0.0,
                 elevation: float = 10.0, fov_y: float = 40.0, near: float | None = None,
                 far: float | None = None, shift=(0.0, 0.0)) -> None:
        self.target = np.array(target, dtype=float)
        self.shift = np.array(shift, dtype=float)
        self.distance = float(distance)
        self.azimuth = float(azimuth)
        self.elevation = float(elevation)
        self.fov_y = float(fov_y)
        self.near = near
        self.far = far
        self._vp_key = self._vp = None  # view_projection's cache

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
        """(4, 4) float32 view matrix (row-vector layout): the eye at the origin looking down −z,
        y up."""
        eye = np.asarray(self.eye, float)
        forward = _unit(np.asarray(self.target, float) - eye)
        side = _unit(np.cross(forward, (0.0, 1.0, 0.0)))
        up = _unit(np.cross(side, forward))
        m = np.eye(4)
        m[:3, 0], m[:3, 1], m[:3, 2] = side, up, -forward
        m[3, :3] = -side @ eye, -up @ eye, forward @ eye
        return m.astype(np.float32)

    def projection_matrix(self, aspect: float) -> np.ndarray:
        """(4, 4) float32 perspective projection for ``aspect`` = width / height (row-vector
        layout, OpenGL's clip space)."""
        near, far = self.clip_planes()
        f = 1.0 / np.tan(np.radians(self.fov_y) / 2.0)
        proj = np.zeros((4, 4), np.float32)
        proj[0, 0], proj[1, 1] = f / max(float(aspect), 1e-6), f
        proj[2, 2], proj[2, 3] = -(far + near) / (far - near), -1.0
        proj[3, 2] = -2.0 * far * near / (far - near)
        # The lens shift: clip x, y += shift · w_clip (w_clip = −z_eye), so NDC moves by shift.
        proj[2, :2] -= self.shift.astype(np.float32)
        return proj

    def view_projection(self, width: int, height: int) -> np.ndarray:
        """(4, 4) float32 view·projection for a ``width`` × ``height`` viewport (row-vector
        layout), read-only: kept until the camera or the viewport changes (most of the
        viewer's frames reuse it)."""
        key = (self.target.tobytes(), self.shift.tobytes(), self.distance, self.azimuth, self.elevation, self.fov_y,
               self.near, self.far, width, height)
        if key != self._vp_key:
            vp = (self.view_matrix().astype(float) @ self.projection_matrix(width / max(height, 1))
                  .astype(float)).astype(np.float32)
            vp.setflags(write=False)
            self._vp, self._vp_key = vp, key
        return self._vp

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

    def frame(self, bounds: Bounds, aspect: float = 16 / 9, margin: float = FRAME_MARGIN) -> None:
        """:meth:`frame_points` on the upright elliptic cylinder inscribed in axis-aligned
        ``bounds`` ((x0, y0, z0), (x1, y1, z1)): a crown is round, not boxy."""
        lo, hi = np.asarray(bounds[0], float), np.asarray(bounds[1], float)
        c, half = 0.5 * (lo + hi), 0.5 * (hi - lo)
        a = np.linspace(0.0, 2.0 * np.pi, 32, endpoint=False)
        ring = np.stack([half[0] * np.cos(a), np.zeros_like(a), half[2] * np.sin(a)], 1)
        self.frame_points(c + np.concatenate([ring - [0.0, half[1], 0.0], ring + [0.0, half[1], 0.0]]),
                          width=aspect, height=1.0, margin=margin)

    def frame_points(self, points, pad=0.0, *, width: float, height: float, margin: float = FRAME_MARGIN,
                     left: float = 0.0) -> None:
        """Aim at the centre of ``points``' box and set the distance and the lens shift so that
        every point, a sphere of radius ``pad``, appears inside the view right of ``left``,
        centred there, its extents times ``margin`` filling that part (the orbit's direction
        is kept).

        Parameters
        ----------
        points : (K, 3) array_like
            World points to show.
        pad : float or (K,) array_like
            Their radii (m): a lamina's length, half a branch's diameter.
        width, height : float
            The view's size (pixels or screen units; only their ratio and ``left`` matter).
        margin : float
            At least 1: the image's width and height times this fit the free part of the view.
        left : float
            Width of the view covered at its left (a panel), in the units of ``width``; the
            tree is framed in the rest.
        """
        P = np.atleast_2d(np.asarray(points, float))
        pad = np.broadcast_to(np.asarray(pad, float), (len(P),))
        lo, hi = P.min(axis=0), P.max(axis=0)
        self.target = 0.5 * (lo + hi)
        rel = P - self.target
        a, u, d = rel @ self.right, rel @ self.up, rel @ self.forward
        tan_y = math.tan(math.radians(self.fov_y) / 2)
        tan_x = tan_y * width / max(height, 1e-9)
        free = 2.0 * max(1.0 - min(max(left, 0.0), 0.9 * width) / max(width, 1e-9), 0.1)  # NDC width left free

        def extents(D):
            depth = D + d
            x, y = a / (depth * tan_x), u / (depth * tan_y)
            px, py = pad / (depth * tan_x), pad / (depth * tan_y)
            return float((x - px).min()), float((x + px).max()), float((y - py).min()), float((y + py).max())

        def fits(D):
            x0, x1, y0, y1 = extents(D)
            return margin * (x1 - x0) <= free and margin * (y1 - y0) <= 2.0

        size = float(np.max(hi - lo)) + 2.0 * float(pad.max(initial=0.0)) or 1.0
        near = max(float(np.max(pad - d)), 0.0)  # every point (sphere) in front of the eye
        D_lo, D_hi = near, near + size
        while not fits(D_hi):
            D_lo, D_hi = D_hi, 2.0 * D_hi
        for _ in range(50):  # the extents shrink as the camera steps back: bisect
            mid = 0.5 * (D_lo + D_hi)
            D_lo, D_hi = (D_lo, mid) if fits(mid) else (mid, D_hi)
            if D_hi - D_lo < 1e-5 * D_hi:
                break
        self.distance = max(D_hi, 1e-3)
        x0, x1, y0, y1 = extents(self.distance)
        self.shift = np.array([1.0 - 0.5 * free - 0.5 * (x0 + x1), -0.5 * (y0 + y1)])

    # ------------------------------------------------------------------ rays
    def pixel_angle(self, height: int) -> float:
        """Metres per pixel at one metre from the eye (small-angle size of a pixel)."""
        return 2.0 * math.tan(math.radians(self.fov_y) / 2) / max(int(height), 1)

    def ray(self, x: float, y: float, width: int, height: int) -> tuple[np.ndarray, np.ndarray]:
        """The world ray through window point (x, y): origin top-left, y down, pixel centres at
        +0.5 (GLFW cursor coordinates). Returns (origin = the eye, unit direction)."""
        ndc_x = 2.0 * x / max(width, 1) - 1.0 - self.shift[0]
        ndc_y = 1.0 - 2.0 * y / max(height, 1) - self.shift[1]
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


# ---------------------------------------------------------------------------- framing a tree
def _unit(v: np.ndarray) -> np.ndarray:
    return v / np.linalg.norm(v)


def framing_elevation(tree) -> float:
    """:data:`FLAT_ELEVATION` for a flat scene (height under 0.3 of its width: grass),
    else :data:`TREE_ELEVATION` (degrees)."""
    ext = np.ptp(np.asarray(tree.rest_positions, float), axis=0)
    return FLAT_ELEVATION if ext[1] < 0.3 * max(ext[0], ext[2]) else TREE_ELEVATION


def tree_extent(tree, present=None) -> tuple[np.ndarray, np.ndarray]:
    """The points a framing shows: ``tree``'s rest nodes (of the ``present`` objects, if any
    is) and their radii (half the node's diameter, plus a leaf's lamina length).

    Returns
    -------
    points : (K, 3) float
    pad : (K,) float
    """
    P = np.asarray(tree.rest_positions, float)
    pad = 0.5 * np.asarray(tree.node_diameter, float)
    if len(getattr(tree, "lamina_length", ())):
        pad = pad + np.asarray(tree.lamina_length, float)[tree.node_object]
    if present is not None:
        keep = np.repeat(np.asarray(present, bool), tree.object_count)
        if keep.any():
            P, pad = P[keep], pad[keep]
    return P, pad


def frame_tree(camera: OrbitCamera, tree, width: float, height: float, *, present=None, left: float = 0.0,
               elevation: float | None = None, margin: float = FRAME_MARGIN) -> OrbitCamera:
    """Frame ``tree`` with ``camera`` (its azimuth kept): from :func:`framing_elevation` (or
    ``elevation``), its rest pose (:func:`tree_extent`) fitted into the ``width`` × ``height``
    view right of ``left`` (see :meth:`OrbitCamera.frame_points`). Returns ``camera``."""
    camera.elevation = framing_elevation(tree) if elevation is None else elevation
    camera.frame_points(*tree_extent(tree, present), width=width, height=height, margin=margin, left=left)
    return camera


def framed_camera(tree, width: int, height: int, azimuth: float = 0.0, elevation: float | None = None,
                  distance: float | None = None, present=None, margin: float = FRAME_MARGIN) -> OrbitCamera:
    """A new :class:`OrbitCamera` on ``tree`` from ``azimuth`` (degrees), framed by
    :func:`frame_tree`; ``distance`` (metres) overrides the distance only."""
    cam = frame_tree(OrbitCamera(azimuth=azimuth), tree, width, height, present=present, elevation=elevation,
                     margin=margin)
    if distance is not None:
        cam.distance = float(distance)
    return cam
